# Shared by the command-line test scripts (check_cli.cmake, check_run_log.cmake): run demmat with ARGN
# and fail the test on a non-zero exit, naming the command and its error; its stdout in OUT.
function(run_ok)
  execute_process(COMMAND ${DEMMAT} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "demmat ${ARGN} failed (${rc}): ${err}")
  endif()
  set(OUT "${out}" PARENT_SCOPE)
endfunction()
