# Verification of the 1-phase liquid and the 2-phase coupled formulation of the
# explicit solver (issue 5, items 1-3). Label "fast": make test / CI; "verify":
# the full versions (make verify).
set(_v ${CMAKE_CURRENT_SOURCE_DIR}/verification)
set(_w ${CMAKE_BINARY_DIR}/tests/verification)
set(_env "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMP_NUM_THREADS=1;PYTHONPATH=${_v}")

function(talus_liquid_case name label script prm)
  add_test(NAME verification.${name}
           COMMAND ${Python3_EXECUTABLE} ${_v}/${script} ${TALUS_TOOLS_DIR}/talus-explicit
                   ${TALUS_PRM_DIR}/${prm} ${_w}/${name} ${ARGN})
  set_tests_properties(verification.${name} PROPERTIES LABELS "${label}" ENVIRONMENT "${_env}" TIMEOUT 1800)
endfunction()

talus_liquid_case(liquid_hydrostatic_newtonian fast check_hydrostatic.py
                  verification/hydrostatic_water_1phase.prm liquid newtonian)
talus_liquid_case(liquid_dam_break fast check_dam_break.py verification/dam_break.prm)
# the same on quadratic B-splines (issue 38; the free-surface density with the B-spline kernel)
talus_liquid_case(liquid_dam_break_bspline fast check_dam_break.py verification/dam_break.prm
                  "numerics/shape function=quadratic bspline")
talus_liquid_case(liquid_hydrostatic_bspline fast check_hydrostatic.py verification/hydrostatic_water_1phase.prm
                  liquid newtonian "numerics/shape function=quadratic bspline" "grid/upper corner=0.09375, 1.25"
                  "grid/cells=3, 40" "body 0/upper corner=0.09375, 1")
talus_liquid_case(two_phase_hydrostatic fast check_hydrostatic.py verification/hydrostatic_2phase.prm two-phase)
talus_liquid_case(two_phase_terzaghi_fast fast check_terzaghi.py verification/terzaghi_consolidation.prm fast)
talus_liquid_case(two_phase_terzaghi verify check_terzaghi.py verification/terzaghi_consolidation.prm)
# coupled 2-phase on quadratic B-splines (issue 38; docs/shape-functions.md, "2-phase on B-splines"):
# Terzaghi within 2 % (3 x 41 cells, 3 x 3 points per cell) and 1 vs 2 ranks (1e-10) on its column;
# the hydrostatic column (3 x 34 cells, 3 x 3 points per cell) at rest; the restart bitwise on 1 and
# 2 ranks of both columns (Terzaghi's: its traction point forces come from the checkpoint, not from a
# new assignment at the restart's volumes, which was an ulp off)
set(_tz_bspline "numerics/shape function=quadratic bspline" "grid/upper corner=0.075, 1.025" "grid/cells=3, 41"
                "body 0/upper corner=0.075, 1" "body 0/particles per direction=3")
set(_hy_bspline "numerics/shape function=quadratic bspline" "grid/upper corner=0.09375, 1.0625" "grid/cells=3, 34"
                "body 0/upper corner=0.09375, 1" "body 0/particles per direction=3")
talus_liquid_case(two_phase_terzaghi_bspline fast check_terzaghi.py verification/terzaghi_consolidation.prm bspline)
talus_liquid_case(two_phase_hydrostatic_bspline fast check_hydrostatic.py verification/hydrostatic_2phase.prm
                  two-phase ${_hy_bspline})
talus_liquid_case(two_phase_bspline_np1_np2 fast check_two_phase_ranks.py verification/terzaghi_consolidation.prm
                  ${_tz_bspline})
talus_liquid_case(two_phase_terzaghi_bspline_restart fast check_two_phase_restart.py
                  verification/terzaghi_consolidation.prm ${_tz_bspline})
set_tests_properties(verification.two_phase_terzaghi_bspline_restart PROPERTIES PROCESSORS 2)
talus_liquid_case(two_phase_bspline_restart fast check_two_phase_restart.py verification/hydrostatic_2phase.prm
                  ${_hy_bspline})
set_tests_properties(verification.two_phase_bspline_np1_np2 verification.two_phase_bspline_restart PROPERTIES
                     PROCESSORS 2)
talus_liquid_case(two_phase_stability fast check_stability_two_phase.py verification/terzaghi_consolidation.prm)
talus_liquid_case(undrained_column fast check_undrained.py verification/elastic_column_gravity.prm)
talus_liquid_case(two_phase_bad_input fast check_bad_input_two_phase.py verification/terzaghi_consolidation.prm)
talus_liquid_case(two_phase_np1_np2 fast check_two_phase_ranks.py verification/terzaghi_consolidation.prm)
set_tests_properties(verification.two_phase_np1_np2 PROPERTIES PROCESSORS 2)
talus_liquid_case(two_phase_terzaghi_3d verify check_terzaghi.py verification/terzaghi_consolidation.prm 3d)
talus_liquid_case(two_phase_local_damping fast check_local_damping.py verification/elastic_column_gravity.prm)
talus_liquid_case(liquid_bingham_slump verify check_bingham_slump.py verification/bingham_slump.prm)
# the shared loads in the 2-phase step (issue 12 item 2)
talus_liquid_case(two_phase_staged_consolidation fast check_two_phase_staged.py
                  verification/two_phase_staged_consolidation.prm)
add_test(NAME verification.two_phase_shared_loads
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_two_phase_loads.py ${TALUS_TOOLS_DIR}/talus-explicit
                 ${TALUS_PRM_DIR}/verification/hydrostatic_2phase.prm
                 ${TALUS_PRM_DIR}/verification/terzaghi_consolidation.prm
                 ${TALUS_PRM_DIR}/verification/block_friction.prm ${_w}/two_phase_shared_loads)
set_tests_properties(verification.two_phase_shared_loads PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 1800)
add_test(NAME verification.loads_np1_np2
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_loads_ranks.py ${TALUS_TOOLS_DIR}/talus-explicit
                 ${TALUS_PRM_DIR}/verification/hydrostatic_2phase.prm
                 ${TALUS_PRM_DIR}/verification/elastic_column_gravity.prm ${_w}/loads_np1_np2)
set_tests_properties(verification.loads_np1_np2 PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600
                     PROCESSORS 2)
