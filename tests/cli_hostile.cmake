# Hostile command lines and model files (issue 14): each must exit with status 2,
# name the option or file:line:key with a message a person can read, and create
# no output. Run as: cmake -DBBM=... -DDIR=... -DMODEL=examples/tunnel_voronoi.toml -P
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})

# "arguments (space-separated) | regular expression the message must match"
set(cases
  "ucs --kn nan|--kn: must be a finite number > 0 Pa/m, got nan"
  "ucs --ks -1|--ks: must be a finite number > 0 Pa/m, got -1"
  "ucs --tensile inf|--tensile: must be a finite number >= 0 Pa, got inf"
  "ucs --friction nan|--friction: must be a finite number in .0, 90. degrees, got nan"
  "ucs --friction 95|--friction: must be a finite number in .0, 90. degrees, got 95"
  "ucs --strain-rate nan|--strain-rate: must be a finite number > 0"
  "ucs --density nan|--density: must be a finite number > 0"
  "ucs --size nan|--size: must be a finite number > 0 m, got nan"
  "ucs --size 0|--size: must be a finite number > 0 m, got 0"
  "ucs --seed -3|--seed: must be a whole number >= 0, got -3"
  "ucs --seed 1.5|--seed: must be a whole number >= 0, got 1.5"
  "ucs --lloyd -1|--lloyd: must be a whole number in .0, 2147483647., got -1"
  "ucs --width 0|--width: must be a finite number > 0"
  "ucs --height 1e400|--height: must be a finite number > 0"
  "ucs --size 1e-5|--size: the specimen asks for about .* blocks .* over the limit"
  "ucs --size 5|--size: blocks of 5 m do not fit a specimen 8 m x 16 m"
  "ucs --max-elements 100|--size: the specimen asks for about .* over the limit of 100 \\(--max-elements\\)"
  "ucs --deformable-fraction 0.5 --mesh-size 1e-6|--mesh-size: the specimen asks for about .* triangles"
  "ucs --deformable-fraction nan|--deformable-fraction: must be a finite number in .0, 1.,"
  "ucs --poisson 0.5|--poisson: must be a finite number in .0, 0.5., got 0.5"
  "ucs --tension-softening nan,1.7,4|--tension-softening"
  "ucs --stop-fraction -0.1|--stop-fraction: must be a finite number in \\[0, 1\\]"
  "tension --max-strain -1|--max-strain: must be a finite number > 0"
  "biaxial --confinement nan|--confinement: must be a finite number >= 0"
  "brazilian --width inf|--width: must be a finite number > 0"
  "calibrate --target-nu 0.5|--target-nu: must be a finite number in \\[0.01, 0.33\\]"
  "calibrate --target-E nan|--target-E: must be a finite number > 0"
)
set(i 0)
foreach(case IN LISTS cases)
  math(EXPR i "${i} + 1")
  string(FIND "${case}" "|" bar)
  string(SUBSTRING "${case}" 0 ${bar} args)
  math(EXPR after "${bar} + 1")
  string(SUBSTRING "${case}" ${after} -1 expected)
  separate_arguments(args UNIX_COMMAND "${args}")
  set(out ${DIR}/out_${i})
  execute_process(COMMAND ${BBM} ${args} --quiet --out ${out}
                  RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_VARIABLE stdout TIMEOUT 60)
  if(NOT status EQUAL 2)
    message(FATAL_ERROR "bbm ${args}: expected exit status 2, got ${status}: ${err}${stdout}")
  endif()
  if(NOT "${err}${stdout}" MATCHES "${expected}")
    message(FATAL_ERROR "bbm ${args}: message does not match '${expected}': ${err}${stdout}")
  endif()
  if(EXISTS ${out})
    message(FATAL_ERROR "bbm ${args}: refused, but created ${out}")
  endif()
endforeach()

