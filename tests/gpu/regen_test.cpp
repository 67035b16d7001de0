// regen_test.cpp — path regeneration (pathtrace.comp traces K samples per pixel per dispatch in one flat
// bounce loop): the image, its running sums and the counters equal one sample per dispatch bit for bit,
// under adaptive tiles, cut-outs, dispersion and a transparent background; K stays within llvmpipe's
// loop cap, so deep paths lose no energy.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstring>

#include "gl_test_util.h"
#include "scene/environment.h"

using namespace caustica;
using namespace caustica::test;

namespace {

// Renders `passes` (samples per pass) with `perDispatch` samples per dispatch; with `tiles`, the
// second and later passes run on those live tiles only (adaptive sampling).
struct Run {
  AccumulationState state;
  RenderStats stats;
  int perDispatch = 0;
};
Run render(const Scene& scene, const Camera& camera, RenderSettings rs, int perDispatch, const std::vector<int>& passes,
           const std::vector<std::uint32_t>& tiles = {}) {
  rs.samplesPerDispatch = perDispatch;
  Renderer r(testShaderLibrary(), scene, camera, rs);
  for (size_t i = 0; i < passes.size(); ++i) {
    if (i == 1 && !tiles.empty()) r.setLiveTiles(tiles);
    r.renderPass(passes[i]);
  }
  return {r.saveAccumulation(), r.stats(), r.samplesPerDispatch()};
}

void checkSame(const Scene& scene, const Camera& camera, const RenderSettings& rs, int k, const std::vector<int>& passes,
               const std::vector<std::uint32_t>& tiles = {}) {
  Run one = render(scene, camera, rs, 1, passes, tiles);
  Run many = render(scene, camera, rs, k, passes, tiles);
  CHECK(one.perDispatch == 1);
  CHECK(many.perDispatch == k);
  double sum = 0.0;
  for (size_t i = 0; i < one.state.accum.size(); i += 4) sum += one.state.accum[i];
  CHECK(sum > 0.0);  // not a black image
  CHECK(differing(one.state.accum, many.state.accum) == 0);
  CHECK(differing(one.state.comp, many.state.comp) == 0);
  CHECK(differing(one.state.half, many.state.half) == 0);
  CHECK(differing(one.state.coverage, many.state.coverage) == 0);
  CHECK(one.state.sampleBase == many.state.sampleBase);
  CHECK(one.stats.primaryRays == many.stats.primaryRays);
  CHECK(one.stats.secondaryRays == many.stats.secondaryRays);
  CHECK(one.stats.shadowRays == many.stats.shadowRays);
  CHECK(one.stats.nonFinite == many.stats.nonFinite);
}

RenderSettings small(Integrator integ, std::uint32_t seed = 5) { return smallSettings(24, 16, integ, seed); }

// Under a uniform sky: a diffuse floor, a glass ball, a half-transparent (alpha 0.5) cut-out sheet
// and a mirror, seen against a transparent background: cut-outs, coverage and long glass paths.
Scene cutoutScene() {
  Scene s;
  s.path = "regen test";
  Material sheet;
  sheet.baseColor = glm::vec4(0.2f, 0.7f, 0.3f, 0.5f);
  s.materials = {diffuseMaterial(glm::vec3(0.6f, 0.5f, 0.4f)), glassMaterial(1.5f), sheet, metalMaterial(glm::vec3(0.9f))};
  addQuad(s, {-2, -1, 1}, {2, -1, 1}, {2, -1, -5}, {-2, -1, -5}, 0);
  addSphere(s, {-0.4f, -0.4f, -3.0f}, 0.6f, 16, 1);
  addQuad(s, {0.1f, -1, -2.2f}, {1.2f, -1, -2.2f}, {1.2f, 0.6f, -2.2f}, {0.1f, 0.6f, -2.2f}, 2);
  addQuad(s, {0.5f, -1, -4.0f}, {1.8f, -1, -3.5f}, {1.8f, 1.0f, -3.5f}, {0.5f, 1.0f, -4.0f}, 3);
  finishBounds(s);
  s.environment = uniformEnvironment(glm::vec3(1.0f));
  s.background.kind = Background::Kind::Transparent;
  return s;
}

Camera frontCamera() { return cameraAt(glm::vec3(0.0f, 0.0f, 0.5f), glm::vec3(0, -0.15f, -1), glm::vec3(0, 1, 0), 0.9f); }

}  // namespace

TEST_CASE("path regeneration: K samples per dispatch give the image, sums and counters of one per dispatch, bit for bit") {
  SUBCASE("cornell-glass, mis, 4 per dispatch, passes of 7 and 5 (splits 4+3, 4+1)") {
    Scene scene = loadScene(sourcePath("assets/scenes/cornell-glass.gltf"));
    checkSame(scene, sceneCamera(scene), small(Integrator::Mis), 4, {7, 5});
  }
  SUBCASE("cornell-glass, naive, depth 32, 16 per dispatch") {
    Scene scene = loadScene(sourcePath("assets/scenes/cornell-glass.gltf"));
    RenderSettings rs = small(Integrator::Naive, 9);
    rs.maxDepth = 32;
    checkSame(scene, sceneCamera(scene), rs, 16, {16});
  }
  SUBCASE("cornell-dispersion, spectral, mis") {
    Scene scene = loadScene(sourcePath("assets/scenes/cornell-dispersion.gltf"));
    RenderSettings rs = small(Integrator::Mis);
    rs.dispersion = DispersionMode::Spectral;
    checkSame(scene, sceneCamera(scene), rs, 4, {6});
  }
  SUBCASE("cornell-materials (GGX), mis, adaptive: the later passes on live tiles only") {
    Scene scene = loadScene(sourcePath("assets/scenes/cornell-materials.gltf"));
    checkSame(scene, sceneCamera(scene), small(Integrator::Mis), 4, {4, 6, 3}, {0u, 2u | (1u << 16)});
  }
  SUBCASE("cut-outs, glass and a mirror under a sky, transparent background (coverage), depth 128: 2 per dispatch") {
    Scene scene = cutoutScene();
    RenderSettings rs = small(Integrator::Mis);
    rs.maxDepth = 128;  // (128 + 256 pass-throughs) * 2 <= 1024
    checkSame(scene, frontCamera(), rs, 2, {5});
  }
}

