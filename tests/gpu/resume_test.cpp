// resume_test.cpp — a render saved to a checkpoint file at 8 spp and resumed to 16 spp in a new
// renderer must equal a straight 16-spp render (render --checkpoint / --resume), also with manifold NEE
// (whose caustic photon pass each renderer runs again: the same cells, so the same image); the identity
// records --manifold as the image sees it, so auto and off continue each other where auto finds no caster.
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

TEST_CASE("resume from a checkpoint: the identity holds --manifold as the image sees it; auto continues off bit for bit where it finds no caster") {
  // cornell-glass: two casters, but its large ceiling lamp puts neither under auto, so auto renders
  // the off variant; on (manifold NEE through both) is another image.
  Scene scene = loadScene(sourcePath("assets/scenes/cornell-glass.gltf"));
  Camera camera = sceneCamera(scene);
  ShaderLibrary& library = testShaderLibrary();
  RenderSettings autoRs = smallSettings(16, 12, Integrator::Mis, 5), offRs = autoRs, onRs = autoRs;
  autoRs.manifold = ManifoldMode::Auto;
  offRs.manifold = ManifoldMode::Off;
  onRs.manifold = ManifoldMode::On;

  Renderer straight(library, scene, camera, offRs);
  straight.renderPass(16);
  const Image expected = straight.image();

  Renderer first(library, scene, camera, autoRs);
  first.renderPass(8);
  const GpuScene& gpu = first.gpuScene();
  REQUIRE(gpu.casters.size() == 2);
  const std::uint64_t hash = 0x5eedull;
  cli::Checkpoint written;  // what render --checkpoint writes now: auto resolved to off
  written.state = first.saveAccumulation();
  written.seed = autoRs.seed;
  written.sceneHash = hash;
  written.identity = cli::accumulationIdentity(cli::ImageSettings{autoRs}, camera, gpu);
  CHECK(written.identity.find("\nmanifold off\n") != std::string::npos);
  cli::Checkpoint literal = written;  // what earlier builds wrote: "manifold auto" as given
  literal.identity = cli::accumulationIdentity(cli::ImageSettings{autoRs}, camera);
  CHECK(literal.identity.find("\nmanifold auto\n") != std::string::npos);

  for (const cli::Checkpoint* ck : {&written, &literal}) {
    CAPTURE(ck->identity);
    const std::string off = cli::accumulationIdentity(cli::ImageSettings{offRs}, camera, gpu);
    CHECK(cli::checkpointMismatch(*ck, hash, off, &gpu) == "");
    CHECK(cli::checkpointMismatch(*ck, hash, cli::accumulationIdentity(cli::ImageSettings{autoRs}, camera, gpu), &gpu) == "");
    // Before the scene is packed the manifold lines are not compared; the seed still is.
    CHECK(cli::checkpointMismatch(*ck, hash, cli::accumulationIdentity(cli::ImageSettings{onRs}, camera), nullptr) == "");
    RenderSettings seed2 = offRs;
    seed2.seed = 6;
    CHECK(cli::checkpointMismatch(*ck, hash, cli::accumulationIdentity(cli::ImageSettings{seed2}, camera), nullptr) ==
          "seed: checkpoint 5, this render 6");
    // --manifold on is another image: refused naming both modes (and light tracing, which only the off
    // variant compiles: docs/path-tracer.md).
    CHECK(cli::checkpointMismatch(*ck, hash, cli::accumulationIdentity(cli::ImageSettings{onRs}, camera, gpu), &gpu) ==
          "light-tracing: checkpoint on, this render off; manifold: checkpoint off, this render on");

    Renderer resumed(library, scene, camera, offRs);
    resumed.restoreAccumulation(ck->state);
    resumed.renderPass(8);
    const Image got = resumed.image();
    REQUIRE(got.rgb.size() == expected.rgb.size());
    CHECK(meanOf(expected) > 0.01);
    CHECK(differing(got.rgb, expected.rgb) == 0);
  }
}

