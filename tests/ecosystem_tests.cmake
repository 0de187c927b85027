# Tests of how fiblet fits its ecosystem, run by ctest next to the GoogleTest
# suite: an installed package used by a downstream project, the generated CLI
# reference, and the Snakemake cohort workflow. (The Python module's pytest
# suite is registered in python/CMakeLists.txt.)
get_filename_component(FIBLET_SHARED_DATA "${PROJECT_SOURCE_DIR}/../shared/data" ABSOLUTE)

add_test(NAME ecosystem.install_downstream
  COMMAND ${PROJECT_SOURCE_DIR}/tests/downstream/run_downstream_test.sh
          ${PROJECT_BINARY_DIR} ${FIBLET_SHARED_DATA}/dwi-small64d-ifod1.tck ${PROJECT_VERSION})
set_tests_properties(ecosystem.install_downstream PROPERTIES TIMEOUT 300)
