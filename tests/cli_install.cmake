# cmake --install into a fresh prefix: the program runs from bin/ and names its
# version, the examples and docs are in share/, and (with the Python module) the
# package imports from lib/python3.X/dist-packages and runs an installed example.
file(REMOVE_RECURSE ${DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD} --prefix ${DIR} RESULT_VARIABLE status OUTPUT_QUIET
                ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${status}): ${err}")
endif()
execute_process(COMMAND ${DIR}/bin/bbm --version RESULT_VARIABLE status OUTPUT_VARIABLE out)
if(NOT status EQUAL 0 OR NOT out MATCHES "^bbm [0-9]+\\.[0-9]+\\.[0-9]+ \\(")
  message(FATAL_ERROR "installed bbm --version: status ${status}, '${out}'")
endif()
foreach(f share/bbm/examples/tunnel_trigon.toml share/doc/bbm/README.md share/doc/bbm/LICENSE share/doc/bbm/docs/input.md)
  if(NOT EXISTS ${DIR}/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
if(PYTHON)
  file(GLOB site ${DIR}/lib/python3*/dist-packages)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${site} ${PYTHON} -c
                  "import bbm; m = bbm.Model('${DIR}/share/bbm/examples/verification/hybrid_elastic.toml'); m.step(3); assert m.steps == 3; assert bbm.__file__.startswith('${DIR}')"
                  RESULT_VARIABLE status ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "the installed Python package: ${err}")
  endif()
endif()
