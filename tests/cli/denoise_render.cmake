# denoise_render.cmake — `render --denoise` and `--aov` as a user runs them (docs/denoising.md): the
# denoised output, the feature files beside a PNG, the raw image staying the default, checkpoints that
# keep the feature sums (resume continues the denoised render bit for bit), shards that keep them and
# merge --denoise, and clear refusals
# (run with cmake -P; CLI, COMPARE (viewer_image_compare) and DIR given).
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})
set(COMMON cornell-glass --size 24 --backend osmesa -q)
include(${CMAKE_CURRENT_LIST_DIR}/cli_run.cmake)

# The raw image stays the default: the same bits with --aov (feature buffers on) as without.
run(0 ${COMMON} --spp 8 -o ${DIR}/raw.pfm)
run(0 ${COMMON} --spp 8 --aov albedo -o ${DIR}/raw-aov.pfm)
file(SHA256 ${DIR}/raw.pfm a)
file(SHA256 ${DIR}/raw-aov.pfm b)
if(NOT a STREQUAL b)
  message(FATAL_ERROR "--aov changed the raw image")
endif()

# --denoise writes another image; --aov all beside a PNG writes the raw image as PNG and the features as PFM.
run(0 ${COMMON} --spp 8 --denoise --aov all -o ${DIR}/den.png)
foreach(f den.png den.raw.png den.albedo.pfm den.normal.pfm den.depth.pfm den.variance.pfm)
  if(NOT EXISTS ${DIR}/${f})
    message(FATAL_ERROR "render --denoise --aov all -o den.png wrote no ${f}")
  endif()
endforeach()
run(0 ${COMMON} --spp 8 --denoise -o ${DIR}/den.pfm)
execute_process(COMMAND ${COMPARE} ${DIR}/den.pfm ${DIR}/raw.pfm RESULT_VARIABLE crc OUTPUT_VARIABLE cout)
if(NOT crc EQUAL 1)
  message(FATAL_ERROR "the denoised image should differ from the raw one: ${cout}")
endif()

# Checkpoints keep the feature sums: 4 + 4 spp resumed with --denoise equals 8 spp straight.
run(0 ${COMMON} --spp 4 --denoise --checkpoint 1000 -o ${DIR}/half.pfm)
run(0 ${COMMON} --spp 8 --denoise --resume ${DIR}/half.pfm.ckpt -o ${DIR}/resumed.pfm)
file(SHA256 ${DIR}/den.pfm c)
file(SHA256 ${DIR}/resumed.pfm d)
if(NOT c STREQUAL d)
  message(FATAL_ERROR "the resumed denoised render differs from the straight one")
endif()
# A checkpoint with them resumes without --denoise too (the raw image, the same bits).
run(0 ${COMMON} --spp 8 --resume ${DIR}/half.pfm.ckpt -o ${DIR}/resumed-raw.pfm)
file(SHA256 ${DIR}/resumed-raw.pfm e)
if(NOT e STREQUAL a)
  message(FATAL_ERROR "resuming a checkpoint with feature sums without --denoise changed the raw image")
endif()

# --target-error and adaptive sampling measure the raw image: with --denoise the render takes the same
# samples (same spp per pixel, same estimate, same stop) and its raw image (--aov raw) is the same bits.
run(0 ${COMMON} --target-error 0.05 -o ${DIR}/target.pfm --stats ${DIR}/target.json)
run(0 ${COMMON} --target-error 0.05 --denoise --aov raw -o ${DIR}/target-den.pfm --stats ${DIR}/target-den.json)
foreach(key spp_min spp_mean spp_max estimated_relmse samples stop)
  file(READ ${DIR}/target.json ja)
  file(READ ${DIR}/target-den.json jb)
  string(JSON va GET "${ja}" ${key})
  string(JSON vb GET "${jb}" ${key})
  if(NOT va STREQUAL vb)
    message(FATAL_ERROR "--target-error with --denoise: ${key} is ${vb}, without ${va}: the budget should see the raw image")
  endif()
endforeach()
file(SHA256 ${DIR}/target.pfm g)
file(SHA256 ${DIR}/target-den.raw.pfm h)
if(NOT g STREQUAL h)
  message(FATAL_ERROR "--target-error with --denoise rendered another raw image than without")
endif()

# --frames writes each frame denoised too (a scene without animations: every frame is den.pfm).
run(0 ${COMMON} --spp 8 --denoise --frames 2..2 -o "${DIR}/frame_#.pfm")
file(SHA256 ${DIR}/frame_2.pfm f)
if(NOT f STREQUAL c)
  message(FATAL_ERROR "render --frames --denoise wrote another image than render --denoise")
endif()

# Shards keep the feature sums (version 6 partials); merge adds them and --denoise runs the filter's C++
# twin on the merged sums: the same image as render --denoise, to float rounding (the twin test measures
# 2e-6 relative; the merged sums differ from one machine's by rounding too).
run(0 ${COMMON} --spp 8 --denoise --shard 1/2 -o ${DIR}/s1.ckpt)
run(0 ${COMMON} --spp 8 --aov albedo --shard 2/2 -o ${DIR}/s2.ckpt)
file(READ ${DIR}/s1.ckpt head LIMIT 200)
if(NOT head MATCHES "^CAUSTICA-CKPT 6\n.*\nfeatures 1\n.*\nshard 1/2 0 4 8\n")
  message(FATAL_ERROR "a shard rendered with --denoise should write a version 6 partial with the feature sums: ${head}")
endif()
run_command(merge 0 ${DIR}/s2.ckpt ${DIR}/s1.ckpt --denoise --aov albedo -o ${DIR}/merged-den.pfm -q)
execute_process(COMMAND ${COMPARE} ${DIR}/merged-den.pfm ${DIR}/den.pfm 1e-4 RESULT_VARIABLE crc OUTPUT_VARIABLE cout)
if(NOT crc EQUAL 0)
  message(FATAL_ERROR "merge --denoise of two shards differs from render --denoise: ${cout}")
endif()
if(NOT EXISTS ${DIR}/merged-den.albedo.pfm)
  message(FATAL_ERROR "merge --aov albedo -o merged-den.pfm wrote no merged-den.albedo.pfm")
endif()
run(0 ${COMMON} --spp 8 --shard 1/2 -o ${DIR}/p1.ckpt)
run(0 ${COMMON} --spp 8 --shard 2/2 -o ${DIR}/p2.ckpt)
refused_command(merge "p1.ckpt: the parts hold no feature sums \\(their shards were rendered without --denoise or --aov\\)"
                ${DIR}/p1.ckpt ${DIR}/p2.ckpt --denoise -o ${DIR}/x.pfm)
refused_command(merge "one holds the albedo sums and the other not" ${DIR}/s1.ckpt ${DIR}/p2.ckpt -o ${DIR}/x.pfm)

run(0 ${COMMON} --spp 4 --checkpoint 1000 -o ${DIR}/plain.pfm)
refused_command(render "plain.pfm.ckpt: has no feature sums \\(it was rendered without --denoise or --aov\\)"
        ${COMMON} --spp 8 --denoise --resume ${DIR}/plain.pfm.ckpt -o ${DIR}/x.pfm)
refused_command(render "--denoise needs the path tracer \\(--mode path\\), not --mode whitted" ${COMMON} --mode whitted --denoise -o ${DIR}/x.png)
refused_command(render "option --aov: unknown feature buffer 'albedos' \\(expected albedo, normal, depth, variance, raw or all\\)"
        ${COMMON} --aov normal,albedos -o ${DIR}/x.png)
