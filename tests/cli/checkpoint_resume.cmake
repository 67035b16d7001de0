# checkpoint_resume.cmake — render 8 spp with --checkpoint, resume to 16 spp and compare with a straight
# 16-spp render bit for bit; resuming with another seed or another scene must fail naming what differs
# (run with cmake -P; CLI, COMPARE (viewer_image_compare) and DIR given).
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})
set(COMMON cornell-box --size 16 --backend osmesa -q)
include(${CMAKE_CURRENT_LIST_DIR}/cli_run.cmake)

run(0 ${COMMON} --spp 8 -o ${DIR}/half.exr --checkpoint 1000)
if(NOT EXISTS ${DIR}/half.exr.ckpt)
  message(FATAL_ERROR "--checkpoint wrote no final checkpoint")
endif()
run(0 ${COMMON} --spp 16 -o ${DIR}/resumed.exr --resume ${DIR}/half.exr.ckpt)
run(0 ${COMMON} --spp 16 -o ${DIR}/straight.exr)
execute_process(COMMAND ${COMPARE} ${DIR}/resumed.exr ${DIR}/straight.exr 0 RESULT_VARIABLE crc OUTPUT_VARIABLE cout)
message(STATUS "resumed vs straight: ${cout}")
file(SHA256 ${DIR}/resumed.exr a)
file(SHA256 ${DIR}/straight.exr b)
if(NOT crc EQUAL 0 OR NOT a STREQUAL b)
  message(FATAL_ERROR "the resumed render differs from the straight one: ${cout}")
endif()

# Each refused resume exits 1 naming what differs.
function(refused pattern)
  run(1 ${ARGN})
  if(NOT err MATCHES "${pattern}")
    message(FATAL_ERROR "render ${ARGN}: the refusal does not say '${pattern}': ${err}")
  endif()
endfunction()
refused("half.exr.ckpt: cannot resume another render: seed: checkpoint 1, this render 2"
        ${COMMON} --spp 16 --seed 2 -o ${DIR}/x.exr --resume ${DIR}/half.exr.ckpt)
refused("cannot resume another render: .*scene files differ"
        cornell-glass --size 16 --backend osmesa -q --spp 16 -o ${DIR}/x.exr --resume ${DIR}/half.exr.ckpt)
refused("size: checkpoint 16x16, this render 8x8" ${COMMON} --size 8 --spp 16 -o ${DIR}/x.exr --resume ${DIR}/half.exr.ckpt)
if(EXISTS ${DIR}/x.exr)
  message(FATAL_ERROR "a refused resume wrote an image")
endif()
