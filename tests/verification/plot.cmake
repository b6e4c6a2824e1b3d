# talus-plot and `output/png snapshots` (issue 17): PNGs announced = written, valid, of the
# requested size and not uniform; bad input exit 2 with nothing written; the coloured extent
# of a block of points against the axes mapping; 3D slice/projection; talus-fem; the soil and
# water sets of talus-semi-implicit and talus-implicit (png snapshots = final, series plots);
# png fields a family never writes refused before the run. Label "fast".
set(_v ${CMAKE_CURRENT_SOURCE_DIR}/verification)
set(_w ${CMAKE_BINARY_DIR}/tests/verification)
set(_env "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMP_NUM_THREADS=1;PYTHONPATH=${_v}")
add_test(NAME verification.plot
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_plot.py ${TALUS_TOOLS_DIR} ${_w}/plot)
set_tests_properties(verification.plot PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600)
