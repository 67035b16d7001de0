# checkpoint_resume.cmake — render 8 spp with --checkpoint, resume to 16 spp and compare with a straight
# 16-spp render bit for bit (also with other speed and output settings, and with --manifold auto and off
# where they render the same image); resuming with another seed, size, background, environment, light
# radius, manifold mode or scene must fail naming what differs
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

# Speed and output settings are not part of the accumulation identity (cli/image_settings.h): a resume
# with another --samples-per-dispatch and --exposure goes on, to the same bits.
run(0 ${COMMON} --spp 16 --samples-per-dispatch 1 --exposure 1 -o ${DIR}/resumed2.exr --resume ${DIR}/half.exr.ckpt)
file(SHA256 ${DIR}/resumed2.exr c)
if(NOT c STREQUAL b)
  message(FATAL_ERROR "a resume with another --samples-per-dispatch and --exposure differs from the straight render")
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
refused("height: checkpoint 16, this render 8; .*width: checkpoint 16, this render 8" ${COMMON} --size 8 --spp 16 -o ${DIR}/x.exr --resume ${DIR}/half.exr.ckpt)
# The settings that change the scene are part of it too.
refused("background: checkpoint env, this render 0.2,0.2,0.2"
        ${COMMON} --background 0.2,0.2,0.2 --spp 16 -o ${DIR}/x.exr --resume ${DIR}/half.exr.ckpt)
refused("env: checkpoint auto, this render 0.5; env-strength: checkpoint 1, this render 2"
        ${COMMON} --env 0.5 --env-strength 2 --spp 16 -o ${DIR}/x.exr --resume ${DIR}/half.exr.ckpt)
refused("light-radius: checkpoint 0, this render 0.05"
        ${COMMON} --light-radius 0.05 --spp 16 -o ${DIR}/x.exr --resume ${DIR}/half.exr.ckpt)
# --manifold is recorded as the image sees it: on cornell-box (no caster) auto renders what off does, so
# a checkpoint of the default auto continues with --manifold off and one of off with auto, to the same
# bits; on is another image there (the manifold variant) and is refused naming both. On lamp-caustics
# auto finds casters but light tracing goes first: a checkpoint of on (an older build's default) does not
# continue with auto, one of off does.
file(READ ${DIR}/half.exr.ckpt head LIMIT 2000)
if(NOT head MATCHES "\nmanifold off\n")
  message(FATAL_ERROR "the checkpoint of --manifold auto on a scene without casters does not record what auto resolved to (off)")
endif()
run(0 ${COMMON} --spp 16 --manifold off -o ${DIR}/resumed-off.exr --resume ${DIR}/half.exr.ckpt)
file(SHA256 ${DIR}/resumed-off.exr d)
if(NOT d STREQUAL b)
  message(FATAL_ERROR "a checkpoint of --manifold auto on a scene without casters resumed with --manifold off differs from the straight render")
endif()
run(0 ${COMMON} --spp 8 --manifold off -o ${DIR}/half-off.exr --checkpoint 1000)
run(0 ${COMMON} --spp 16 -o ${DIR}/resumed-auto.exr --resume ${DIR}/half-off.exr.ckpt)
file(SHA256 ${DIR}/resumed-auto.exr e)
if(NOT e STREQUAL b)
  message(FATAL_ERROR "a checkpoint of --manifold off resumed with the default auto differs from the straight render")
endif()
refused("half.exr.ckpt: cannot resume another render: manifold: checkpoint off, this render on"
        ${COMMON} --spp 16 --manifold on -o ${DIR}/x.exr --resume ${DIR}/half.exr.ckpt)
run(0 lamp-caustics --size 16 --backend osmesa -q --spp 2 --manifold on -o ${DIR}/lamp-on.exr --checkpoint 1000)
refused("lamp-on.exr.ckpt: cannot resume another render: light-tracing: checkpoint off, this render on; manifold: checkpoint on, this render off"
        lamp-caustics --size 16 --backend osmesa -q --spp 4 -o ${DIR}/x.exr --resume ${DIR}/lamp-on.exr.ckpt)
run(0 lamp-caustics --size 16 --backend osmesa -q --spp 2 --manifold off -o ${DIR}/lamp-off.exr --checkpoint 1000)
run(0 lamp-caustics --size 16 --backend osmesa -q --spp 4 -o ${DIR}/lamp-resumed.exr --resume ${DIR}/lamp-off.exr.ckpt)
run(0 lamp-caustics --size 16 --backend osmesa -q --spp 4 -o ${DIR}/lamp-straight.exr)
file(SHA256 ${DIR}/lamp-resumed.exr lr)
file(SHA256 ${DIR}/lamp-straight.exr ls)
if(NOT lr STREQUAL ls)  # light tracing with caster aiming and guiding beside it, all resumed bit for bit
  message(FATAL_ERROR "lamp-caustics: a checkpoint of --manifold off resumed with the default auto differs from the straight render")
endif()
if(EXISTS ${DIR}/x.exr)
  message(FATAL_ERROR "a refused resume wrote an image")
endif()
