# Start-up of a tool's process (issue 41): --help, --print-parameters and --check of a
# tool started directly start no MPI and still validate everything (docs/scaling.md).
# Label "fast": make test / CI.
set(_v ${CMAKE_CURRENT_SOURCE_DIR}/verification)
set(_w ${CMAKE_BINARY_DIR}/tests/verification)
set(_env "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMP_NUM_THREADS=1;PYTHONPATH=${_v}")
add_test(NAME verification.startup_check_without_mpi
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_startup_no_mpi.py ${TALUS_TOOLS_DIR} ${CMAKE_SOURCE_DIR}
                 ${_w}/startup_check_without_mpi)
set_tests_properties(verification.startup_check_without_mpi PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600)