# The paper's tunnel with one value changed: "text=>replacement | line: key the message names | message".
file(READ ${MODEL} model)
set(edits
  "mesh = { size = 0.3,=>mesh = { size = 1e-6,|:40: region\\[0\\]\\.mesh\\.size|asks for about .* triangles"
  "type = \"voronoi\", size = 0.3, seed = 7=>type = \"voronoi\", size = 1e-5, seed = 7|:47: region\\[1\\]\\.pattern\\.size|asks for about .* blocks"
  "type = \"voronoi\", size = 0.3, seed = 7=>type = \"voronoi\", size = 1e300, seed = 7|:47: region\\[1\\]\\.pattern\\.size|too large for region 'bonded'"
  "type = \"voronoi\", size = 0.3, seed = 7=>type = \"voronoi\", size = 30, seed = 7|:47: region\\[1\\]\\.pattern\\.size|too large for region 'bonded'"
)
set(k 0)
foreach(edit IN LISTS edits)
  math(EXPR k "${k} + 1")
  string(REPLACE "|" ";" parts "${edit}")
  list(GET parts 0 replace)
  list(GET parts 1 where)
  list(GET parts 2 expected)
  string(FIND "${replace}" "=>" eq)
  string(SUBSTRING "${replace}" 0 ${eq} from)
  math(EXPR after "${eq} + 2")
  string(SUBSTRING "${replace}" ${after} -1 to)
  string(FIND "${model}" "${from}" found)
  if(found EQUAL -1)
    message(FATAL_ERROR "the model no longer holds '${from}': update this test")
  endif()
  string(REPLACE "${from}" "${to}" changed "${model}")
  file(WRITE ${DIR}/model_${k}.toml "${changed}")
  foreach(command mesh run)
    set(out ${DIR}/model_out_${k}_${command})
    execute_process(COMMAND ${BBM} ${command} ${DIR}/model_${k}.toml --quiet --out ${out}
                    RESULT_VARIABLE status ERROR_VARIABLE err TIMEOUT 60)
    if(NOT status EQUAL 2 OR NOT err MATCHES "model_${k}.toml${where}: .*${expected}")
      message(FATAL_ERROR "bbm ${command} with '${to}': expected status 2 and 'model_${k}.toml${where}: ${expected}', got ${status}: ${err}")
    endif()
    if(EXISTS ${out})
      message(FATAL_ERROR "bbm ${command} with '${to}': refused, but created ${out}")
    endif()
  endforeach()
endforeach()

# The limit is the model's to raise, or lower: [model] max_elements.
string(REPLACE "[model]" "[model]\nmax_elements = 100" changed "${model}")
file(WRITE ${DIR}/limited.toml "${changed}")
execute_process(COMMAND ${BBM} mesh ${DIR}/limited.toml --quiet --out ${DIR}/limited_out
                RESULT_VARIABLE status ERROR_VARIABLE err TIMEOUT 60)
if(NOT status EQUAL 2 OR NOT err MATCHES "over the limit of 100 set by max_elements")
  message(FATAL_ERROR "[model] max_elements = 100 should refuse the tunnel, got ${status}: ${err}")
endif()

# A stress no joint can carry: a numerical failure named by its cause (exit 3),
# the output kept and marked incomplete.
string(REPLACE "syy = -15.529740e6" "syy = -1e300" changed "${model}")
file(WRITE ${DIR}/huge_stress.toml "${changed}")
execute_process(COMMAND ${BBM} run ${DIR}/huge_stress.toml --quiet --out ${DIR}/huge_stress_out
                RESULT_VARIABLE status ERROR_VARIABLE err TIMEOUT 120)
if(NOT status EQUAL 3 OR NOT err MATCHES "beyond what the joints and zones can carry")
  message(FATAL_ERROR "syy = -1e300: expected exit 3 naming the load, got ${status}: ${err}")
endif()
file(READ ${DIR}/huge_stress_out/summary.json summary)
if(NOT summary MATCHES "\"complete\": false")
  message(FATAL_ERROR "syy = -1e300: summary.json not marked incomplete: ${summary}")
