# A model with an error must fail with exit status 2, name file, line and key,
# and leave earlier output untouched.
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR}/out)
file(WRITE ${DIR}/out/summary.json "earlier good output\n")
file(WRITE ${DIR}/bad.toml "[[region]]\nname = \"a\"\noutline = { type = \"rectangle\", min = [0.0, 0.0], max = [1.0, 1.0] }\npattern = { type = \"voronoi\", size = -0.3 }\n")
execute_process(COMMAND ${BBM} mesh ${DIR}/bad.toml --out ${DIR}/out
                RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT status EQUAL 2)
  message(FATAL_ERROR "expected exit status 2, got ${status}: ${err}")
endif()
if(NOT err MATCHES "bad.toml:4: region\\[0\\]\\.pattern\\.size")
  message(FATAL_ERROR "message does not name file:line: key: ${err}")
endif()
file(READ ${DIR}/out/summary.json kept)
if(NOT kept STREQUAL "earlier good output\n")
  message(FATAL_ERROR "earlier output was changed")
endif()
# A geometric defect (self-intersecting outline) is reported at its line too.
file(WRITE ${DIR}/bowtie.toml "[[region]]\nname = \"a\"\noutline = { type = \"polygon\", points = [[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]] }\npattern = { type = \"single\" }\n")
execute_process(COMMAND ${BBM} mesh ${DIR}/bowtie.toml --out ${DIR}/out
                RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 2 OR NOT err MATCHES "bowtie.toml:3: region\\[0\\]\\.outline: .*intersects itself")
  message(FATAL_ERROR "self-intersection not reported as expected (${status}): ${err}")
endif()
# Lab-test options from a TOML file: a misspelt key is an error naming the file and the key.
file(WRITE ${DIR}/ucs.toml "[ucs]\nwidht = 2.0\n")
execute_process(COMMAND ${BBM} --config ${DIR}/ucs.toml ucs --quiet --out ${DIR}/ucs_out
                RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT status EQUAL 2 OR NOT err MATCHES "ucs.toml" OR NOT err MATCHES "widht")
  message(FATAL_ERROR "a bad key in --config should give status 2 naming file and key, got ${status}: ${err}")
endif()
# A rock file (--rock) with a misspelt key: status 2 naming file, line and key, for
# every command that reads one (it once aborted: the file is read while parsing).
file(WRITE ${DIR}/rock.toml "[[joint_property]]\nname = \"rock\"\nlaw = \"softening\"\nkn = 1e11\nks = 4e10\nfrictoin = 30\n")
foreach(command ucs envelope calibrate shear)
  execute_process(COMMAND ${BBM} ${command} --rock ${DIR}/rock.toml --quiet --out ${DIR}/out
                  RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_VARIABLE out)
  if(NOT status EQUAL 2 OR NOT err MATCHES "rock.toml:6: joint_property\\[0\\]\\.frictoin")
    message(FATAL_ERROR "bbm ${command} --rock with a misspelt key should give status 2 naming file:line: key, "
                        "got ${status}: ${err}")
  endif()
endforeach()
# A flag in a --config file is read as on the command line: fit-curvature with one
# confined target is refused, naming the flag (it was once silently ignored).
file(WRITE ${DIR}/curvature.toml "[calibrate]\ntarget-mi = 10\ntarget-mi-confinements = [5e6]\nfit-curvature = true\n")
execute_process(COMMAND ${BBM} --check --config ${DIR}/curvature.toml calibrate --quiet --out ${DIR}/calibrate_out
                RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_VARIABLE out)
if(NOT status EQUAL 2 OR NOT err MATCHES "--fit-curvature")
  message(FATAL_ERROR "fit-curvature = true in --config with one confined target should give status 2 naming "
                      "--fit-curvature, got ${status}: ${err}")
endif()
# Ctrl-C stops a lab test at once (it has no checkpoint): exit status 130, nothing written.
# The paper's specimen loaded 5 times slower than by default takes some 100,000 steps,
# most of a minute; the signal comes after 3 s, during its set-up or early loading (the
# flag waits for the loop). With the signal after 1 s the test failed once, beside a long
# test on both cores (its output not kept, not reproduced since): 3 s leave start-up room.
file(REMOVE_RECURSE ${DIR}/interrupted)
execute_process(COMMAND timeout --preserve-status -s INT 3 ${BBM} ucs --quiet --threads 1 --strain-rate 1e-8
                        --out ${DIR}/interrupted
                RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 130 OR NOT err MATCHES "interrupted" OR EXISTS ${DIR}/interrupted/summary.json)
  message(FATAL_ERROR "SIGINT during bbm ucs should stop it with status 130 and no summary, got ${status}: ${err}")
endif()
# bbm shear: a bad combination of flags names the flag, exits 2 and keeps earlier output.
execute_process(COMMAND ${BBM} shear --pattern single --persistence 0.5 --quiet --out ${DIR}/out
                RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 2 OR NOT err MATCHES "--persistence")
  message(FATAL_ERROR "bbm shear with a single pattern and rock bridges should name --persistence (${status}): ${err}")
endif()
file(READ ${DIR}/out/summary.json kept)
if(NOT kept STREQUAL "earlier good output\n")
  message(FATAL_ERROR "bbm shear changed earlier output")
endif()
# bbm compare --envelope: a model whose rock a specimen cannot carry (trigon radial
# and peripheral joints of different properties) is refused before anything runs,
# naming the file and the rule; earlier output stays.
file(WRITE ${DIR}/two_bonds.toml "[[region]]\nname = \"rock\"\noutline = { type = \"rectangle\", min = [0.0, 0.0], max = [2.0, 2.0] }\npattern = { type = \"trigon\", size = 0.5 }\n[[joint_property]]\nname = \"bond\"\nlaw = \"softening\"\nkn = 1e10\nks = 1e10\ntensile = 1e6\ncohesion = 2e6\n[[joint_property]]\nname = \"weak\"\nlaw = \"softening\"\nkn = 1e10\nks = 1e10\ntensile = 1e5\ncohesion = 2e5\n[[joint_assignment]]\nproperty = \"bond\"\n[[joint_assignment]]\nproperty = \"weak\"\ntags = [\"radial\"]\n[[stage]]\nname = \"s\"\ntype = \"solve\"\nmax_steps = 10\n")
execute_process(COMMAND ${BBM} compare ${DIR}/two_bonds.toml --envelope --quiet --out ${DIR}/out
                RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 2 OR NOT err MATCHES "two_bonds.toml:[0-9]+: joint_assignment\\[1\\]: .*radial and peripheral")
  message(FATAL_ERROR "bbm compare --envelope should refuse two bonds naming file, line and rule (${status}): ${err}")
endif()
execute_process(COMMAND ${BBM} compare ${DIR}/two_bonds.toml --envelope --envelope-confinements 2e6,-1e6 --quiet --out ${DIR}/out
                RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 2 OR NOT err MATCHES "--envelope-confinements")
  message(FATAL_ERROR "a negative --envelope-confinements should name the flag (${status}): ${err}")
endif()
file(READ ${DIR}/out/summary.json kept)
if(NOT kept STREQUAL "earlier good output\n")
  message(FATAL_ERROR "bbm compare --envelope changed earlier output")
endif()
