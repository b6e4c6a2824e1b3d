# Mesh preparation (issue 4): talus-mesh on gmsh meshes, talus-explicit from its
# files, broken meshes refused. Label "fast" (each takes a few seconds).
set(_v ${CMAKE_CURRENT_SOURCE_DIR}/verification)
set(_w ${CMAKE_BINARY_DIR}/tests/verification)
set(_env "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMP_NUM_THREADS=1;PYTHONPATH=${_v}")

function(talus_mesh_case name script)
  add_test(NAME verification.${name}
           COMMAND ${Python3_EXECUTABLE} ${_v}/${script} ${TALUS_TOOLS_DIR} ${CMAKE_SOURCE_DIR} ${_w}/${name})
  set_tests_properties(verification.${name} PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600)
endfunction()

talus_mesh_case(mesh_groups_volumes_np1_np2 check_mesh_groups.py)
talus_mesh_case(mesh_column_from_files check_mesh_column.py)
talus_mesh_case(mesh_broken_inputs check_mesh_broken.py)

# the unit test of grid files and mesh preparation reads meshes/*.geo
target_compile_definitions(test_mesh_io PRIVATE TALUS_SOURCE_DIR="${CMAKE_SOURCE_DIR}")
