# symlink_escape.cmake — a symlink cannot be stored in git portably, so this builds one at test time:
# WORK/scene/scene.gltf refers to link.bin, a symlink to WORK/outside/data.bin. `caustica info` must
# refuse it naming the reference (exit 1, target not read) and load it with --allow-outside-paths.
set(root ${WORK}/symlink-escape)
file(REMOVE_RECURSE ${root})
file(MAKE_DIRECTORY ${root}/scene ${root}/outside)
file(READ ${BAD}/missing-bin.gltf text)  # a valid one-triangle scene but for its missing.bin buffer
file(COPY_FILE ${BAD}/bin-size-mismatch.bin ${root}/outside/data.bin)  # the triangle's bytes
file(COPY_FILE ${BAD}/bin-size-mismatch.bin ${root}/scene/inside.bin)

function(run_info scene expect_rc expect_text)
  execute_process(COMMAND ${CLI} info ${scene} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                  TIMEOUT 60)
  if(NOT rc EQUAL expect_rc)
    message(FATAL_ERROR "info ${scene} ${ARGN}: expected exit status ${expect_rc}, got '${rc}'\n${out}${err}")
  endif()
  string(FIND "${out}${err}" "${expect_text}" found)
  if(found EQUAL -1)
    message(FATAL_ERROR "info ${scene} ${ARGN}: expected '${expect_text}' in:\n${out}${err}")
  endif()
endfunction()

# A file symlink and a directory symlink out of the folder: refused by name.
file(CREATE_LINK ../outside/data.bin ${root}/scene/link.bin SYMBOLIC)
file(CREATE_LINK ../outside ${root}/scene/linkdir SYMBOLIC)
foreach(uri link.bin linkdir/data.bin)
  string(REPLACE "missing.bin" "${uri}" scene "${text}")
  string(MAKE_C_IDENTIFIER ${uri} name)
  file(WRITE ${root}/scene/${name}.gltf "${scene}")
  run_info(${root}/scene/${name}.gltf 1
           "${name}.gltf: buffers[0].uri '${uri}' leads outside the scene's folder (use --allow-outside-paths to permit)")
  run_info(${root}/scene/${name}.gltf 0 "triangles:  1" --allow-outside-paths)
endforeach()

# A symlink that stays inside the folder loads without the option.
file(CREATE_LINK inside.bin ${root}/scene/inner.bin SYMBOLIC)
string(REPLACE "missing.bin" "inner.bin" scene "${text}")
file(WRITE ${root}/scene/inner.gltf "${scene}")
run_info(${root}/scene/inner.gltf 0 "triangles:  1")
file(REMOVE_RECURSE ${root})
message(STATUS "symlink escapes refused, inside symlinks and --allow-outside-paths load")
