# The implicit updated-Lagrangian family (talus-implicit, issue 13). Label "fast"
# for the CI subset, "verify" for the full versions (make verify).
set(_v ${CMAKE_CURRENT_SOURCE_DIR}/verification)
set(_w ${CMAKE_BINARY_DIR}/tests/verification)
set(_env "OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMP_NUM_THREADS=1;PYTHONPATH=${_v}")

# static cantilever under self-weight (seed 001 §4.5.1): quadratic Newton, tip
# deflection vs the thesis, observed order over three grids
add_test(NAME verification.implicit_cantilever
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_implicit_cantilever.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/implicit/cantilever_self_weight.prm ${_w}/implicit_cantilever 0.005 0.5 0.25 0.125 0.0625)
set_tests_properties(verification.implicit_cantilever PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 900)
add_test(NAME verification.implicit_cantilever_full
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_implicit_cantilever.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/implicit/cantilever_self_weight.prm ${_w}/implicit_cantilever_full 0.0005
                 0.5 0.25 0.125 0.0625 0.03125)
set_tests_properties(verification.implicit_cantilever_full PROPERTIES LABELS "verify" ENVIRONMENT "${_env}" TIMEOUT 3600)

# 1 vs 2 ranks: the cantilever (static) and the bar (dynamic)
add_test(NAME verification.implicit_ranks_cantilever
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_implicit_ranks.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/implicit/cantilever_self_weight.prm ${_w}/implicit_ranks_cantilever
                 "grid/cells=34, 10")
set_tests_properties(verification.implicit_ranks_cantilever PROPERTIES LABELS "fast" ENVIRONMENT "${_env}"
                     TIMEOUT 900 PROCESSORS 2)
add_test(NAME verification.implicit_ranks_bar
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_implicit_ranks.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/implicit/bar_vibration.prm ${_w}/implicit_ranks_bar)
set_tests_properties(verification.implicit_ranks_bar PROPERTIES LABELS "fast" ENVIRONMENT "${_env}"
                     TIMEOUT 900 PROCESSORS 2)

# dynamic: first axial mode of an elastic bar at 10 x the explicit critical step:
# period = the exact period stretched by the trapezoidal rule, energy conserved
add_test(NAME verification.implicit_bar_vibration
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_implicit_bar.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/implicit/bar_vibration.prm ${_w}/implicit_bar_vibration)
set_tests_properties(verification.implicit_bar_vibration PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600)

# bad input, Newton failure, singular system: messages, exit codes, no NaN
add_test(NAME verification.implicit_bad_input
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_implicit_bad_input.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/implicit/cantilever_self_weight.prm ${_w}/implicit_bad_input)
set_tests_properties(verification.implicit_bad_input PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600)

# tractions (loads/point_forces): oedometric block under a top traction, u_y and
# sigma_yy vs the small-strain answer, on 1 and 2 ranks
add_test(NAME verification.implicit_traction
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_implicit_traction.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/implicit/block_top_traction.prm ${_w}/implicit_traction 1e-3)
set_tests_properties(verification.implicit_traction PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 600
                     PROCESSORS 2)

# Cook's membrane (seed 001 §5.4.1, Table 5.1): u locks at nu = 0.499999, the
# stabilised u-p does not; u-p at the finest resolution vs 0.323 / 0.275
add_test(NAME verification.implicit_cooks_membrane
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_implicit_cooks.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/implicit/cooks_membrane.prm ${_w}/implicit_cooks_membrane 0.035 2 4 8 16 32)
set_tests_properties(verification.implicit_cooks_membrane PROPERTIES LABELS "fast" ENVIRONMENT "${_env}" TIMEOUT 900)
add_test(NAME verification.implicit_cooks_membrane_full
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_implicit_cooks.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/implicit/cooks_membrane.prm ${_w}/implicit_cooks_membrane_full 0.02 2 4 8 16 32 64)
set_tests_properties(verification.implicit_cooks_membrane_full PROPERTIES LABELS "verify" ENVIRONMENT "${_env}"
                     TIMEOUT 3600)
# 1 vs 2 ranks on Cook's membrane (u-p, nu = 0.499999, n = 16)
add_test(NAME verification.implicit_ranks_cooks
         COMMAND ${Python3_EXECUTABLE} ${_v}/check_implicit_ranks.py ${TALUS_TOOLS_DIR}
                 ${TALUS_PRM_DIR}/implicit/cooks_membrane.prm ${_w}/implicit_ranks_cooks)
set_tests_properties(verification.implicit_ranks_cooks PROPERTIES LABELS "fast" ENVIRONMENT "${_env}"
                     TIMEOUT 900 PROCESSORS 2)