TEST_CASE("resume from a checkpoint: auto continues off where light tracing takes the caustics; without it, off does not continue auto where auto finds casters, nor auto on where it takes only some") {
  // lamp-caustics: its small lamp puts both casters under auto's manifold NEE, which light tracing (on by
  // default) goes before: auto then renders what off does; with --light-tracing off, what on does.
  Scene lamp = loadScene(sourcePath("assets/scenes/lamp-caustics.gltf"));
  const Camera camera = sceneCamera(lamp);
  RenderSettings rs = smallSettings(8, 8, Integrator::Mis, 1), offRs = rs, onRs = rs;
  rs.manifold = ManifoldMode::Auto;
  offRs.manifold = ManifoldMode::Off;
  onRs.manifold = ManifoldMode::On;
  RenderSettings eyeRs = rs, eyeOffRs = offRs;  // --light-tracing off
  eyeRs.lightTracing = eyeOffRs.lightTracing = false;
  {
    Renderer renderer(testShaderLibrary(), lamp, camera, rs);
    const GpuScene& gpu = renderer.gpuScene();
    CHECK(cli::imageManifoldMode(rs, gpu) == ManifoldMode::Off);
    CHECK(cli::imageManifoldMode(eyeRs, gpu) == ManifoldMode::On);
    cli::Checkpoint off;  // --manifold off with light tracing: what auto renders
    off.identity = cli::accumulationIdentity(cli::ImageSettings{offRs}, camera);
    CHECK(cli::checkpointMismatch(off, 0, cli::accumulationIdentity(cli::ImageSettings{rs}, camera, gpu), &gpu) == "");
    cli::Checkpoint before;  // the default of the builds before light tracing went first: manifold NEE
    before.identity = cli::accumulationIdentity(cli::ImageSettings{eyeRs}, camera, gpu);
    CHECK(before.identity.find("\nmanifold on\n") != std::string::npos);
    CHECK(cli::checkpointMismatch(before, 0, cli::accumulationIdentity(cli::ImageSettings{rs}, camera, gpu), &gpu) ==
          "light-tracing: checkpoint off, this render on; manifold: checkpoint on, this render off");
    // Without light tracing: an older build's default --manifold off is not what auto renders, on is.
    cli::Checkpoint older;
    older.identity = cli::accumulationIdentity(cli::ImageSettings{eyeOffRs}, camera);
    CHECK(cli::checkpointMismatch(older, 0, cli::accumulationIdentity(cli::ImageSettings{eyeRs}, camera, gpu), &gpu) ==
          "manifold: checkpoint off, this render on");
    cli::Checkpoint on;
    on.identity = cli::accumulationIdentity(cli::ImageSettings{onRs}, camera);
    CHECK(cli::checkpointMismatch(on, 0, cli::accumulationIdentity(cli::ImageSettings{eyeRs}, camera, gpu), &gpu) == "");
  }
  // A glass ball far under a small lamp qualifies, a mirror ball beside it does not: without light tracing
  // auto sends photons through the glass only, an image neither on nor off renders, so it stays "auto".
  const Scene s = lampOverGlassAndMirror();
  const GpuScene g = packScene(s, buildBvh(s.triangles));
  REQUIRE(g.casters.size() == 2);
  CHECK(cli::imageManifoldMode(eyeRs, g) == ManifoldMode::Auto);
  CHECK(cli::imageManifoldMode(rs, g) == ManifoldMode::Off);
  cli::Checkpoint on;
  on.identity = cli::accumulationIdentity(cli::ImageSettings{onRs}, camera);
  CHECK(cli::checkpointMismatch(on, 0, cli::accumulationIdentity(cli::ImageSettings{eyeRs}, camera, g), &g) ==
        "manifold: checkpoint on, this render auto");
  for (ManifoldMode m : {ManifoldMode::On, ManifoldMode::Off}) {
    RenderSettings given = rs;
    given.manifold = m;
    CHECK(cli::imageManifoldMode(given, g) == m);
  }
}
