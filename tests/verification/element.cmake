# talus-element: a Mohr-Coulomb drained triaxial test against the closed form,
# and a broken .prm that must be rejected with exit status 2.
add_test(NAME verification.element.mc_drained_triaxial
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/verification/check_element_csv.py
                 mc-triaxial ${TALUS_TOOLS_DIR}/talus-element
                 ${TALUS_PRM_DIR}/element/mc_drained_triaxial.prm
                 ${CMAKE_CURRENT_BINARY_DIR}/element_mc
                 --c 5e3 --phi 30 --psi 10 --sigma3 100e3)
add_test(NAME verification.element.broken_prm
         COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/verification/check_element_csv.py
                 broken ${TALUS_TOOLS_DIR}/talus-element
                 ${TALUS_PRM_DIR}/element/mc_broken.prm
                 ${CMAKE_CURRENT_BINARY_DIR}/element_broken)
set_tests_properties(verification.element.mc_drained_triaxial verification.element.broken_prm
                     PROPERTIES LABELS "fast" TIMEOUT 120)
