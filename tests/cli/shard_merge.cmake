# shard_merge.cmake — render --shard K/N and merge as a user runs them (docs/render-farm.md): 3 shards
# merged equal one render (to float rounding); a merged .ckpt continues with render --resume; a shard
# killed (SIGKILL) mid-way resumes from its last partial and completes the set; merge refuses missing,
# overlapping, unfinished and foreign parts naming them, and --partial merges what there is
# (run with cmake -P; CLI, COMPARE (viewer_image_compare) and DIR given).
file(REMOVE_RECURSE ${DIR})
file(MAKE_DIRECTORY ${DIR})
set(COMMON cornell-box --size 16 --backend osmesa -q)
include(${CMAKE_CURRENT_LIST_DIR}/cli_run.cmake)

function(merge_run expect)
  run_command(merge ${expect} ${ARGN})
  set(err "${err}" PARENT_SCOPE)
endfunction()
function(merge_refused pattern)
  refused_command(merge "${pattern}" ${ARGN})
endfunction()
# same(A B): the two linear images agree to float rounding (relative 1e-6).
function(same a b)
  execute_process(COMMAND ${COMPARE} ${a} ${b} 1e-6 RESULT_VARIABLE crc OUTPUT_VARIABLE cout)
  message(STATUS "${a} vs ${b}: ${cout}")
  if(NOT crc EQUAL 0)
    message(FATAL_ERROR "${a} and ${b} differ beyond float rounding: ${cout}")
  endif()
endfunction()

# 3 shards of 10 spp (shares 0-1, 2-5, 6-9) merged equal one render of 10 spp.
foreach(k 1 2 3)
  run(0 ${COMMON} --spp 10 --shard ${k}/3 -o ${DIR}/p${k}.ckpt)
endforeach()
file(READ ${DIR}/p2.ckpt head LIMIT 120)
if(NOT head MATCHES "\nshard 2/3 2 6 10\n")
  message(FATAL_ERROR "the partial of shard 2/3 does not name its share: ${head}")
endif()
run(0 ${COMMON} --spp 10 -o ${DIR}/one.exr)
merge_run(0 ${DIR}/p3.ckpt ${DIR}/p1.ckpt ${DIR}/p2.ckpt -o ${DIR}/merged.exr)
same(${DIR}/merged.exr ${DIR}/one.exr)
merge_run(0 ${DIR}/p1.ckpt ${DIR}/p2.ckpt ${DIR}/p3.ckpt -o ${DIR}/merged.png)

# Partials record --manifold as the image sees it: on cornell-box (no caster) a shard of --manifold off
# merges with shards of the default auto; one of --manifold on (another image there) is refused.
run(0 ${COMMON} --spp 10 --shard 2/3 --manifold off -o ${DIR}/p2-off.ckpt)
merge_run(0 ${DIR}/p1.ckpt ${DIR}/p2-off.ckpt ${DIR}/p3.ckpt -o ${DIR}/merged-off.exr)
same(${DIR}/merged-off.exr ${DIR}/one.exr)
run(0 ${COMMON} --spp 10 --shard 2/3 --manifold on -o ${DIR}/p2-on.ckpt)
merge_refused("are renders with other settings: manifold: .*p1.ckpt off, .*p2-on.ckpt on"
              ${DIR}/p1.ckpt ${DIR}/p2-on.ckpt ${DIR}/p3.ckpt -o ${DIR}/x.exr)

# A merged .ckpt is a whole render's checkpoint: render --resume takes it to more samples.
merge_run(0 ${DIR}/p1.ckpt ${DIR}/p2.ckpt ${DIR}/p3.ckpt -o ${DIR}/merged.ckpt)
run(0 ${COMMON} --spp 14 -o ${DIR}/extended.exr --resume ${DIR}/merged.ckpt)
run(0 ${COMMON} --spp 14 -o ${DIR}/straight14.exr)
same(${DIR}/extended.exr ${DIR}/straight14.exr)

# Refusals, each naming the files and the problem.
merge_refused("missing shard 2/3 \\(samples 2-5\\) of the 10-spp render" ${DIR}/p1.ckpt ${DIR}/p3.ckpt -o ${DIR}/x.exr)
merge_refused("p1.ckpt \\(shard 1/3 \\(samples 0-1\\)\\) and .*p1.ckpt \\(shard 1/3 \\(samples 0-1\\)\\) overlap: the same shard given twice"
              ${DIR}/p1.ckpt ${DIR}/p1.ckpt ${DIR}/p2.ckpt ${DIR}/p3.ckpt -o ${DIR}/x.exr)
run(0 ${COMMON} --spp 10 --seed 2 --shard 2/3 -o ${DIR}/seed2.ckpt)
merge_refused("are renders with other settings: seed: .*p1.ckpt 1, .*seed2.ckpt 2"
              ${DIR}/p1.ckpt ${DIR}/seed2.ckpt ${DIR}/p3.ckpt -o ${DIR}/x.exr)
