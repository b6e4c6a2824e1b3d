# The scene layer shared by the three families (issue 37): one scene fragment
# solved by every family, the shared vocabulary refused alike by every tool.
# Label "fast": make test / CI.
set(_v ${CMAKE_CURRENT_SOURCE_DIR}/verification)
set(_w ${CMAKE_BINARY_DIR}/tests/verification)
set(_env "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMP_NUM_THREADS=1;PYTHONPATH=${_v}")

# one scene, three tools: the elastic layer loaded through a rigid plate
# (parameter_files/verification/rigid_plate/layer.inc) by talus-explicit (to
# rest), talus-implicit (static) and talus-semi-implicit (drained, end of
# consolidation): plate settlement within 1 % of q H / E_oed and of each
# other; every formulation tool accepts --restart
add_test(NAME verification.rigid_plate_families
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_rigid_plate_families.py ${TALUS_TOOLS_DIR} ${TALUS_PRM_DIR}
                 ${_w}/rigid_plate_families 0.01)
set_tests_properties(verification.rigid_plate_families PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 900)

# bad rigid-plate entries: exit 2 naming the entry, nothing written, in every family
add_test(NAME verification.rigid_plate_bad_input
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_rigid_plate_input.py ${TALUS_TOOLS_DIR} ${TALUS_PRM_DIR}
                 ${_w}/rigid_plate_bad_input)
set_tests_properties(verification.rigid_plate_bad_input PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600)

# one initial-stress entry, three tools: the K0 column of
# parameter_files/verification/initial_stress/column.inc stays at rest in
# every family (against the stress-free release), sigma_xx / sigma_yy = K0, and
# the shared entry's refusals
add_test(NAME verification.initial_stress_families
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_initial_stress_families.py ${TALUS_TOOLS_DIR} ${TALUS_PRM_DIR}
                 ${_w}/initial_stress_families)
set_tests_properties(verification.initial_stress_families PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600)

# one .prm vocabulary (issue 37 item 2): the same 'damping' / 'material k/pore liquid'
# fragment (parameter_files/verification/vocabulary/*.inc) accepted by the tools that
# honour it (the value seen in the run) and refused with exit 2 by the others
add_test(NAME verification.vocabulary_fragments
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_vocabulary.py ${TALUS_TOOLS_DIR} ${TALUS_PRM_DIR}
                 ${_w}/vocabulary_fragments)
set_tests_properties(verification.vocabulary_fragments PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 900)

# point loads (loads/point load k) in every family: the block of
# parameter_files/verification/point_load/block.inc, its base reaction equal to
# the point load (implicit static 1e-8, explicit at rest and semi-implicit at the
# end of consolidation 1 %), the same point chosen on 1 and 2 ranks (implicit
# series 1e-10); bad entries refused alike (exit 2 naming the entry, nothing written)
add_test(NAME verification.point_load_families
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_point_load_families.py ${TALUS_TOOLS_DIR} ${TALUS_PRM_DIR}
                 ${_w}/point_load_families 0.01)
set_tests_properties(verification.point_load_families PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 900)
add_test(NAME verification.point_load_bad_input
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_point_load_input.py ${TALUS_TOOLS_DIR} ${TALUS_PRM_DIR}
                 ${_w}/point_load_bad_input)
set_tests_properties(verification.point_load_bad_input PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600)

# the composability matrix of talus-explicit (issue 38 item 4): every feature alone under every
# option set (kernel, velocity transfer, stabilisation) for 6 steps; each pair runs and conserves
# mass (and momentum where nothing external acts) or is refused with exit 2 naming the entry;
# docs/composability.md must equal the generated table (`make composability` rewrites it)
add_test(NAME verification.composability_matrix
         COMMAND ${Python3_EXECUTABLE} ${_v}/composability.py ${TALUS_TOOLS_DIR}/talus-explicit
                 ${_w}/composability_matrix --check ${CMAKE_SOURCE_DIR}/docs/composability.md)
set_tests_properties(verification.composability_matrix PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" PROCESSORS 2
                     TIMEOUT 900)
