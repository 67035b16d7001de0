# cli_run.cmake — helpers shared by the cmake -P CLI tests: run a caustica command and check its exit
# code and message.
# run_command(COMMAND EXPECTED_RC args...): runs `caustica COMMAND args...`; fails the test naming the
# arguments and stderr when the exit code differs; leaves stderr in `err` in the caller's scope.
function(run_command command expect)
  execute_process(COMMAND ${CLI} ${command} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL expect)
    message(FATAL_ERROR "${command} ${ARGN}: exit ${rc}, expected ${expect}: ${err}")
  endif()
  set(err "${err}" PARENT_SCOPE)
endfunction()
# run(EXPECTED_RC args...): run_command for `caustica render`.
function(run expect)
  run_command(render ${expect} ${ARGN})
  set(err "${err}" PARENT_SCOPE)
endfunction()
# refused_command(COMMAND PATTERN args...): `caustica COMMAND args...` exits 1 with PATTERN in stderr.
function(refused_command command pattern)
  run_command(${command} 1 ${ARGN})
  if(NOT err MATCHES "${pattern}")
    message(FATAL_ERROR "${command} ${ARGN}: the refusal does not say '${pattern}': ${err}")
  endif()
endfunction()
