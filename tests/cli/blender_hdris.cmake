# blender_hdris.cmake — every HDRI Blender ships (Debian's blender-data: DWAB-compressed EXR) lights a
# render through --env. Skipped where blender-data is not installed (scripts/setup-deps does not
# install it: 100 MB); tests/image/exr_file_test.cpp covers every compression without it.
include(${CMAKE_CURRENT_LIST_DIR}/cli_run.cmake)
file(GLOB hdris /usr/share/blender/datafiles/studiolights/world/*.exr)
if(NOT hdris)
  message("SKIPPED: blender-data is not installed (apt-get install blender-data)")
  return()
endif()
list(LENGTH hdris count)
foreach(hdri ${hdris})
  get_filename_component(name ${hdri} NAME_WE)
  run(0 cornell-box --env ${hdri} --size 16 --spp 1 --backend osmesa -o ${OUT}/blender-hdri-${name}.exr)
  if(NOT err MATCHES "wrote")
    message(FATAL_ERROR "--env ${hdri}: no image written: ${err}")
  endif()
endforeach()
message("rendered with each of the ${count} Blender HDRIs")
