# view_matches_render.cmake — runs `caustica view` under Xvfb for some frames, reads the spp of its
# screenshot from stdout, renders the same scene, seed and spp headless and compares the two linear
# images: the renderer seeds each sample by (pixel, sample index, seed), so they must agree to float
# rounding however the viewer split its passes. A render with another seed must NOT match (the check
# can fail). The viewer shows (and its screenshot holds) the denoised image in the path mode unless
# --no-denoise, so the headless render gets --denoise then: the same sums give the same denoised bits.
# Run with cmake -P; XVFB_RUN, CLI, COMPARE, DIR, SIZE and VIEW_ARGS (more viewer options) given; MODE
# (optional) is the --mode of both (docs/render-modes.md).
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})
separate_arguments(viewArgs UNIX_COMMAND "${VIEW_ARGS}")
set(modeArgs "")
if(MODE)
  set(modeArgs --mode ${MODE})
endif()
set(denoiseArgs "")
if(NOT MODE AND NOT VIEW_ARGS MATCHES "--no-denoise")
  set(denoiseArgs --denoise)
endif()
execute_process(COMMAND ${XVFB_RUN} -a -s "-screen 0 1280x1024x24"
                        ${CLI} view cornell-glass --size ${SIZE} ${viewArgs} ${modeArgs} --seed 3 --frames 8 --screenshot ${DIR}/view.exr
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "view failed (${rc}): ${out}${err}")
endif()
if(NOT out MATCHES "screenshot [^\n]*view.exr: ([0-9]+)x([0-9]+), ([0-9]+) spp(, denoised)?")
  message(FATAL_ERROR "view did not report its screenshot: ${out}${err}")
endif()
set(spp ${CMAKE_MATCH_3})
if(denoiseArgs AND NOT CMAKE_MATCH_4)
  message(FATAL_ERROR "the viewer should show the denoised image by default: ${out}")
elseif(NOT denoiseArgs AND CMAKE_MATCH_4)
  message(FATAL_ERROR "the viewer should show the raw image here: ${out}")
endif()
message(STATUS "view: ${out}")
if(spp LESS 1)
  message(FATAL_ERROR "the screenshot has no samples")
endif()
foreach(seed 3 4)
  execute_process(COMMAND ${CLI} render cornell-glass --size ${SIZE} ${modeArgs} ${denoiseArgs} --seed ${seed} --spp ${spp} -o ${DIR}/render${seed}.exr -q
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "render failed (${rc}): ${err}")
  endif()
endforeach()
execute_process(COMMAND ${COMPARE} ${DIR}/view.exr ${DIR}/render3.exr RESULT_VARIABLE rc OUTPUT_VARIABLE cmp)
message(STATUS "same seed: ${cmp}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the viewer's screenshot differs from the headless render at ${spp} spp: ${cmp}")
endif()
execute_process(COMMAND ${COMPARE} ${DIR}/view.exr ${DIR}/render4.exr RESULT_VARIABLE rc OUTPUT_VARIABLE cmp)
message(STATUS "other seed: ${cmp}")
if(NOT rc EQUAL 1)
  message(FATAL_ERROR "a render with another seed should differ from the screenshot: ${cmp}")
endif()
