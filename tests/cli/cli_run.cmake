# cli_run.cmake — helpers shared by the cmake -P CLI tests: run `caustica render` and check its exit code.
# run(EXPECTED_RC args...): fails the test naming the arguments and stderr when the exit code differs;
# leaves stderr in `err` in the caller's scope.
function(run expect)
  execute_process(COMMAND ${CLI} render ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL expect)
    message(FATAL_ERROR "render ${ARGN}: exit ${rc}, expected ${expect}: ${err}")
  endif()
  set(err "${err}" PARENT_SCOPE)
endfunction()
