# FEM on the same grid (numerics/integration = fem | ul-fem, talus-fem), results
# files and talus-compare (issue 4). Label "fast".
set(_v ${CMAKE_CURRENT_SOURCE_DIR}/verification)
set(_w ${CMAKE_BINARY_DIR}/tests/verification)
set(_env "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMP_NUM_THREADS=1;PYTHONPATH=${_v}")

# cantilever under self-weight vs Timoshenko: FEM 2 %, MPM 3 % (issue 4)
foreach(_mode_tol "fem;0.02" "ul-fem;0.02" "mpm;0.03")
  list(GET _mode_tol 0 _mode)
  list(GET _mode_tol 1 _tol)
  add_test(NAME verification.fem_cantilever_${_mode}
           COMMAND ${Python3_EXECUTABLE} ${_v}/check_fem_cantilever.py ${TALUS_TOOLS_DIR}
                   ${TALUS_PRM_DIR}/verification/cantilever_self_weight.prm ${_w}/fem_cantilever_${_mode} ${_mode} ${_tol})
  set_tests_properties(verification.fem_cantilever_${_mode} PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 900)
endforeach()

# oedometer under gravity: MPM, FEM, UL-FEM vs analytic and each other; talus-compare exit codes
add_test(NAME verification.fem_oedometer_box
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_fem_oedometer.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/verification/oedometer_gravity.prm ${_w}/fem_oedometer_box)
set_tests_properties(verification.fem_oedometer_box PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 900 PROCESSORS 2)
# the same on the gmsh mesh (meshes/oedometer_2d.geo -> talus-mesh -> grid + particle files)
add_test(NAME verification.fem_oedometer_gmsh
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_fem_oedometer.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/verification/oedometer_gravity.prm ${_w}/fem_oedometer_gmsh
                 ${TALUS_PRM_DIR}/mesh/oedometer_2d.prm)
set_tests_properties(verification.fem_oedometer_gmsh PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 900)

# parameter_files/examples/Makefile: the chain runs, a second make does nothing
add_test(NAME verification.examples_makefile
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_examples_makefile.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/examples ${_w}/examples_makefile)
set_tests_properties(verification.examples_makefile PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600)

# 3D (hexahedra): column under gravity with fem, ul-fem, mpm
add_test(NAME verification.fem_column_3d
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_fem_column_3d.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/verification/elastic_column_gravity_3d.prm ${_w}/fem_column_3d)
set_tests_properties(verification.fem_column_3d PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600)

# mesh convergence of the cantilever (FEM quadratic, MPM below 1 % on the finest grid); long: label verify
add_test(NAME verification.fem_cantilever_convergence
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_fem_cantilever_convergence.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/verification/cantilever_self_weight.prm ${_w}/fem_cantilever_convergence)
set_tests_properties(verification.fem_cantilever_convergence PROPERTIES LABELS "verify" ENVIRONMENT "${_env}" TIMEOUT 1800)
