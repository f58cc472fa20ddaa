# `bbm calibrate` writes the calibrated set as a model file's [[joint_property]]:
# everything the calibration ran with must be in it, or the set a user pastes into
# a model is not the rock that was measured. Residual friction and heterogeneous
# strengths (a Weibull modulus) once went missing; the file must also read back
# as a model's joint property.
file(REMOVE_RECURSE ${DIR})
execute_process(COMMAND ${BBM} calibrate --size 0.5 --width 2 --height 4 --iterations 1 --realizations 1
                        --residual-friction 31 --weibull-m 4 --strength-classes 8 --threads 1 --quiet --out ${DIR}/cal
                RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT (status EQUAL 0 OR status EQUAL 4))
  message(FATAL_ERROR "calibrate failed (${status}): ${err}")
endif()
file(READ ${DIR}/cal/joint_property.toml set)
foreach(line "residual_friction = 31" "weibull_modulus = 4" "strength_classes = 8" "friction = 25")
  string(FIND "${set}" "\n${line}\n" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "joint_property.toml lacks '${line}':\n${set}")
  endif()
endforeach()
file(WRITE ${DIR}/model.toml "[[region]]\nname = \"rock\"\noutline = { type = \"rectangle\", min = [0.0, 0.0], max = [2.0, 2.0] }\npattern = { type = \"voronoi\", size = 0.5, seed = 1 }\n\n${set}\n[[joint_assignment]]\nproperty = \"calibrated\"\n")
execute_process(COMMAND ${BBM} mesh ${DIR}/model.toml --out ${DIR}/mesh --quiet
                RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "the calibrated set does not read back as a model's joint property (${status}): ${err}")
endif()

# Bonds calibrated with deformable blocks come with their blocks: the set's
# [[material]] (young, poisson, deformable_fraction), without which a user's model
# would put them between rigid blocks, a rock the calibration never measured.
execute_process(COMMAND ${BBM} calibrate --size 0.5 --width 2 --height 4 --iterations 1 --realizations 1
                        --deformable-fraction 0.5 --young 20e9 --poisson 0.22 --threads 1 --quiet --out ${DIR}/cal_deformable
                RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT (status EQUAL 0 OR status EQUAL 4))
  message(FATAL_ERROR "deformable calibrate failed (${status}): ${err}")
endif()
file(READ ${DIR}/cal_deformable/joint_property.toml set)
foreach(line "[[material]]" "young = 2e+10" "poisson = 0.22" "deformable_fraction = 0.5")
  string(FIND "${set}" "\n${line}\n" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the deformable set lacks '${line}':\n${set}")
  endif()
endforeach()
# ... and a lab test reads it back as that rock: the same seed's UCS test gives
# the modulus the calibration measured on it, to the last digit. (Read as rigid
# blocks, without the [[material]], it gives 20.58 against 20.45 GPa: the split is
# built to keep E, so only an exact match tells the rock apart.)
file(READ ${DIR}/cal_deformable/calibration.json record)
string(JSON calibrated_E GET "${record}" iterations 0 E_ucs_curve)
execute_process(COMMAND ${BBM} ucs --rock ${DIR}/cal_deformable/joint_property.toml --size 0.5 --width 2 --height 4
                        --seed 1 --max-strain 2e-4 --threads 1 --quiet --out ${DIR}/ucs_deformable
                RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "bbm ucs --rock with the deformable set failed (${status}): ${err}")
endif()
file(READ ${DIR}/ucs_deformable/summary.json summary)
string(JSON measured_E GET "${summary}" E)
if(NOT measured_E STREQUAL calibrated_E)
  message(FATAL_ERROR "bbm ucs --rock with the deformable set: E ${measured_E}, the calibration measured ${calibrated_E}")
endif()
