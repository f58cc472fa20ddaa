# `bbm calibrate` writes the calibrated set as a model file's [[joint_property]]:
# everything the calibration ran with must be in it, or the set a user pastes into
# a model is not the rock that was measured. Residual friction and heterogeneous
# strengths (a Weibull modulus) once went missing; the file must also read back
# as a model's joint property.
file(REMOVE_RECURSE ${DIR})
# One iteration of a small calibration into DIR/<out>; its set in `set`, which must
# hold each of the LINES.
function(calibrate_set out)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "FLAGS;LINES")
  execute_process(COMMAND ${BBM} calibrate --size 0.5 --width 2 --height 4 --iterations 1 --realizations 1
                          ${arg_FLAGS} --threads 1 --quiet --out ${DIR}/${out}
                  RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_VARIABLE stdout)
  if(NOT (status EQUAL 0 OR status EQUAL 4))
    message(FATAL_ERROR "calibrate ${arg_FLAGS} failed (${status}): ${err}")
  endif()
  file(READ ${DIR}/${out}/joint_property.toml text)
  foreach(line ${arg_LINES})
    string(FIND "${text}" "\n${line}\n" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "${out}/joint_property.toml lacks '${line}':\n${text}")
    endif()
  endforeach()
  set(set "${text}" PARENT_SCOPE)
endfunction()
calibrate_set(cal FLAGS --residual-friction 31 --weibull-m 4 --strength-classes 8
              LINES "residual_friction = 31" "weibull_modulus = 4" "strength_classes = 8" "friction = 25")
file(WRITE ${DIR}/model.toml "[[region]]\nname = \"rock\"\noutline = { type = \"rectangle\", min = [0.0, 0.0], max = [2.0, 2.0] }\npattern = { type = \"voronoi\", size = 0.5, seed = 1 }\n\n${set}\n[[joint_assignment]]\nproperty = \"calibrated\"\n")
execute_process(COMMAND ${BBM} mesh ${DIR}/model.toml --out ${DIR}/mesh --quiet
                RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "the calibrated set does not read back as a model's joint property (${status}): ${err}")
endif()

# Bonds calibrated with deformable blocks come with their blocks: the set's
# [[material]] (young, poisson, deformable_fraction), without which a user's model
# would put them between rigid blocks, a rock the calibration never measured.
calibrate_set(cal_deformable FLAGS --deformable-fraction 0.5 --young 20e9 --poisson 0.22
              LINES "[[material]]" "young = 2e+10" "poisson = 0.22" "deformable_fraction = 0.5")
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
