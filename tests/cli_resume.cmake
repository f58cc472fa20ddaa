# The program as a user runs it (issue 27): a run stopped at an exact step
# (--stop-at-step) or by a signal (SIGTERM, SIGUSR1, as a cluster's scheduler
# sends them) writes a checkpoint and exits 130; `bbm run --resume` ends in the
# uninterrupted run's state hash, on another thread count too. A finished run
# resumes to "nothing to resume" with status 0; a checkpoint of an edited model,
# of another model or of an older format is refused with status 2 and the reason.
# With TRIGON set, the trigon tunnel stopped in its excavation (where resumed runs
# used to end at 570 / 539 cracks instead of 541 / 516) and resumed on 2 threads.
# Also: a run that goes unstable stops with status 3 and says why.
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})

function(run_bbm expected)
  execute_process(COMMAND ${BBM} ${ARGN} --quiet RESULT_VARIABLE status ERROR_VARIABLE err OUTPUT_VARIABLE out)
  if(NOT status EQUAL expected)
    message(FATAL_ERROR "bbm ${ARGN}: status ${status}, expected ${expected}: ${err}")
  endif()
  set(err "${err}" PARENT_SCOPE)
endfunction()

include(${CMAKE_CURRENT_LIST_DIR}/cli_common.cmake)

function(expect_same_hash dir reference)
  state_hash(${dir} hash)
  state_hash(${reference} expected)
  if(NOT hash STREQUAL expected)
    message(FATAL_ERROR "resumed run ${dir} differs: ${hash} vs ${expected}")
  endif()
endfunction()

run_bbm(0 run ${MODEL} --out ${DIR}/whole)

# Exact stops: in the excavation (relaxed over 3,000 steps) and in the failure stage.
foreach(stop 1500 3700)
  run_bbm(130 run ${MODEL} --out ${DIR}/stop_${stop} --stop-at-step ${stop})
  file(READ ${DIR}/stop_${stop}/summary.json text)
  if(NOT text MATCHES "\"interrupted\": true" OR NOT text MATCHES "\"steps\": ${stop},")
    message(FATAL_ERROR "the stopped run's summary should say interrupted at step ${stop}: ${text}")
  endif()
  run_bbm(0 run --resume --out ${DIR}/stop_${stop} --threads 2)
  expect_same_hash(${DIR}/stop_${stop} ${DIR}/whole)
endforeach()

# A finished run: nothing to resume, status 0.
run_bbm(0 run --resume --out ${DIR}/stop_1500)
execute_process(COMMAND ${BBM} run --resume --out ${DIR}/stop_1500 RESULT_VARIABLE status ERROR_VARIABLE err)
if(NOT status EQUAL 0 OR NOT err MATCHES "finished")
  message(FATAL_ERROR "resuming a finished run should say so and exit 0 (${status}): ${err}")
endif()

# Signals from a scheduler: SIGTERM (preemption) and SIGUSR1 (Slurm --signal).
# If the run finished first (a fast machine), there is nothing to resume: fine.
foreach(signal TERM USR1)
  execute_process(COMMAND timeout --preserve-status -s ${signal} 1 ${BBM} run ${MODEL} --out ${DIR}/sig_${signal} --quiet
                  RESULT_VARIABLE status ERROR_VARIABLE err)
  if(NOT (status EQUAL 0 OR status EQUAL 130))
    message(FATAL_ERROR "SIG${signal}: unexpected status ${status}: ${err}")
  endif()
  if(status EQUAL 130 AND NOT EXISTS ${DIR}/sig_${signal}/checkpoint.bin)
    message(FATAL_ERROR "SIG${signal}: no checkpoint written")
  endif()
  run_bbm(0 run --resume --out ${DIR}/sig_${signal})
  expect_same_hash(${DIR}/sig_${signal} ${DIR}/whole)
endforeach()

# Checkpoints by wall time: a run of about 2 s with one every 0.2 s leaves one.
run_bbm(0 run ${MODEL} --out ${DIR}/timed --checkpoint-every 0.2s)
if(NOT EXISTS ${DIR}/timed/checkpoint.bin)
  message(FATAL_ERROR "--checkpoint-every 0.2s wrote no checkpoint")
endif()
run_bbm(2 run ${MODEL} --out ${DIR}/bad_interval --checkpoint-every often)
if(NOT err MATCHES "--checkpoint-every")
  message(FATAL_ERROR "a bad interval should name the option: ${err}")
endif()

# The model file edited after the checkpoint: refused, the file named.
configure_file(${MODEL} ${DIR}/edited.toml COPYONLY)
run_bbm(130 run ${DIR}/edited.toml --out ${DIR}/edited --stop-at-step 500)
# Another model given with --resume: refused, both named.
run_bbm(2 run ${UNSTABLE_BASE} --resume --out ${DIR}/edited)
if(NOT err MATCHES "is of the model")
  message(FATAL_ERROR "another model should be refused: ${err}")
endif()
file(APPEND ${DIR}/edited.toml "\n# edited\n")
run_bbm(2 run --resume --out ${DIR}/edited)
if(NOT err MATCHES "edited.toml" OR NOT err MATCHES "changed since")
  message(FATAL_ERROR "an edited model should be refused, naming the file: ${err}")
endif()
# A checkpoint of format 1 (bbm before issue 27): refused with the format named.
file(MAKE_DIRECTORY ${DIR}/old)
file(WRITE ${DIR}/old/checkpoint.bin "bbm-run-checkpoint-1 and the rest of an old file")
run_bbm(2 run --resume --out ${DIR}/old)
if(NOT err MATCHES "format 1")
  message(FATAL_ERROR "an old checkpoint should be refused naming its format: ${err}")
endif()

if(TRIGON)
  run_bbm(0 run ${TRIGON} --out ${DIR}/trigon_whole)
  run_bbm(130 run ${TRIGON} --out ${DIR}/trigon_1901 --stop-at-step 1901)
  run_bbm(0 run --resume --out ${DIR}/trigon_1901 --threads 2)
  expect_same_hash(${DIR}/trigon_1901 ${DIR}/trigon_whole)
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
# Its history so far is kept: the rows of the stage that went wrong (written only
# at a stage's end before 2026-11-30, so a run stopped inside its first long
# stage kept none).
file(STRINGS ${DIR}/unstable/history.csv rows)
list(LENGTH rows n)
if(n LESS 5)
  message(FATAL_ERROR "the stopped run's history.csv should keep its rows so far: ${n} lines")
endif()
