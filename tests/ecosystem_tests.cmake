# Tests of how fiblet fits its ecosystem, run by ctest next to the GoogleTest
# suite: an installed package used by a downstream project, the generated CLI
# reference, and the Snakemake cohort workflow. (The Python module's pytest
# suite is registered in python/CMakeLists.txt.)
get_filename_component(FIBLET_SHARED_DATA "${PROJECT_SOURCE_DIR}/../shared/data" ABSOLUTE)

add_test(NAME ecosystem.install_downstream
  COMMAND ${PROJECT_SOURCE_DIR}/tests/downstream/run_downstream_test.sh
          ${PROJECT_BINARY_DIR} ${FIBLET_SHARED_DATA}/dwi-small64d-ifod1.tck ${PROJECT_VERSION} ${Python_EXECUTABLE})
set_tests_properties(ecosystem.install_downstream PROPERTIES TIMEOUT 300)
if(FIBLET_SANITIZE)  # an instrumented libfiblet.a needs the sanitizer runtimes in the downstream link
  set_tests_properties(ecosystem.install_downstream PROPERTIES
    ENVIRONMENT "CXXFLAGS=-fsanitize=address,undefined;LDFLAGS=-fsanitize=address,undefined")
endif()

# docs/cli.md must equal what the CLI generates (scripts/gen_cli_docs.sh).
add_test(NAME ecosystem.cli_docs_up_to_date
  COMMAND ${PROJECT_SOURCE_DIR}/scripts/gen_cli_docs.sh --check $<TARGET_FILE:fiblet_cli>)

# The Snakemake cohort workflow on 3 generated subjects.
if(DEFINED Python_EXECUTABLE)
  fiblet_add_pytest(ecosystem.cohort_workflow ${PROJECT_SOURCE_DIR}/scripts/workflow/test_workflow.py 300
    ENVIRONMENT "FIBLET_SHARED_DATA=${FIBLET_SHARED_DATA}" "FIBLET_CLI=$<TARGET_FILE:fiblet_cli>" "FIBLET_VERSION=${PROJECT_VERSION}")
endif()

# The same Snakefile on a single-node SLURM (slurm-wlm, munge) started on
# localhost by the test, its state in the build tree; the test stops the
# daemons itself (its workflow timeout is under CTest's) and they die with it
# if it is killed.
if(DEFINED Python_EXECUTABLE)
  fiblet_add_pytest(ecosystem.cohort_workflow_slurm ${PROJECT_SOURCE_DIR}/scripts/workflow/test_workflow_slurm.py 500
    ENVIRONMENT "FIBLET_SHARED_DATA=${FIBLET_SHARED_DATA}" "FIBLET_CLI=$<TARGET_FILE:fiblet_cli>" "FIBLET_SLURM_DIR=${PROJECT_BINARY_DIR}/slurm")
endif()

# CLI conventions: help, --version, --json, documented exit codes.
if(DEFINED Python_EXECUTABLE)
  fiblet_add_pytest(ecosystem.cli_conventions ${PROJECT_SOURCE_DIR}/tests/test_cli_conventions.py 120
    ENVIRONMENT "FIBLET_SHARED_DATA=${FIBLET_SHARED_DATA}" "FIBLET_CLI=$<TARGET_FILE:fiblet_cli>" "FIBLET_VERSION=${PROJECT_VERSION}")
endif()

# The compress speed guard (bench/instruction_budget.py): callgrind's
# instruction count of compress, default and --effort 0, within 25 % of the
# committed budget (valgrind: scripts/setup.sh).
if(DEFINED Python_EXECUTABLE)
  set(FIBLET_BUDGET_FLAGS "")
  if(FIBLET_SANITIZE)
    set(FIBLET_BUDGET_FLAGS --sanitized)
  endif()
  add_test(NAME bench.compress_instruction_budget
    COMMAND ${Python_EXECUTABLE} ${PROJECT_SOURCE_DIR}/bench/instruction_budget.py
            --fiblet $<TARGET_FILE:fiblet_cli> --tck ${FIBLET_SHARED_DATA}/small-ifod1.tck ${FIBLET_BUDGET_FLAGS})
  # Sanitized builds: a skip of the "sanitizer" category (scripts/check_skips.py).
  set_tests_properties(bench.compress_instruction_budget PROPERTIES TIMEOUT 300 SKIP_RETURN_CODE 77)
endif()

# The skip check scripts/test.sh runs after CTest (scripts/check_skips.py).
if(DEFINED Python_EXECUTABLE)
  fiblet_add_pytest(ecosystem.check_skips ${PROJECT_SOURCE_DIR}/tests/test_check_skips.py 60)
endif()

# The before/after compress timing of two binaries (scripts/bench_ab.sh).
if(DEFINED Python_EXECUTABLE)
  fiblet_add_pytest(bench.ab_script ${PROJECT_SOURCE_DIR}/tests/test_bench_ab.py 120
    ENVIRONMENT "FIBLET_CLI=$<TARGET_FILE:fiblet_cli>")
endif()

# The sections of bench/results.md, each replaced in place by its script.
if(DEFINED Python_EXECUTABLE)
  fiblet_add_pytest(bench.results_sections ${PROJECT_SOURCE_DIR}/tests/test_results_sections.py 60)
endif()

# The viewer benchmark's quick form on this machine's renderer, and the
# build it carries to a GPU machine (scripts/bench_viewer.sh).
if(DEFINED Python_EXECUTABLE AND FIBLET_BUILD_VIEWER)
  fiblet_add_pytest(bench.viewer_quick ${PROJECT_SOURCE_DIR}/tests/test_bench_viewer.py 600
    ENVIRONMENT "FIBLET_CLI=$<TARGET_FILE:fiblet_cli>" "FIBLET_ODF=${PROJECT_BINARY_DIR}/tests/phantom-fod/phantom-fod-crop.nii")
  set_tests_properties(bench.viewer_quick PROPERTIES FIXTURES_REQUIRED phantom_fod)
endif()

# --reference IMAGE gives .tck sources a space, checked through nibabel.
if(DEFINED Python_EXECUTABLE)
  fiblet_add_pytest(ecosystem.reference_space ${PROJECT_SOURCE_DIR}/tests/test_reference_space.py 120
    ENVIRONMENT "FIBLET_SHARED_DATA=${FIBLET_SHARED_DATA}" "FIBLET_CLI=$<TARGET_FILE:fiblet_cli>")
endif()
