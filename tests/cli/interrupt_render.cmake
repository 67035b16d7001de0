# interrupt_render.cmake — starts a render far too long to finish, sends SIGINT once it has written its
# first checkpoint, and checks exit status 4, the one-line message and a plausible partial image
# (run with cmake -P; CLI, COMPARE (viewer_image_compare) and DIR given).
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})
set(OUT ${DIR}/out.exr)
# The first checkpoint (after 1 s of rendering) shows the signal handlers are installed; until then a
# background job of a non-interactive shell would ignore SIGINT.
execute_process(
  COMMAND sh -c "\"$0\" render cornell-box --size 16 --spp 1000000 --backend osmesa -o \"$1\" --checkpoint 1 &
pid=$!
i=0
while [ ! -f \"$1.ckpt\" ] && [ $i -lt 600 ]; do sleep 0.1; i=$((i+1)); done
sleep 1
kill -INT $pid
wait $pid
echo \"exit=$?\"" ${CLI} ${OUT}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 110)
message(STATUS "stdout: ${out}")
message(STATUS "stderr: ${err}")
if(NOT out MATCHES "exit=4")
  message(FATAL_ERROR "expected exit status 4 after SIGINT, got: ${out}")
endif()
if(NOT err MATCHES "caustica: interrupted at ([0-9]+)/1000000 spp after [0-9]+ s; wrote [^ ]*out.exr \\(partial\\) and checkpoint [^ ]*out.exr.ckpt")
  message(FATAL_ERROR "no interrupt message naming the spp reached: ${err}")
endif()
set(reached ${CMAKE_MATCH_1})
if(reached LESS 1 OR reached GREATER_EQUAL 1000000)
  message(FATAL_ERROR "implausible spp reached: ${reached}")
endif()
if(NOT EXISTS ${OUT} OR NOT EXISTS ${OUT}.ckpt)
  message(FATAL_ERROR "no partial image or checkpoint written")
endif()
if(EXISTS ${OUT}.ckpt.tmp)
  message(FATAL_ERROR "a temporary checkpoint was left behind")
endif()
file(READ ${OUT}.ckpt head LIMIT 200)
if(NOT head MATCHES "^CAUSTICA-CKPT 5\nwidth 16\nheight 16\nspp ${reached}\n")
  message(FATAL_ERROR "the checkpoint does not hold the ${reached} spp reached: ${head}")
endif()
# The Cornell box's mean radiance at 16x16 is about 0.3-0.4: non-black and finite.
execute_process(COMMAND ${COMPARE} ${OUT} ${OUT} RESULT_VARIABLE crc OUTPUT_VARIABLE cout)
message(STATUS "${cout}")
if(NOT crc EQUAL 0 OR NOT cout MATCHES "mean ([0-9.e+-]+) vs")
  message(FATAL_ERROR "the partial image is black or unreadable: ${cout}")
endif()
if(CMAKE_MATCH_1 LESS 0.05 OR CMAKE_MATCH_1 GREATER 5)
  message(FATAL_ERROR "implausible mean radiance ${CMAKE_MATCH_1}")
endif()
