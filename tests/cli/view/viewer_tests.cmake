# viewer_tests.cmake — tests of `caustica view`: its camera math and time model (no GL), and the window
# itself run under Xvfb (Debian packages xvfb and xauth; Mesa llvmpipe draws). Included by
# tests/CMakeLists.txt, which builds the unit tests (camera_controller_test.cpp, frame_pacer_test.cpp)
# into cli_tests.

# Compares two linear images within float rounding (and insists they are not black).
add_executable(viewer_image_compare ${CMAKE_CURRENT_LIST_DIR}/image_compare.cpp)
target_link_libraries(viewer_image_compare PRIVATE caustica_scene)
target_compile_options(viewer_image_compare PRIVATE ${CAUSTICA_WARNINGS})

if(CAUSTICA_VIEWER)
  set(VIEWER_TEST_DIR ${CMAKE_CURRENT_BINARY_DIR}/viewer)
  find_program(XVFB_RUN xvfb-run)
  if(XVFB_RUN)
    # RESOURCE_LOCK: concurrent `xvfb-run -a` calls can race for the same server number.
    # The window's screenshot after some frames equals `render` with the same seed and spp: once with
    # the default budget, once with a tiny budget (passes split in row bands, a preview first).
    # The Whitted mode too (its jittered samples are seeded alike; docs/render-modes.md). The path mode
    # shows the denoised image (docs/denoising.md), compared with render --denoise; --no-denoise the raw one.
    foreach(case "default;64;;" "banded;96x72;--budget-ms 2;" "whitted;64;;whitted" "raw;64;--no-denoise;")
      list(GET case 0 name)
      list(GET case 1 size)
      list(GET case 2 viewArgs)
      list(GET case 3 mode)
      add_test(NAME "viewer: screenshot matches a headless render (${name})"
               COMMAND ${CMAKE_COMMAND} -DXVFB_RUN=${XVFB_RUN} -DCLI=$<TARGET_FILE:caustica>
                       -DCOMPARE=$<TARGET_FILE:viewer_image_compare> -DDIR=${VIEWER_TEST_DIR}/${name}
                       -DSIZE=${size} "-DVIEW_ARGS=${viewArgs}" "-DMODE=${mode}" -P ${CMAKE_CURRENT_LIST_DIR}/view_matches_render.cmake)
      set_tests_properties("viewer: screenshot matches a headless render (${name})"
                           PROPERTIES ENVIRONMENT "LP_NUM_THREADS=2" TIMEOUT 180 RESOURCE_LOCK xvfb)
    endforeach()
    # A moving camera (preview resolution, then full) runs and ends in a complete image.
    add_test(NAME "viewer: spinning camera with preview"
             COMMAND ${CMAKE_COMMAND} -DXVFB_RUN=${XVFB_RUN} -DCLI=$<TARGET_FILE:caustica>
                     -DCOMPARE=$<TARGET_FILE:viewer_image_compare> -DDIR=${VIEWER_TEST_DIR}/spin
                     -P ${CMAKE_CURRENT_LIST_DIR}/view_spin.cmake)
    set_tests_properties("viewer: spinning camera with preview"
                         PROPERTIES ENVIRONMENT "LP_NUM_THREADS=2" TIMEOUT 180 RESOURCE_LOCK xvfb)
    # --target-error: refining (and GPU work) stops once the error estimate reaches the target.
    add_test(NAME "viewer: --target-error stops refining at the target"
             COMMAND ${CMAKE_COMMAND} -DXVFB_RUN=${XVFB_RUN} -DCLI=$<TARGET_FILE:caustica> -DDIR=${VIEWER_TEST_DIR}/target
                     -P ${CMAKE_CURRENT_LIST_DIR}/view_target.cmake)
    set_tests_properties("viewer: --target-error stops refining at the target"
                         PROPERTIES ENVIRONMENT "LP_NUM_THREADS=2" TIMEOUT 180 RESOURCE_LOCK xvfb)
  else()
    message(STATUS "xvfb-run not found: the viewer's window tests are skipped (Debian: apt-get install xvfb xauth)")
  endif()
  add_test(NAME "viewer: no display fails and points to render"
           COMMAND ${CMAKE_COMMAND} -DCLI=$<TARGET_FILE:caustica> -P ${CMAKE_CURRENT_LIST_DIR}/view_without_display.cmake)
endif()
