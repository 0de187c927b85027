# Finds the GL viewer's dependencies (all from Debian: libglfw3-dev, libepoxy-dev,
# libegl-dev, libspng-dev, libimgui-dev) and defines FIBLET_BUILD_VIEWER, ON by default when
# they are all present, so that the core library and the CLI build without them.
find_package(glfw3 3.3 QUIET)
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(FIBLET_EPOXY QUIET IMPORTED_TARGET epoxy)
  pkg_check_modules(FIBLET_EGL QUIET IMPORTED_TARGET egl)
  pkg_check_modules(FIBLET_SPNG QUIET IMPORTED_TARGET spng)
  pkg_check_modules(FIBLET_IMGUI QUIET IMPORTED_TARGET imgui)  # with its GLFW and OpenGL 3 backends
endif()
if(glfw3_FOUND AND FIBLET_EPOXY_FOUND AND FIBLET_EGL_FOUND AND FIBLET_SPNG_FOUND AND FIBLET_IMGUI_FOUND)
  set(FIBLET_VIEWER_DEPS_FOUND ON)
else()
  set(FIBLET_VIEWER_DEPS_FOUND OFF)
endif()
option(FIBLET_BUILD_VIEWER "Build the OpenGL viewer (fiblet view / fiblet render)" ${FIBLET_VIEWER_DEPS_FOUND})
if(FIBLET_BUILD_VIEWER AND NOT FIBLET_VIEWER_DEPS_FOUND)
  message(FATAL_ERROR "FIBLET_BUILD_VIEWER needs libglfw3-dev, libepoxy-dev, libegl-dev, libspng-dev and libimgui-dev "
                      "(scripts/setup.sh installs them)")
endif()
message(STATUS "fiblet viewer: ${FIBLET_BUILD_VIEWER}")
