# bench_tests.cmake — tests of `caustica bench`: a smoke run of the program on llvmpipe (measured runs,
# the reference cache, --adaptive-bound). Included by tests/CMakeLists.txt; run with `cmake -P` (CLI, OUT, GNUPLOT set)
# this same file is the smoke check itself.

if(CMAKE_SCRIPT_MODE_FILE)
  # ---- smoke check: a tiny bench twice (the second must hit the reference cache) ---------------
  file(REMOVE_RECURSE ${OUT})
  set(args bench cornell-glass --size 16 --reference-spp 64 --max-seconds 0.3 --out ${OUT} --cache ${OUT}/cache
      --backend osmesa)
  execute_process(COMMAND ${CLI} ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "caustica bench failed (${rc}):\n${err}")
  endif()
  if(NOT err MATCHES "reference rgb, 64 spp mis: rendered")
    message(FATAL_ERROR "the first run did not render its reference:\n${err}")
  endif()
  # The CSV: a header and at least one checkpoint row per estimator, with finite relMSE values.
  set(csv ${OUT}/bench-cornell-glass.csv)
  if(NOT EXISTS ${csv})
    message(FATAL_ERROR "no ${csv}")
  endif()
  file(STRINGS ${csv} lines)
  list(LENGTH lines n)
  if(n LESS 3)
    message(FATAL_ERROR "${csv} has ${n} lines, expected a header and rows:\n${lines}")
  endif()
  list(GET lines 0 header)
  if(NOT header MATCHES "^scene,integrator,dispersion,.*relmse,relmse_caustic")
    message(FATAL_ERROR "${csv}: unexpected header '${header}'")
  endif()
  foreach(integrator naive mis "mis adaptive")
    set(found FALSE)
    foreach(line ${lines})
      if(line MATCHES "^cornell-glass,${integrator},rgb,16,16,")
        set(found TRUE)
        if(line MATCHES ",nan,|,inf,")
          message(FATAL_ERROR "${csv}: non-finite value in '${line}'")
        endif()
      endif()
    endforeach()
    if(NOT found)
      message(FATAL_ERROR "${csv} has no ${integrator} rows:\n${lines}")
    endif()
  endforeach()
  if(NOT out MATCHES "\\| cornell-glass \\| naive \\| 16x16 \\|" OR NOT out MATCHES "mis/naive efficiency"
     OR NOT out MATCHES "mis adaptive/mis t\\(0.01\\)")
    message(FATAL_ERROR "the summary table is missing or incomplete:\n${out}")
  endif()
  foreach(f summary.md cornell-glass-rgb-reference.png bench-cornell-glass.gp)
    if(NOT EXISTS ${OUT}/${f})
      message(FATAL_ERROR "no ${OUT}/${f}")
    endif()
  endforeach()
  if(GNUPLOT AND NOT EXISTS ${OUT}/bench-cornell-glass.png)
    message(FATAL_ERROR "gnuplot is installed but no plot was written:\n${err}")
  endif()

  execute_process(COMMAND ${CLI} ${args} --quiet RESULT_VARIABLE rc OUTPUT_VARIABLE out2 ERROR_VARIABLE err2)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "the second caustica bench failed (${rc}):\n${err2}")
  endif()
  file(GLOB cached ${OUT}/cache/cornell-glass-rgb-*-a.exr)
  list(LENGTH cached ncached)
  if(NOT ncached EQUAL 1)
    message(FATAL_ERROR "expected one cached reference in ${OUT}/cache, found ${ncached}: ${cached}")
  endif()
  if(NOT out2 MATCHES "\\| cornell-glass \\| mis \\| 16x16 \\|")
    message(FATAL_ERROR "the cached run printed no summary:\n${out2}")
  endif()
  # --adaptive-bound: no measured runs, one table row with finite bounds and the sampler's allocation.
  execute_process(COMMAND ${CLI} ${args} --quiet --adaptive-bound --bound-spp 32 RESULT_VARIABLE rc OUTPUT_VARIABLE out3
                  ERROR_VARIABLE err3)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "caustica bench --adaptive-bound failed (${rc}):\n${err3}")
  endif()
  if(NOT out3 MATCHES "\\| cornell-glass \\| 16x16 \\| 32 \\| [0-9]+ \\| [0-9.]+ \\| [0-9.]+ \\| [0-9.]+ \\| [0-9.]+ \\| [0-9.]+ \\| [0-9.]+ at [0-9]+ \\|"
     OR NOT EXISTS ${OUT}/cornell-glass-rgb-tile-variance.txt)
    message(FATAL_ERROR "--adaptive-bound printed no complete row or wrote no tile variances:\n${out3}")
  endif()
  return()
endif()

# ---- included from tests/CMakeLists.txt ---------------------------------------------------------
# The unit tests (bench_metrics_test.cpp, reference_cache_test.cpp, report_test.cpp) are built into
# cli_tests by tests/CMakeLists.txt.
find_program(CAUSTICA_GNUPLOT gnuplot)
add_test(NAME "bench: smoke run writes CSV, plot and summary, then reuses the cached reference"
         COMMAND ${CMAKE_COMMAND} -DCLI=$<TARGET_FILE:caustica> -DOUT=${CMAKE_CURRENT_BINARY_DIR}/bench_smoke
                 -DGNUPLOT=${CAUSTICA_GNUPLOT} -P ${CMAKE_CURRENT_LIST_FILE})
set_tests_properties("bench: smoke run writes CSV, plot and summary, then reuses the cached reference"
                     PROPERTIES ENVIRONMENT "LP_NUM_THREADS=2" TIMEOUT 120)

# bench/run-all, the command behind docs/benchmarks.md, end to end on one tiny scene (run_all_smoke.cmake).
find_package(Python3 COMPONENTS Interpreter)
if(Python3_Interpreter_FOUND)
  add_test(NAME "bench: run-all --smoke fills every region of docs/benchmarks.md"
           COMMAND ${CMAKE_COMMAND} -DPYTHON=${Python3_EXECUTABLE} -DSRC=${CMAKE_SOURCE_DIR} -DCLI=$<TARGET_FILE:caustica>
                   -DOUT=${CMAKE_CURRENT_BINARY_DIR}/run_all_smoke -P ${CMAKE_CURRENT_LIST_DIR}/run_all_smoke.cmake)
  set_tests_properties("bench: run-all --smoke fills every region of docs/benchmarks.md"
                       PROPERTIES ENVIRONMENT "LP_NUM_THREADS=2" TIMEOUT 300)
  # bench/cycles-compare needs Blender, which caustica never does: without it, it must say so (exit 2).
  add_test(NAME "bench: cycles-compare without Blender says so"
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_SOURCE_DIR}/bench/cycles-compare --blender /nonexistent/blender
                   --out ${CMAKE_CURRENT_BINARY_DIR}/cycles_compare_absent)
  set_tests_properties("bench: cycles-compare without Blender says so"
                       PROPERTIES PASS_REGULAR_EXPRESSION "Blender not found \\('/nonexistent/blender'\\)" TIMEOUT 30)
endif()
