# docs/reference/commands.md is generated from the program's own help: `bbm --help`
# and `bbm <command> --help` for every command it lists. This test fails when the
# file is stale; with -DWRITE=1 it rewrites it:
#   cmake -DBBM=build/apps/bbm -DREFERENCE=docs/reference/commands.md -DWRITE=1 -P tests/cli_reference.cmake
cmake_minimum_required(VERSION 3.20)

function(help_of out)
  execute_process(COMMAND ${BBM} ${ARGN} --help OUTPUT_VARIABLE text ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "bbm ${ARGN} --help exited ${rc}: ${err}")
  endif()
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

help_of(top)
# The commands: the lines of the "Subcommands:" block, two spaces then the name.
string(FIND "${top}" "Subcommands:" at)
if(at LESS 0)
  message(FATAL_ERROR "bbm --help lists no subcommands")
endif()
string(SUBSTRING "${top}" ${at} -1 listed)
string(REGEX MATCHALL "\n  [a-z][a-z_-]*" names "${listed}")

set(fence "```")
set(doc "# Commands and options\n\n")
string(APPEND doc "Generated from the program's help (`bbm --help`, `bbm <command> --help`) by\n")
string(APPEND doc "`tests/cli_reference.cmake`; the test `cli.reference` fails when this file is\n")
string(APPEND doc "stale. Rewrite it after changing a command or option:\n\n")
string(APPEND doc "${fence}sh\ncmake -DBBM=build/apps/bbm -DREFERENCE=docs/reference/commands.md -DWRITE=1 -P tests/cli_reference.cmake\n${fence}\n\n")
string(APPEND doc "The rock's joint and material options of the lab tests, `calibrate`, `envelope`\n")
string(APPEND doc "and `shear` are the model file's keys with dashes ([joint_property.md](joint_property.md),\n")
string(APPEND doc "[material.md](material.md)); the Python functions take the same names as keywords.\n\n")
string(APPEND doc "## bbm\n\n${fence}text\n${top}${fence}\n")
foreach(line IN LISTS names)
  string(STRIP "${line}" name)
  help_of(text ${name})
  string(APPEND doc "\n## bbm ${name}\n\n${fence}text\n${text}${fence}\n")
endforeach()

if(WRITE)
  file(WRITE ${REFERENCE} "${doc}")
  message(STATUS "wrote ${REFERENCE}")
  return()
endif()
file(READ ${REFERENCE} recorded)
if(NOT recorded STREQUAL doc)
  file(WRITE ${DIR}/commands.md "${doc}")
  message(FATAL_ERROR "${REFERENCE} is stale: the program's help differs (now in ${DIR}/commands.md). Rewrite it:\n"
                      "  cmake -DBBM=build/apps/bbm -DREFERENCE=docs/reference/commands.md -DWRITE=1 -P tests/cli_reference.cmake")
endif()
