// resume_test.cpp — a render saved to a checkpoint file at 8 spp and resumed to 16 spp in a new
// renderer must equal a straight 16-spp render (render --checkpoint / --resume), also with manifold NEE
// (whose caustic photon pass each renderer runs again: the same cells, so the same image).
#include <doctest/doctest.h>

#include <cstring>
#include <filesystem>

#include "cli/checkpoint.h"
#include "gl_test_util.h"
#include "util/error.h"

using namespace caustica;
using namespace caustica::test;

TEST_CASE("resume from a checkpoint: 8 spp + 8 spp equals 16 spp bit for bit") {
  for (bool manifold : {false, true}) {
    CAPTURE(manifold);
    Scene scene = loadScene(sourcePath("assets/scenes/cornell-glass.gltf"));
    Camera camera = sceneCamera(scene);
    RenderSettings rs = smallSettings(16, 12, Integrator::Mis, 11);
    rs.manifold = manifold ? ManifoldMode::On : ManifoldMode::Off;
    ShaderLibrary& library = testShaderLibrary();
    std::string path = (std::filesystem::temp_directory_path() / "caustica-resume-test.ckpt").string();

    Renderer straight(library, scene, camera, rs);
    straight.renderPass(5);
    straight.renderPass(11);
    Image expected = straight.image();
    AccumulationState expectedState = straight.saveAccumulation();

    {
      Renderer first(library, scene, camera, rs);
      first.renderPass(3);
      first.renderPass(5);
      cli::Checkpoint ck;
      ck.state = first.saveAccumulation();
      CHECK(ck.state.spp == 8);
      CHECK(ck.state.sampleBase == 8u);
      ck.seed = rs.seed;
      ck.identity = cli::accumulationIdentity(cli::ImageSettings{rs}, camera);
      cli::writeCheckpoint(path, ck);
    }
    Renderer resumed(library, scene, camera, rs);
    resumed.restoreAccumulation(cli::readCheckpoint(path).state);
    CHECK(resumed.samplesPerPixel() == 8);
    resumed.renderPass(8);
    CHECK(resumed.samplesPerPixel() == 16);
    Image got = resumed.image();
    AccumulationState gotState = resumed.saveAccumulation();

    REQUIRE(got.rgb.size() == expected.rgb.size());
    CHECK(meanOf(expected) > 0.01);  // not a black image
    CHECK(differing(got.rgb, expected.rgb) == 0);
    CHECK(gotState.accum == expectedState.accum);  // the running sums and their compensation too
    CHECK(gotState.comp == expectedState.comp);

    Renderer wrongSize(library, scene, camera, [&] { RenderSettings s = rs; s.width = 8; return s; }());
    CHECK_THROWS_AS(wrongSize.restoreAccumulation(gotState), Error);
    std::filesystem::remove(path);
  }
}

TEST_CASE("a renderer given a new scene (an animation's next frame) renders what a new renderer does, also with manifold NEE") {
  // Both scenes have two casters, so the same caster mask: the photon cells must still be the new scene's.
  const Scene first = loadScene(sourcePath("assets/scenes/cornell-glass.gltf"));
  const Scene second = loadScene(sourcePath("assets/scenes/lamp-caustics.gltf"));
  for (bool manifold : {false, true}) {
    CAPTURE(manifold);
    RenderSettings rs = smallSettings(16, 12, Integrator::Mis, 3);
    rs.manifold = manifold ? ManifoldMode::On : ManifoldMode::Off;
    ShaderLibrary& library = testShaderLibrary();
    Renderer fresh(library, second, sceneCamera(second), rs);
    fresh.renderPass(8);
    const Image expected = fresh.image();

    Renderer reused(library, first, sceneCamera(first), rs);
    reused.renderPass(8);
    reused.setScene(second, sceneCamera(second));
    reused.renderPass(8);
    const Image got = reused.image();
    REQUIRE(got.rgb.size() == expected.rgb.size());
    CHECK(meanOf(expected) > 0.01);  // not a black image
    CHECK(differing(got.rgb, expected.rgb) == 0);
  }
}
