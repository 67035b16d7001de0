# view_target.cmake — `caustica view --target-error E` stops refining once its error estimate reaches
# E: after many frames it reports the target reached, an estimate at or below E, and no more samples
# than the estimate schedule needed. Run with cmake -P; XVFB_RUN, CLI and DIR given.
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})
execute_process(COMMAND ${XVFB_RUN} -a -s "-screen 0 1280x1024x24"
                        ${CLI} view cornell-box --size 32 --target-error 0.05 --frames 80
                        --screenshot ${DIR}/target.exr
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "view --target-error failed (${rc}): ${out}${err}")
endif()
message(STATUS "view: ${out}")
if(NOT out MATCHES "32x32, ([0-9]+) spp, relMSE~([0-9.e-]+)")
  message(FATAL_ERROR "no spp and relMSE in the summary: ${out}${err}")
endif()
set(spp ${CMAKE_MATCH_1})
set(est ${CMAKE_MATCH_2})
if(NOT out MATCHES "target relMSE 0.05 reached")
  message(FATAL_ERROR "the target was not reached in 80 frames: ${out}")
endif()
# The Cornell box reaches 0.05 at 32x32 near 8 spp (render --target-error: ~0.027 at 8 spp); the first
# estimate comes at 16 spp, then every +1/8: the viewer must have stopped at the first check at or
# after the target, well before the 80 frames' worth of samples.
if(est GREATER 0.05 OR spp GREATER 24)
  message(FATAL_ERROR "stopped at ${spp} spp with relMSE ${est}: the target 0.05 should stop it by 24 spp")
endif()
