# run_all_smoke.cmake — bench/run-all, the command that re-measures docs/benchmarks.md, run tiny on one
# scene (--smoke): every section must measure, and --apply must fill every region of a copy of the page
# with a table (it reads caustica's output: a changed `info`, load line or bench CSV breaks it here).
# Run with `cmake -P` (PYTHON, SRC, CLI, OUT set).
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT}/doc)
execute_process(COMMAND ${PYTHON} ${SRC}/bench/run-all --smoke --scenes mirror-caustic --backend osmesa
                        --caustica ${CLI} --out ${OUT}/run --cache ${OUT}/cache
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "bench/run-all --smoke failed (${rc}):\n${err}\n${out}")
endif()
foreach(f page.md throughput.csv bvh-scenes.csv big.csv error/bench-mirror-caustic.csv error-no-casters/bench-mirror-caustic.csv
         denoise/denoise.csv)
  if(NOT EXISTS ${OUT}/run/${f})
    message(FATAL_ERROR "bench/run-all wrote no ${f}:\n${err}")
  endif()
endforeach()
file(COPY ${SRC}/docs/benchmarks.md DESTINATION ${OUT}/doc)
execute_process(COMMAND ${PYTHON} ${SRC}/bench/run-all --apply --out ${OUT}/run --doc ${OUT}/doc/benchmarks.md
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0 OR err MATCHES "warning")
  message(FATAL_ERROR "bench/run-all --apply failed (${rc}):\n${err}")
endif()
file(READ ${OUT}/doc/benchmarks.md page)
foreach(region machine throughput specialisation regeneration error adaptive casters denoise bvh-scenes bvh-build big
               instancing)
  string(FIND "${page}" "<!-- run-all:${region} begin -->" b)
  string(FIND "${page}" "<!-- run-all:${region} end -->" e)
  if(b LESS 0 OR e LESS b)
    message(FATAL_ERROR "docs/benchmarks.md has no region ${region}")
  endif()
  math(EXPR n "${e} - ${b}")
  string(SUBSTRING "${page}" ${b} ${n} body)
  if(region STREQUAL "machine")
    if(NOT body MATCHES "Measured .* by `bench/run-all --smoke")
      message(FATAL_ERROR "region machine was not filled:\n${body}")
    endif()
  elseif(NOT body MATCHES "\n\\| mirror-caustic[ ,|]" AND NOT body MATCHES "\n\\| (bunny|sphere|8 spheres)")
    message(FATAL_ERROR "region ${region} has no table row:\n${body}")
  endif()
endforeach()
foreach(f bench-mirror-caustic.png bench-mirror-caustic-reference.png)
  if(NOT EXISTS ${OUT}/doc/images/${f})
    message(WARNING "no plot ${f} (gnuplot missing?)")
  endif()
endforeach()
