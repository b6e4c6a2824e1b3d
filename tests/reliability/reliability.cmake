# Reliability checks (issue 7). The .prm fuzz test (tests/reliability/fuzz_prm.py):
# a fast subset in "fast" (CI), the full set in "verify". In the sanitizer build
# (TALUS_SANITIZE=ON, `make sanitize`) the short runs of every tool and the fast
# fuzz subset under ASan+UBSan are labelled "sanitize".
set(_r ${CMAKE_CURRENT_SOURCE_DIR}/reliability)
set(_rw ${CMAKE_BINARY_DIR}/tests/reliability)
set(_renv "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMP_NUM_THREADS=1;PYTHONPATH=${CMAKE_CURRENT_SOURCE_DIR}/verification")

if(NOT TALUS_SANITIZE)
  add_test(NAME reliability.fuzz_prm_fast
           COMMAND ${Python3_EXECUTABLE} ${_r}/fuzz_prm.py --subset fast --jobs 2 --tools-dir ${TALUS_TOOLS_DIR}
                   --prm-dir ${TALUS_PRM_DIR} --workdir ${_rw}/fuzz_fast)
  set_tests_properties(reliability.fuzz_prm_fast PROPERTIES LABELS "fast" ENVIRONMENT "${_renv}" TIMEOUT 600 PROCESSORS 2)
  add_test(NAME reliability.fuzz_prm_full
           COMMAND ${Python3_EXECUTABLE} ${_r}/fuzz_prm.py --subset full --jobs 2 --tools-dir ${TALUS_TOOLS_DIR}
                   --prm-dir ${TALUS_PRM_DIR} --workdir ${_rw}/fuzz_full)
  set_tests_properties(reliability.fuzz_prm_full PROPERTIES LABELS "verify" ENVIRONMENT "${_renv}" TIMEOUT 1800 PROCESSORS 2)
else()
  # LeakSanitizer: the MPI stack keeps its start-up allocations until exit
  set(_senv "${_renv};LSAN_OPTIONS=suppressions=${_r}/lsan.supp:print_suppressions=0;UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1;ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:fast_unwind_on_malloc=0")
  add_test(NAME sanitize.tools_smoke
           COMMAND ${Python3_EXECUTABLE} ${_r}/sanitize_smoke.py ${TALUS_TOOLS_DIR} ${TALUS_PRM_DIR} ${_rw}/smoke)
  set_tests_properties(sanitize.tools_smoke PROPERTIES LABELS "sanitize" ENVIRONMENT "${_senv}" TIMEOUT 3600)
  add_test(NAME sanitize.fuzz_prm_fast
           COMMAND ${Python3_EXECUTABLE} ${_r}/fuzz_prm.py --subset fast --jobs 2 --timeout 120
                   --tools-dir ${TALUS_TOOLS_DIR} --prm-dir ${TALUS_PRM_DIR} --workdir ${_rw}/fuzz_fast)
  set_tests_properties(sanitize.fuzz_prm_fast PROPERTIES LABELS "sanitize" ENVIRONMENT "${_senv}" TIMEOUT 3600 PROCESSORS 2)
  # the unit tests (label "unit") run under the sanitizers with the same options
  get_property(_tests DIRECTORY PROPERTY TESTS)
  foreach(_t ${_tests})
    if(_t MATCHES "^unit\\.")
      set_tests_properties(${_t} PROPERTIES ENVIRONMENT "${_senv}")
    endif()
  endforeach()
endif()
