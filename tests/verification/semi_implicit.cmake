# Verification of the semi-implicit two-phase double-point family (issue 14).
# Label "fast": make test / CI; "verify": the full versions (make verify).
set(_v ${CMAKE_CURRENT_SOURCE_DIR}/verification)
set(_w ${CMAKE_BINARY_DIR}/tests/verification)
set(_env "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMP_NUM_THREADS=1;PYTHONPATH=${_v}")

# geostatic saturated column at rest for k = 1e-3 and 1e-7 m/s at the same step;
# the explicit 2-phase critical step of the same scene printed beside it
add_test(NAME verification.semi_implicit_hydrostatic
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_semi_hydrostatic.py ${TALUS_TOOLS_DIR}/talus-semi-implicit
                 ${TALUS_PRM_DIR}/verification/semi_implicit_hydrostatic.prm ${_w}/semi_implicit_hydrostatic
                 ${TALUS_TOOLS_DIR}/talus-critical-dt
                 ${TALUS_PRM_DIR}/verification/semi_implicit_hydrostatic_explicit.prm)
set_tests_properties(verification.semi_implicit_hydrostatic PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600)
