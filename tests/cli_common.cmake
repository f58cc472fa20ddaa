# Shared by the CLI test scripts: the state hash of a run from its summary.json.
function(state_hash dir var)
  file(READ ${dir}/summary.json text)
  string(REGEX MATCH "\"state_hash\": \"[0-9]+\"" hash "${text}")
  if(NOT hash)
    message(FATAL_ERROR "no state hash in ${dir}/summary.json")
  endif()
  set(${var} "${hash}" PARENT_SCOPE)
endfunction()
