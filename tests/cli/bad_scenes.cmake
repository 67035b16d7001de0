# bad_scenes.cmake — every scene in DIR must make `caustica info` and `caustica render` exit with
# status 1 (a clean error, not a crash) and print a one-line error that names the file.
file(GLOB bad LIST_DIRECTORIES false ${DIR}/*)
set(count 0)
foreach(f ${bad})
  get_filename_component(ext ${f} EXT)
  if(ext STREQUAL ".bin" OR ext STREQUAL ".png" OR ext STREQUAL ".md")
    continue()  # companions of the bad scenes
  endif()
  get_filename_component(name ${f} NAME)
  foreach(cmd info render)
    if(cmd STREQUAL "render")
      set(extra --size 8 --spp 1 --backend osmesa -o ${CMAKE_CURRENT_BINARY_DIR}/bad.png)
    else()
      set(extra "")
    endif()
    # --instances off: the corpus's limits are those of a flattened load. Under --instances auto (the
    # default) wide-node-tree.gltf, 1000 placements of one 10^6-triangle mesh, is a legitimate instanced
    # scene that stores the mesh once (docs/instancing.md).
    execute_process(COMMAND ${CLI} ${cmd} ${f} ${extra} --instances off RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
    if(NOT rc EQUAL 1)
      message(FATAL_ERROR "${cmd} ${name}: expected exit status 1, got '${rc}'\n${err}")
    endif()
    string(FIND "${err}" "${name}" named)
    if(named EQUAL -1)
      message(FATAL_ERROR "${cmd} ${name}: the error does not name the file: ${err}")
    endif()
  endforeach()
  math(EXPR count "${count} + 1")
endforeach()
if(count LESS 10)
  message(FATAL_ERROR "only ${count} bad scenes found in ${DIR}")
endif()
message(STATUS "${count} bad scenes fail cleanly")