endif()

# Files that are no model at all: empty, binary garbage, 30 MB of comments.
file(WRITE ${DIR}/empty.toml "")
string(ASCII 255 254 1 2 3 200 201 128 129 10 91 91 255 93 garbage)
string(REPEAT "${garbage}" 500 garbage)
file(WRITE ${DIR}/garbage.toml "${garbage}")
string(REPEAT "# a comment line of a huge file, and nothing else\n" 600000 huge)
file(WRITE ${DIR}/huge.toml "${huge}")
foreach(pair "empty.toml|empty.toml: region: a model needs at least one \\[\\[region\\]\\] table"
             "garbage.toml|garbage.toml:1: TOML syntax error"
             "huge.toml|huge.toml: region: a model needs at least one \\[\\[region\\]\\] table")
  string(REPLACE "|" ";" parts "${pair}")
  list(GET parts 0 name)
  list(GET parts 1 expected)
  foreach(command mesh run)
    execute_process(COMMAND ${BBM} ${command} ${DIR}/${name} --quiet --out ${DIR}/out_${name}
                    RESULT_VARIABLE status ERROR_VARIABLE err TIMEOUT 60)
    if(NOT status EQUAL 2 OR NOT err MATCHES "${expected}")
      message(FATAL_ERROR "bbm ${command} ${name}: expected status 2 and '${expected}', got ${status}: ${err}")
    endif()
    if(EXISTS ${DIR}/out_${name})
      message(FATAL_ERROR "bbm ${command} ${name}: refused, but created output")
    endif()
  endforeach()
endforeach()

# An output path that is a file: status 2 naming --out, the file untouched.
file(WRITE ${DIR}/a_file "not a directory\n")
foreach(command "mesh;${MODEL}" "run;${MODEL}" "ucs;--max-strain;1e-5")
  execute_process(COMMAND ${BBM} ${command} --quiet --out ${DIR}/a_file
                  RESULT_VARIABLE status ERROR_VARIABLE err TIMEOUT 120)
  if(NOT status EQUAL 2 OR NOT err MATCHES "--out: .*a_file is a file, not a directory")
    message(FATAL_ERROR "bbm ${command} --out FILE: expected status 2 naming --out, got ${status}: ${err}")
  endif()
endforeach()
file(READ ${DIR}/a_file kept)
if(NOT kept STREQUAL "not a directory\n")
  message(FATAL_ERROR "the file given as --out was changed")
endif()

# --check: a valid model and valid options pass (status 0) and write nothing; so do
# the shipped laboratory files (examples/lab/: calibration options, and a calibrated
# set read as a rock).
get_filename_component(EXAMPLES ${MODEL} DIRECTORY)
# One command a list item, its arguments joined by "|".
set(checked_commands "run|${MODEL}" "mesh|${MODEL}" "ucs|--pattern|trigon" "calibrate|--target-E|20e9"
    "envelope|--rock|${EXAMPLES}/lab/paper_rock_hoek_brown_set.toml")
file(GLOB lab_files ${EXAMPLES}/lab/*.toml)
foreach(lab_file ${lab_files})
  file(READ ${lab_file} lab_text)
  if(lab_text MATCHES "\\[calibrate\\]")
    list(APPEND checked_commands "--config|${lab_file}|calibrate")
  endif()
endforeach()
foreach(joined IN LISTS checked_commands)
  string(REPLACE "|" ";" command "${joined}")
  execute_process(COMMAND ${BBM} --check ${command} --quiet --out ${DIR}/checked
                  RESULT_VARIABLE status ERROR_VARIABLE err TIMEOUT 120)
  if(NOT status EQUAL 0 OR EXISTS ${DIR}/checked)
    message(FATAL_ERROR "bbm --check ${command}: expected status 0 and no output, got ${status}: ${err}")
  endif()
endforeach()
