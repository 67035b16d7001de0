# render_budgets.cmake — render --spp/--time/--target-error stop at the first budget reached and
# --stats writes the statistics; an adaptive render resumed from a checkpoint equals an uninterrupted
# one bit for bit; bad budget options fail naming the option (run with cmake -P; CLI, COMPARE, DIR given).
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})
set(COMMON cornell-glass --size 32 --backend osmesa -q)
include(${CMAKE_CURRENT_LIST_DIR}/cli_run.cmake)
function(stat file key var)
  file(READ ${file} json)
  string(JSON v GET "${json}" ${key})
  set(${var} "${v}" PARENT_SCOPE)
endfunction()

# --spp alone: every pixel gets exactly that many samples; every key is there.
run(0 ${COMMON} --spp 6 -o ${DIR}/spp.exr --stats ${DIR}/spp.json)
foreach(key seconds spp_min spp_mean spp_max estimated_relmse nonfinite_samples rays samples)
  stat(${DIR}/spp.json ${key} v)
  message(STATUS "spp.json ${key} = ${v}")
endforeach()
stat(${DIR}/spp.json spp_min a)
stat(${DIR}/spp.json spp_max b)
stat(${DIR}/spp.json samples n)
stat(${DIR}/spp.json stop why)
if(NOT a EQUAL 6 OR NOT b EQUAL 6 OR NOT n EQUAL 6144 OR NOT why STREQUAL "spp")
  message(FATAL_ERROR "--spp 6 at 32x32: spp ${a}..${b}, ${n} samples, stop ${why}")
endif()

# --time: stops on time (how long it took is not checked: no timed tests).
run(0 ${COMMON} --time 0.5 -o ${DIR}/time.exr --stats ${DIR}/time.json)
stat(${DIR}/time.json stop why)
if(NOT why STREQUAL "time")
  message(FATAL_ERROR "--time 0.5 stopped on ${why}")
endif()

# --target-error: stops there, estimate at or below it, tiles got different sample counts (light tracing
# brings cornell-glass to 0.012 at the first check, 16 spp: a target below it).
run(0 ${COMMON} --target-error 0.005 -o ${DIR}/target.exr --stats ${DIR}/target.json)
stat(${DIR}/target.json stop why)
stat(${DIR}/target.json estimated_relmse e)
stat(${DIR}/target.json spp_min a)
stat(${DIR}/target.json spp_max b)
message(STATUS "--target-error 0.005: relMSE~${e}, spp ${a}..${b}")
if(NOT why STREQUAL "target-error" OR e GREATER 0.005 OR NOT a LESS b)
  message(FATAL_ERROR "--target-error 0.005 stopped on ${why} at relMSE ${e}, spp ${a}..${b}")
endif()
# --uniform: every pixel the same count.
run(0 ${COMMON} --target-error 0.005 --uniform -o ${DIR}/uniform.exr --stats ${DIR}/uniform.json)
stat(${DIR}/uniform.json spp_min a)
stat(${DIR}/uniform.json spp_max b)
if(NOT a EQUAL b)
  message(FATAL_ERROR "--uniform gave spp ${a}..${b}")
endif()

# Adaptive resume: stop at the 24-spp cap with a checkpoint, resume to the target; equals a straight run.
run(0 ${COMMON} --target-error 0.01 --spp 24 -o ${DIR}/part.exr --checkpoint 1000)
run(0 ${COMMON} --target-error 0.01 --spp 200 -o ${DIR}/resumed.exr --resume ${DIR}/part.exr.ckpt --stats ${DIR}/resumed.json)
run(0 ${COMMON} --target-error 0.01 --spp 200 -o ${DIR}/straight.exr --stats ${DIR}/straight.json)
file(SHA256 ${DIR}/resumed.exr a)
file(SHA256 ${DIR}/straight.exr b)
if(NOT a STREQUAL b)
  execute_process(COMMAND ${COMPARE} ${DIR}/resumed.exr ${DIR}/straight.exr 0 OUTPUT_VARIABLE cout)
  message(FATAL_ERROR "the resumed adaptive render differs from the straight one: ${cout}")
endif()

# Bad budgets name the option.
function(refused pattern)
  run(1 ${ARGN})
  if(NOT err MATCHES "${pattern}")
    message(FATAL_ERROR "render ${ARGN}: the refusal does not say '${pattern}': ${err}")
  endif()
endfunction()
refused("--time needs a number of seconds" ${COMMON} --time 0 -o ${DIR}/x.exr)
refused("--target-error needs a relMSE above 0" ${COMMON} --target-error -1 -o ${DIR}/x.exr)
refused("--uniform needs --target-error" ${COMMON} --uniform -o ${DIR}/x.exr)
refused("stats" ${COMMON} --stats /nonexistent/dir/s.json -o ${DIR}/x.exr)