TEST_CASE("path regeneration: samples per dispatch stay within llvmpipe's loop cap") {
  Scene scene = loadScene(sourcePath("assets/scenes/cornell-box.gltf"));
  auto perDispatch = [&](int depth, int wanted, RenderMode mode = RenderMode::Path) {
    RenderSettings rs = small(Integrator::Mis);
    rs.maxDepth = depth;
    rs.samplesPerDispatch = wanted;
    rs.mode = mode;
    return Renderer(testShaderLibrary(), scene, sceneCamera(scene), rs).samplesPerDispatch();
  };
  CHECK(perDispatch(256, 0) == 4);    // the default depth: 4 * 256 bounces
  CHECK(perDispatch(1024, 0) == 1);   // the deepest: one sample
  CHECK(perDispatch(1024, 64) == 1);  // asking for more does not pass the bound
  CHECK(perDispatch(300, 64) == 3);
  CHECK(perDispatch(16, 64) == 64);
  CHECK(perDispatch(16, 2) == 2);
  CHECK(perDispatch(16, 0, RenderMode::Whitted) == 1);  // whitted.comp: one sample per dispatch
  Scene cut = cutoutScene();  // alpha pass-throughs (up to 256 per sample) count against the bound
  RenderSettings rs = small(Integrator::Mis);
  CHECK(Renderer(testShaderLibrary(), cut, frontCamera(), rs).samplesPerDispatch() == 2);
}

TEST_CASE("path regeneration: deep paths lose no energy at the largest samples per dispatch asked for") {
  // A closed furnace of albedo 1 emitting 1: Russian roulette never ends a path (its throughput stays
  // 1), so a naive path runs to the depth cap and collects exactly 1 per bounce (a few end early, lost
  // through the box's edges or below the surface: the mean is 0.06 % low at depth 256 and 0.25 % at
  // 1024, with one sample per dispatch as with four). llvmpipe's loop cap,
  // once hit, ends a lane's loop early: its remaining samples are missing from the pixel's count and its
  // paths are cut short. Asking for 64 samples per dispatch must not let that happen (without the bound
  // in samplesPerDispatch(), 16 paths of 256 or 1024 bounces per lane do hit it).
  Scene scene = loadScene(sourcePath("tests/data/scenes/furnace.gltf"));
  for (Material& m : scene.materials) m.baseColor = glm::vec4(1.0f);
  const int spp = 16;
  for (int depth : {256, 1024}) {
    RenderSettings rs = small(Integrator::Naive);
    rs.width = rs.height = 16;
    rs.maxDepth = depth;
    rs.samplesPerDispatch = 64;
    Renderer r(testShaderLibrary(), scene, sceneCamera(scene), rs);
    r.renderPass(spp);
    AccumulationState st = r.saveAccumulation();
    int shortCount = 0;
    for (size_t i = 0; i < st.accum.size(); i += 4) shortCount += st.accum[i + 3] - st.comp[i + 3] != float(spp);
    Image img = r.image();
    INFO("depth ", depth, ", ", r.samplesPerDispatch(), " per dispatch, mean ", meanOf(img), ", pixels with too few samples ",
         shortCount);
    CHECK(shortCount == 0);
    CHECK(meanOf(img) == Rel(depth, 0.005));
    CHECK(r.stats().nonFinite == 0);
  }
}

TEST_CASE("specialisation: a scene without emitters leaves the emitter estimate out (CAUSTICA_NO_EMITTERS), same image bit for bit") {
  // sun-glass under the default sky: mis for the environment alone. The specialised shader leaves
  // sampleEmitterLight and the emitter-hit pdf out but draws their random numbers; --all-features keeps
  // them (and every material feature), so the two must agree bit for bit.
  Scene scene = loadScene(sourcePath("assets/scenes/sun-glass.gltf"));
  REQUIRE_FALSE(sceneHasLights(scene));
  scene.environment = uniformEnvironment(glm::vec3(kDefaultEnvironmentRadiance));
  const Camera camera = sceneCamera(scene);
  RenderSettings rs = small(Integrator::Mis, 3);
  Renderer specialised(testShaderLibrary(), scene, camera, rs);
  rs.allFeatures = true;
  Renderer all(testShaderLibrary(), scene, camera, rs);
  CHECK(hasDefine(specialised.shaderDefines(), "CAUSTICA_NO_EMITTERS"));
  CHECK_FALSE(hasDefine(all.shaderDefines(), "CAUSTICA_NO_EMITTERS"));
  specialised.renderPass(8);
  all.renderPass(8);
  const AccumulationState a = specialised.saveAccumulation(), b = all.saveAccumulation();
  double sum = 0.0;
  for (size_t i = 0; i < a.accum.size(); i += 4) sum += a.accum[i];
  CHECK(sum > 0.0);
  CHECK(differing(a.accum, b.accum) == 0);
  CHECK(differing(a.half, b.half) == 0);
}