run(0 cornell-glass --size 16 --backend osmesa -q --spp 10 --shard 2/3 -o ${DIR}/glass.ckpt)
merge_refused("are renders of different scene files" ${DIR}/p1.ckpt ${DIR}/glass.ckpt ${DIR}/p3.ckpt -o ${DIR}/x.exr)
run(0 ${COMMON} --spp 20 --shard 2/3 -o ${DIR}/spp20.ckpt)
merge_refused("shards of renders of different --spp \\(20 and 10\\)" ${DIR}/p1.ckpt ${DIR}/spp20.ckpt -o ${DIR}/x.exr)
run(0 ${COMMON} --spp 10 -o ${DIR}/whole.exr --checkpoint 1000)
merge_refused("whole.exr.ckpt: not a shard's partial" ${DIR}/whole.exr.ckpt -o ${DIR}/x.exr)
merge_refused("a part is also the output" ${DIR}/p1.ckpt ${DIR}/p2.ckpt ${DIR}/p3.ckpt -o ${DIR}/p1.ckpt)
if(EXISTS ${DIR}/x.exr)
  message(FATAL_ERROR "a refused merge wrote an image")
endif()
# --partial merges what there is, says what is missing, and will not write a gapped .ckpt.
merge_run(0 ${DIR}/p1.ckpt ${DIR}/p3.ckpt --partial -o ${DIR}/partial.exr)
if(NOT err MATCHES "partial merge: 6 of 10 samples per pixel; missing samples 2-5")
  message(FATAL_ERROR "--partial does not say what is missing: ${err}")
endif()
merge_refused("the merged samples have gaps" ${DIR}/p1.ckpt ${DIR}/p3.ckpt --partial -o ${DIR}/partial.ckpt)

# The render side refuses what a shard cannot keep.
function(render_refused pattern)
  refused_command(render "${pattern}" ${ARGN})
endfunction()
render_refused("--shard writes a mergeable partial, not an image" ${COMMON} --shard 1/2 -o ${DIR}/x.exr)
render_refused("--target-error with --shard" ${COMMON} --shard 1/2 --target-error 0.01 -o ${DIR}/x.ckpt)
render_refused("--time with --shard" ${COMMON} --shard 1/2 --time 5 -o ${DIR}/x.ckpt)
render_refused("option --shard needs K/N with 1 <= K <= N" ${COMMON} --shard 3/2 -o ${DIR}/x.ckpt)
render_refused("--mode raster with --shard" ${COMMON} --mode raster --shard 1/2 -o ${DIR}/x.ckpt)
render_refused("a .ckpt output is a shard's partial: add --shard K/N" ${COMMON} -o ${DIR}/x.ckpt)
render_refused("p2.ckpt: cannot resume another shard: the file holds shard 2/3 \\(samples 2-5\\) of 10 spp, this render is shard 1/3"
               ${COMMON} --spp 10 --shard 1/3 -o ${DIR}/x.ckpt --resume ${DIR}/p2.ckpt)
render_refused("p2.ckpt: it is the partial of shard 2/3 \\(samples 2-5\\) of 10 spp: continue it with --shard 2/3 --spp 10"
               ${COMMON} --spp 10 -o ${DIR}/x.exr --resume ${DIR}/p2.ckpt)

# Faults: shard 2/2 of 8000 spp writes its partial every 0.3 s and is killed (SIGKILL: no handler runs)
# after its first one; the partial is unfinished, merge names it, and resuming it completes the set.
set(BIG cornell-box --size 16 --backend osmesa --spp 8000)  # not quiet: the resume lines are checked
run(0 ${BIG} --shard 1/2 -o ${DIR}/big1.ckpt --resume auto)
if(NOT err MATCHES "--resume auto: no [^ ]*big1.ckpt yet, starting the render")
  message(FATAL_ERROR "--resume auto without a partial does not say it starts: ${err}")
endif()
execute_process(
  COMMAND sh -c "\"$0\" render $1 --shard 2/2 -o \"$2\" --checkpoint 0.3 &
pid=$!
i=0
while [ ! -f \"$2\" ] && [ $i -lt 600 ]; do sleep 0.05; i=$((i+1)); done
kill -KILL $pid
wait $pid
echo \"exit=$?\"" ${CLI} "cornell-box --size 16 --backend osmesa -q --spp 8000" ${DIR}/big2.ckpt
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 110)
message(STATUS "killed shard: ${out}")
if(NOT out MATCHES "exit=137")
  message(FATAL_ERROR "the shard was not killed mid-way (it finished before its first partial?): ${out} ${err}")
endif()
merge_refused("big2.ckpt: shard 2/2 \\(samples 4000-7999\\) is incomplete: it holds samples 4000-[0-9]+ \\(continue it with render --shard 2/2 --resume .*big2.ckpt\\)"
              ${DIR}/big1.ckpt ${DIR}/big2.ckpt -o ${DIR}/x.exr)
# --resume auto: the job script's one command line continues the partial (and starts when there is none).
run(0 ${BIG} --shard 2/2 -o ${DIR}/big2.ckpt --resume auto)
if(NOT err MATCHES "resumed [^ ]*big2.ckpt at [0-9]+ spp")
  message(FATAL_ERROR "--resume auto did not continue the partial: ${err}")
endif()
merge_run(0 ${DIR}/big1.ckpt ${DIR}/big2.ckpt -o ${DIR}/big.exr)
run(0 ${BIG} -o ${DIR}/big-one.exr)
same(${DIR}/big.exr ${DIR}/big-one.exr)
