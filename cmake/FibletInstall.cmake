# Installation and export: the library, its public headers, the fiblet CLI, a
# CMake package (fibletConfig.cmake, version file, targets in the fiblet::
# namespace) and a pkg-config file. Downstream:
#   find_package(fiblet CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE fiblet::fiblet)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(FIBLET_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/fiblet" CACHE STRING
    "Where fibletConfig.cmake is installed (relative to the prefix)")

# Static by default (self-contained CLI and Python module, nothing to find at
# run time); -DBUILD_SHARED_LIBS=ON builds a versioned shared library.
if(BUILD_SHARED_LIBS)
  set_target_properties(fiblet PROPERTIES VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
  set_target_properties(fiblet_cli PROPERTIES INSTALL_RPATH "$ORIGIN/../${CMAKE_INSTALL_LIBDIR}")
  set(FIBLET_PC_LIBS "")
  set(FIBLET_PC_LIBS_PRIVATE "-lzstd -lzip -lnifti2 -lznz -lxxhash -pthread")
else()
  # A static archive needs its dependencies on every link line.
  set(FIBLET_PC_LIBS "-lzstd -lzip -lnifti2 -lznz -lxxhash -pthread")
  set(FIBLET_PC_LIBS_PRIVATE "")
endif()

install(TARGETS fiblet EXPORT fibletTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/libfiblet/include/fiblet DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.hpp")
install(TARGETS fiblet_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

install(EXPORT fibletTargets NAMESPACE fiblet:: DESTINATION ${FIBLET_INSTALL_CMAKEDIR})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/fibletConfig.cmake.in
  ${PROJECT_BINARY_DIR}/fibletConfig.cmake INSTALL_DESTINATION ${FIBLET_INSTALL_CMAKEDIR})
# 0.x releases may break the API between minor versions: only the same minor
# version is compatible until 1.0.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/fibletConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/fibletConfig.cmake ${PROJECT_BINARY_DIR}/fibletConfigVersion.cmake
  DESTINATION ${FIBLET_INSTALL_CMAKEDIR})

file(RELATIVE_PATH FIBLET_PC_TO_PREFIX "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
configure_file(${CMAKE_CURRENT_LIST_DIR}/fiblet.pc.in ${PROJECT_BINARY_DIR}/fiblet.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/fiblet.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# The man page fiblet(1) and the bash completion, generated from the CLI11
# definitions by the CLI just built (`fiblet help --man | --bash-completion`).
set(FIBLET_MAN_PAGE ${PROJECT_BINARY_DIR}/share/man/man1/fiblet.1)
set(FIBLET_BASH_COMPLETION ${PROJECT_BINARY_DIR}/share/bash-completion/completions/fiblet)
add_custom_command(OUTPUT ${FIBLET_MAN_PAGE} ${FIBLET_BASH_COMPLETION}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/share/man/man1
          ${PROJECT_BINARY_DIR}/share/bash-completion/completions
  COMMAND sh -c "\"$1\" help --man > \"$2\" && \"$1\" help --bash-completion > \"$3\"" sh
          $<TARGET_FILE:fiblet_cli> ${FIBLET_MAN_PAGE} ${FIBLET_BASH_COMPLETION}
  DEPENDS fiblet_cli VERBATIM)
add_custom_target(fiblet_cli_reference ALL DEPENDS ${FIBLET_MAN_PAGE} ${FIBLET_BASH_COMPLETION})
install(FILES ${FIBLET_MAN_PAGE} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
install(FILES ${FIBLET_BASH_COMPLETION} DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions)
