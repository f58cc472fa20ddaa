# The program as a user runs it: the paper's tunnel interrupted by SIGINT (after
# 2 s, with checkpoints every 1000 steps as well, so a checkpoint exists however
# fast the machine), then `bbm run --resume`, ends in the same state hash as an
# uninterrupted run. Also: a run that goes unstable stops with status 3 and says why.
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})
execute_process(COMMAND ${BBM} run ${MODEL} --out ${DIR}/whole --quiet RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "uninterrupted run failed (${status}): ${err}")
endif()
execute_process(COMMAND timeout --preserve-status -s INT 2 ${BBM} run ${MODEL} --out ${DIR}/part --quiet --checkpoint-every 1000
                RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT (status EQUAL 0 OR status EQUAL 130))
  message(FATAL_ERROR "interrupted run: unexpected status ${status}: ${err}")
endif()
if(NOT EXISTS ${DIR}/part/checkpoint.bin)
  message(FATAL_ERROR "no checkpoint written")
endif()
execute_process(COMMAND ${BBM} run --resume --out ${DIR}/part --quiet RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "resume failed (${status}): ${err}")
endif()
file(READ ${DIR}/whole/summary.json whole)
file(READ ${DIR}/part/summary.json part)
string(REGEX MATCH "\"state_hash\": \"[0-9]+\"" hash_whole "${whole}")
string(REGEX MATCH "\"state_hash\": \"[0-9]+\"" hash_part "${part}")
if(NOT hash_whole OR NOT hash_whole STREQUAL hash_part)
  message(FATAL_ERROR "resumed run differs: ${hash_part} vs ${hash_whole}")
endif()

# Instability: a dynamic model with a time step six times the stable one.
file(READ ${UNSTABLE_BASE} text)
string(REPLACE "safety = 0.5" "safety = 0.5\ntimestep = 1.0e-4" text "${text}")
string(APPEND text "\n[[stage]]\nname = \"go\"\ntype = \"cycle\"\nsteps = 3000\n")
file(WRITE ${DIR}/unstable.toml "${text}")
execute_process(COMMAND ${BBM} run ${DIR}/unstable.toml --out ${DIR}/unstable --quiet
                RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 3)
  message(FATAL_ERROR "an unstable run should stop with status 3, got ${status}: ${err}")
endif()
if(NOT err MATCHES "solver.timestep")
  message(FATAL_ERROR "the message should say what to change: ${err}")
endif()
