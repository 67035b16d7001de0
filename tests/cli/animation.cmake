# animation.cmake — glTF animation as a user renders it (docs/animation.md): a render at a key time equals
# the static file with that pose bit for bit (node TRS and camera; morph weights); `--frames` renders a
# sequence whose frames equal single `--frame N` renders bit for bit and, with instances, builds the
# meshes' BVHs once; a file with animations and no time says it shows t = 0; the pose is part of the
# accumulation identity; bad animation options are named
# (run with cmake -P; CLI, COMPARE (viewer_image_compare), DATA (tests/data/animated) and DIR given).
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})
set(COMMON --size 24 --spp 4 --backend osmesa)
include(${CMAKE_CURRENT_LIST_DIR}/cli_run.cmake)

# identical(A B): the two files hold the same bytes (and are not black).
function(identical a b)
  execute_process(COMMAND ${COMPARE} ${a} ${b} 0 RESULT_VARIABLE crc OUTPUT_VARIABLE cout)
  message(STATUS "${a} vs ${b}: ${cout}")
  file(SHA256 ${a} ha)
  file(SHA256 ${b} hb)
  if(NOT crc EQUAL 0 OR NOT ha STREQUAL hb)
    message(FATAL_ERROR "${a} and ${b} differ: ${cout}")
  endif()
endfunction()

# A key time equals the static scene with that pose (make-animated-gltf writes both files).
run(0 ${DATA}/trs.gltf ${COMMON} -q --anim-time 1 -o ${DIR}/trs-t1.exr)
run(0 ${DATA}/trs-at-1.gltf ${COMMON} -q -o ${DIR}/trs-static.exr)
identical(${DIR}/trs-t1.exr ${DIR}/trs-static.exr)
run(0 ${DATA}/morph.gltf ${COMMON} -q --frame 24 -o ${DIR}/morph-f24.exr)  # t = 24 / 24 fps
run(0 ${DATA}/morph-at-1.gltf ${COMMON} -q -o ${DIR}/morph-static.exr)
identical(${DIR}/morph-f24.exr ${DIR}/morph-static.exr)

# --frames: one process, each frame equal to its single-frame render; the rigid animation of an
# instanced scene builds its meshes' BVHs once.
run(0 ${DATA}/trs.gltf ${COMMON} --instances on --frames 1..3 --fps 2 -o "${DIR}/seq_###.exr")
if(NOT err MATCHES "frame 3 \\(t = 1.5 s\\): 4 spp, .*wrote [^ ]*seq_003.exr")
  message(FATAL_ERROR "--frames does not report frame 3 at t = 1.5 s: ${err}")
endif()
if(NOT err MATCHES "3 frame\\(s\\) in [0-9.]+ s; .*mesh BVH builds: 1")
  message(FATAL_ERROR "a rigid animation of an instanced scene rebuilt its meshes' BVHs: ${err}")
endif()
foreach(n 1 2 3)
  run(0 ${DATA}/trs.gltf ${COMMON} -q --instances on --frame ${n} --fps 2 -o ${DIR}/single${n}.exr)
  identical(${DIR}/seq_00${n}.exr ${DIR}/single${n}.exr)
endforeach()
# Skinned frames change the stored mesh: built again each frame, and still equal to single renders.
run(0 ${DATA}/skin.gltf ${COMMON} --frames 0..1 --fps 2 -o "${DIR}/skin_#.exr")
run(0 ${DATA}/skin.gltf ${COMMON} -q --anim-time 0.5 -o ${DIR}/skin-single.exr)
identical(${DIR}/skin_1.exr ${DIR}/skin-single.exr)

# No time given: t = 0, and it says so.
run(0 ${DATA}/trs.gltf ${COMMON} -o ${DIR}/t0.exr)
if(NOT err MATCHES "trs.gltf has 2 animations: 0 'move' 0-2 s \\(5 channels\\), 1 'spin' 0-0.5 s \\(2 channels\\); showing 0 'move' at t = 0 s \\(choose the time with --anim-time")
  message(FATAL_ERROR "an animated file rendered without a time does not say it shows t = 0: ${err}")
endif()

# The pose is part of the accumulation identity: a checkpoint of t = 0.5 does not resume at t = 1.
run(0 ${DATA}/trs.gltf ${COMMON} -q --anim-time 0.5 -o ${DIR}/half.exr --checkpoint 1000)
refused_command(render "half.exr.ckpt: cannot resume another render: anim-time: checkpoint 0.5, this render 1"
                ${DATA}/trs.gltf ${COMMON} -q --anim-time 1 --spp 8 -o ${DIR}/x.exr --resume ${DIR}/half.exr.ckpt)
refused_command(render "animation: checkpoint first, this render spin"
                ${DATA}/trs.gltf ${COMMON} -q --anim-time 0.5 --animation spin --spp 8 -o ${DIR}/x.exr --resume ${DIR}/half.exr.ckpt)

# Bad options, each named.
refused_command(render "--animation walk: no such animation \\(the file has 2: 0 'move', 1 'spin'; or 'all'\\)"
                ${DATA}/trs.gltf ${COMMON} --animation walk -o ${DIR}/x.exr)
refused_command(render "give the time with --anim-time or with --frame/--frames, not both"
                ${DATA}/trs.gltf ${COMMON} --anim-time 1 --frames 0..2 -o "${DIR}/x_#.exr")
refused_command(render "--frames needs the frame number's place in the output name, as ####"
                ${DATA}/trs.gltf ${COMMON} --frames 0..2 -o ${DIR}/x.exr)
refused_command(render "option --frames needs A..B with 0 <= A <= B" ${DATA}/trs.gltf ${COMMON} --frames 3..1 -o "${DIR}/x_#.exr")
refused_command(render "option --fps needs --frame N" ${DATA}/trs.gltf ${COMMON} --fps 30 -o ${DIR}/x.exr)
refused_command(render "--shard with --frames" ${DATA}/trs.gltf ${COMMON} --frames 0..1 --shard 1/2 -o "${DIR}/x_#.exr")
refused_command(info "--animation 2: no such animation" ${DATA}/trs.gltf --animation 2)
