# view_without_display.cmake — `caustica view` with no display must fail with exit status 1 and a
# one-line message pointing to `caustica render` (run with cmake -P; CLI given).
execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=DISPLAY --unset=WAYLAND_DISPLAY
                        ${CLI} view --size 32 --frames 1
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 1)
  message(FATAL_ERROR "view without a display exited with '${rc}', expected 1: ${err}")
endif()
if(NOT err MATCHES "no display" OR NOT err MATCHES "caustica render")
  message(FATAL_ERROR "the message should say there is no display and point to 'caustica render': ${err}")
endif()
message(STATUS "${err}")
