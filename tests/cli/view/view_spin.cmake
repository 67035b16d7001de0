# view_spin.cmake — `caustica view --spin` orbits the camera every frame, so the viewer shows its
# low-resolution preview; at the end it must return to full resolution, finish a pass and write an
# image that is not black and differs from the scene camera's render (the camera did move).
# Run with cmake -P; XVFB_RUN, CLI, COMPARE and DIR given.
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})
execute_process(COMMAND ${XVFB_RUN} -a -s "-screen 0 1280x1024x24"
                        ${CLI} view cornell-box --size 160x120 --budget-ms 5 --spin 3 --frames 10
                        --screenshot ${DIR}/spin.exr
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "view --spin failed (${rc}): ${out}${err}")
endif()
message(STATUS "view: ${out}")
if(NOT out MATCHES "screenshot [^\n]*spin.exr: 160x120, ([0-9]+) spp")
  message(FATAL_ERROR "the screenshot should be at full resolution 160x120 with its spp: ${out}${err}")
endif()
set(spp ${CMAKE_MATCH_1})
execute_process(COMMAND ${CLI} render cornell-box --size 160x120 --spp ${spp} -o ${DIR}/still.exr -q RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "render failed (${rc})")
endif()
execute_process(COMMAND ${COMPARE} ${DIR}/spin.exr ${DIR}/spin.exr RESULT_VARIABLE rc OUTPUT_VARIABLE cmp)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the screenshot is black or unreadable: ${cmp}")
endif()
execute_process(COMMAND ${COMPARE} ${DIR}/spin.exr ${DIR}/still.exr RESULT_VARIABLE rc OUTPUT_VARIABLE cmp)
message(STATUS "spun vs still: ${cmp}")
if(NOT rc EQUAL 1)
  message(FATAL_ERROR "the spinning camera's image should differ from the still camera's: ${cmp}")
endif()
