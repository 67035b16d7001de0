// render_test.cpp — accuracy of the path tracer against ground truth on llvmpipe: furnaces with known
// answers, an invisible glass sphere, naive vs MIS agreement (per block, and per region under curved
// lights), a caustic where optics puts it, rgb vs spectral dispersion, manifold NEE against naive and
// mis (image, quadrants and caustic regions), reproducibility, and no non-finite samples.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <numeric>

#include <glm/gtc/matrix_transform.hpp>

#include "shading/layers.h"
#include "shading/microfacet.h"
#include "shading/sampling.h"
#include "util/error.h"
#include "gl_test_util.h"

using namespace caustica;
using namespace caustica::test;

namespace {

// Per-block means of several independent renders (different seeds) for a statistical comparison.
struct BlockStats {
  int blocksX = 0, blocksY = 0;
  std::vector<double> mean, var;  // per block and channel: mean of the renders, variance of that mean
  // Per render: the image mean and the means of its four quadrants (grey), for region tests.
  std::vector<std::array<double, 5>> regions;
  std::vector<std::vector<double>> perRender;  // per render: the block means (block and channel), as mean's
};

BlockStats blockStats(const Scene& scene, const Camera& cam, Integrator integrator, int w, int h, int block, int spp,
                      int renders, std::uint32_t seedBase, std::uint64_t* nonFinite, int maxDepth,
                      float casterProbability = 0.5f, std::vector<std::string>* defines = nullptr,
                      ManifoldMode manifold = ManifoldMode::Off, float guideProbability = 0.5f) {
  BlockStats b;
  b.blocksX = w / block;
  b.blocksY = h / block;
  size_t nb = static_cast<size_t>(b.blocksX) * b.blocksY * 3;
  std::vector<std::vector<double>> per(renders, std::vector<double>(nb, 0.0));
  for (int r = 0; r < renders; ++r) {
    RenderSettings settings = smallSettings(w, h, integrator, seedBase + r);
    settings.maxDepth = maxDepth;
    settings.casterProbability = casterProbability;
    settings.manifold = manifold;
    settings.guideProbability = guideProbability;
    settings.lightTracing = false;  // the eye-path estimators these comparisons measure (light tracing: its own tests)
    RenderResult res = renderScene(scene, cam, settings, spp);
    *nonFinite += res.stats.nonFinite;
    if (defines) *defines = res.defines;
    b.regions.push_back(quadrantMeans(res.image));
    for (int y = 0; y < b.blocksY * block; ++y)
      for (int x = 0; x < b.blocksX * block; ++x)
        for (int c = 0; c < 3; ++c)
          per[r][(static_cast<size_t>(y / block) * b.blocksX + x / block) * 3 + c] += res.image.at(x, y, c) / (block * block);
  }
  b.mean.assign(nb, 0.0);
  b.var.assign(nb, 0.0);
  b.perRender = per;
  for (size_t i = 0; i < nb; ++i) {
    for (int r = 0; r < renders; ++r) b.mean[i] += per[r][i] / renders;
    for (int r = 0; r < renders; ++r) b.var[i] += (per[r][i] - b.mean[i]) * (per[r][i] - b.mean[i]) / (renders - 1);
    b.var[i] /= renders;  // variance of the mean
  }
  return b;
}

// With CAUSTICA_LONG_TESTS=1 (scripts/stress-long) the estimator comparisons take `longFactor` times
// the samples, enough that the image-mean comparison fails a 0.5 % bias (asserted); the normal run
// resolves about 1.2-3 % (printed).
bool longTests() { return std::getenv("CAUSTICA_LONG_TESTS") != nullptr; }

// Two estimators must agree within noise: per block, |difference| within 4.5 standard errors (plus a
// small relative slack for the variance estimate's own noise); the image and its quadrants within 4.5
// standard errors of their own. Without `blocks` only the image and its quadrants (for an estimator
// that finds a small lamp in too few of a block's samples to estimate its variance).
void checkBlocksAgree(const std::string& what, const BlockStats& a, const BlockStats& b, bool blocks = true) {
  int bad = 0;
  std::string worst;
  for (size_t i = 0; i < a.mean.size() && blocks; ++i) {
    double diff = std::abs(a.mean[i] - b.mean[i]);
    double tol = 4.5 * std::sqrt(a.var[i] + b.var[i]) + 0.01 * std::max(a.mean[i], b.mean[i]) + 1e-4;
    if (diff > tol) {
      ++bad;
      worst = "block " + std::to_string(i / 3) + " channel " + std::to_string(i % 3) + ": naive " +
              std::to_string(a.mean[i]) + " mis " + std::to_string(b.mean[i]) + " tol " + std::to_string(tol);
    }
  }
  INFO(what, ": ", bad, " of ", a.mean.size(), " block channels disagree; e.g. ", worst);
  CHECK(bad <= 1);  // one in ~200 may fall outside 4.5 sigma with an estimated variance
  // The image and its quadrants, each against its own standard error (from the spread of the
  // independent renders): |difference| within 4.5 of them. The image mean's test must itself be
  // sharp enough to fail a 0.5 % bias (asserted), so a 1 % bias can no longer hide in the noise.
  static const char* kRegion[] = {"image", "top left", "top right", "bottom left", "bottom right"};
  for (int k = 0; k < 5; ++k) {
    auto stats = [&](const BlockStats& s) {
      double m = 0.0, v = 0.0;
      const double n = static_cast<double>(s.regions.size());
      for (const auto& r : s.regions) m += r[k] / n;
      for (const auto& r : s.regions) v += (r[k] - m) * (r[k] - m) / (n - 1.0);
      return std::pair<double, double>(m, v / n);
    };
    const auto [ma, va] = stats(a);
    const auto [mb, vb] = stats(b);
    const double se = std::sqrt(va + vb), mean = 0.5 * (ma + mb);
    INFO(what, ", ", kRegion[k], ": naive ", ma, " mis ", mb, ", standard error of the difference ", se,
         " (", 100.0 * se / mean, " % of the mean)");
    CHECK(std::abs(ma - mb) <= 4.5 * se);
    if (k == 0) {
      MESSAGE(what, ": naive ", ma, ", mis ", mb, "; the smallest image-mean bias this run detects: ",
              100.0 * 4.5 * se / mean, " %");
      if (longTests()) CHECK(4.5 * se <= 0.005 * mean);  // detects a 0.5 % bias of the image mean
    }
  }
}

void checkEstimatorsAgree(const std::string& scenePath, int w, int h, int sppNaive, int sppMis, int maxDepth,
                          int longFactor) {
  if (longTests()) {
    sppNaive *= longFactor;
    sppMis *= longFactor;
  }
  Scene scene = loadScene(sourcePath(scenePath));
  Camera cam = sceneCamera(scene);
  std::uint64_t nonFinite = 0;
  const int block = 8, renders = 8;
  BlockStats a = blockStats(scene, cam, Integrator::Naive, w, h, block, sppNaive, renders, 100, &nonFinite, maxDepth);
  BlockStats b = blockStats(scene, cam, Integrator::Mis, w, h, block, sppMis, renders, 200, &nonFinite, maxDepth);
  checkBlocksAgree(scenePath, a, b);
  CHECK(nonFinite == 0);
}

}  // namespace

TEST_CASE("furnace: walls of albedo 0.5 emitting 1 give radiance 2 everywhere") {
  for (const char* file : {"tests/data/scenes/furnace.gltf", "tests/data/scenes/furnace-glass.gltf"}) {
    Scene scene = loadScene(sourcePath(file));
    for (Integrator integ : {Integrator::Naive, Integrator::Mis}) {
      RenderResult r = renderScene(scene, sceneCamera(scene), smallSettings(32, 32, integ), 64);
      INFO(file, " ", std::string(integratorName(integ)));
      for (int c = 0; c < 3; ++c) CHECK(meanOf(r.image, c) == Rel(2.0, 0.01));
      // Pixels more than 30 % off: none where every path sees the same walls; the glass furnace's
      // naive render has an occasional firefly pixel (measured over seeds 1-12 with two random
      // streams: one such pixel in 6 of 24 renders, never two), so it may have two.
      int farOff = 0;
      for (size_t i = 0; i + 2 < r.image.rgb.size(); i += 3)
        farOff += std::abs(r.image.rgb[i] - 2.0f) > 0.6f || std::abs(r.image.rgb[i + 1] - 2.0f) > 0.6f ||
                  std::abs(r.image.rgb[i + 2] - 2.0f) > 0.6f;
      CHECK(farOff <= (std::string(file).find("glass") != std::string::npos ? 2 : 0));
      CHECK(r.stats.nonFinite == 0);
    }
  }
}

TEST_CASE("a clear glass sphere inside a uniformly emitting black enclosure is invisible") {
  Scene scene = loadScene(sourcePath("tests/data/scenes/glass-in-white-enclosure.gltf"));
  for (Integrator integ : {Integrator::Naive, Integrator::Mis}) {
    RenderSettings settings = smallSettings(32, 32, integ);
    settings.maxDepth = 256;  // rays caught by total internal reflection near the rim need many bounces
    RenderResult r = renderScene(scene, sceneCamera(scene), settings, 32);
    INFO(std::string(integratorName(integ)));
    CHECK(meanOf(r.image) == Rel(1.0, 0.003));
    int off = 0;
    float hi = 0.0f;
    for (float v : r.image.rgb) {
      off += std::abs(v - 1.0f) > 0.1f;
      hi = std::max(hi, v);
    }
    // No dark silhouette, no bright rim: each path that leaves the glass carries exactly the
    // enclosure's radiance. Only paths trapped at the rim of the tessellated sphere until the depth
    // limit lose energy, in a few pixels.
    CHECK(off <= static_cast<int>(r.image.rgb.size() / 100));
    CHECK(hi < 1.02f);
    CHECK(r.stats.nonFinite == 0);
  }
}

TEST_CASE("naive and mis converge to the same image: Cornell box") {
  checkEstimatorsAgree("assets/scenes/cornell-box.gltf", 32, 32, 256, 64, 32, 48);
}

TEST_CASE("naive and mis converge to the same image at a depth limit of 2: Cornell box") {
  // Light sampling at the last allowed vertex would add light one bounce beyond the limit.
  checkEstimatorsAgree("assets/scenes/cornell-box.gltf", 32, 32, 256, 64, 2, 64);
}

TEST_CASE("naive and mis converge to the same image: glass and mirror spheres") {
  checkEstimatorsAgree("tests/data/scenes/small-cornell.gltf", 32, 32, 256, 64, 32, 32);
}

TEST_CASE("naive and mis converge to the same image: bunny-shaped light") {
  checkEstimatorsAgree("assets/scenes/cornell-bunny-light.gltf", 32, 32, 256, 64, 32, 8);
}

TEST_CASE("same seed, same image; another seed, another image") {
  Scene scene = loadScene(sourcePath("tests/data/scenes/small-cornell.gltf"));
  RenderResult a = renderScene(scene, sceneCamera(scene), smallSettings(16, 16, Integrator::Mis, 5), 4, 4);
  RenderResult b = renderScene(scene, sceneCamera(scene), smallSettings(16, 16, Integrator::Mis, 5), 4, 1);  // other split
  RenderResult c = renderScene(scene, sceneCamera(scene), smallSettings(16, 16, Integrator::Mis, 6), 4, 4);
  double maxDiff = 0, otherDiff = 0;
  for (size_t i = 0; i < a.image.rgb.size(); ++i) {
    maxDiff = std::max(maxDiff, double(std::abs(a.image.rgb[i] - b.image.rgb[i])));
    otherDiff = std::max(otherDiff, double(std::abs(a.image.rgb[i] - c.image.rgb[i])));
  }
  CHECK(maxDiff <= 1e-5);  // only the order of float additions may differ
  CHECK(otherDiff > 1e-3);
}

TEST_CASE("Renderer::apply: a renderer whose settings changed renders what a new one would") {
  // Renderer::apply is the one place that decides what a settings change rebuilds: after changing
  // size, estimator, depth, seed and caster aiming on an existing renderer, the image must equal a
  // fresh renderer's with those settings (same variant, same accumulation restart).
  Scene scene = loadScene(sourcePath("assets/scenes/cornell-glass.gltf"));
  ShaderLibrary& library = testShaderLibrary();
  RenderSettings first = smallSettings(12, 10, Integrator::Naive, 3);
  RenderSettings second = smallSettings(16, 12, Integrator::Mis, 9);
  second.maxDepth = 7;
  second.casterProbability = 0.3f;
  Renderer changed(library, scene, sceneCamera(scene), first);
  changed.renderPass(2);
  SettingsChange c = changed.apply(second);
  CHECK((c.restart && c.resize && c.shader && c.casters));
  CHECK(changed.samplesPerPixel() == 0);
  changed.renderPass(3);
  CHECK_FALSE(changed.apply(second).restart);  // the same settings again: nothing restarts
  CHECK(changed.samplesPerPixel() == 3);
  RenderResult fresh = renderScene(scene, sceneCamera(scene), second, 3, 3);
  Image img = changed.image();
  REQUIRE(img.rgb.size() == fresh.image.rgb.size());
  double maxDiff = 0;
  for (size_t i = 0; i < img.rgb.size(); ++i) maxDiff = std::max(maxDiff, double(std::abs(img.rgb[i] - fresh.image.rgb[i])));
  CHECK(maxDiff == 0.0);
  CHECK(changed.shaderDefines() == fresh.defines);
  // An invalid change is refused and leaves the renderer as it was.
  RenderSettings bad = second;
  bad.maxDepth = 0;
  CHECK_THROWS_AS(changed.apply(bad), Error);
  CHECK(changed.settings() == second);
  CHECK(changed.samplesPerPixel() == 3);
}

namespace {

// A floor, a small light above it and a glass sphere between them whose focus lies on the floor.
Scene causticScene(float dispersion, float h = 0.15f) {
  Scene s;
  Material glass = glassMaterial(1.5f);
  glass.dispersion = dispersion;
  s.materials = {diffuseMaterial(0.8f), emitterMaterial(18.0f), glass};
  addQuad(s, {-1.5f, 0, 1.5f}, {1.5f, 0, 1.5f}, {1.5f, 0, -1.5f}, {-1.5f, 0, -1.5f}, 0);  // floor, facing +y
  addQuad(s, {-h, 2.5f, -h}, {h, 2.5f, -h}, {h, 2.5f, h}, {-h, 2.5f, h}, 1);               // light, facing -y
  addSphere(s, {0.0f, 0.62f, 0.0f}, 0.3f, 24, 2);
  finishBounds(s);
  s.cameras.push_back(lookAt({0.0f, 1.4f, 1.9f}, {0.0f, 0.0f, 0.0f}, 0.9f));
  return s;
}

// Pixel of a world point for the renderer's pinhole camera (square image of size n).
glm::ivec2 project(const Camera& cam, glm::vec3 p, int n) {
  glm::vec3 f = glm::normalize(cam.forward), r = glm::normalize(glm::cross(f, cam.up)), u = glm::cross(r, f);
  glm::vec3 d = p - cam.position;
  float t = std::tan(0.5f * cam.yfov);
  float x = glm::dot(d, r) / glm::dot(d, f) / t, y = glm::dot(d, u) / glm::dot(d, f) / t;
  return {static_cast<int>((x + 1) / 2 * n), static_cast<int>((1 - y) / 2 * n)};
}

double floorRadiance(const Image& img, const Camera& cam, float radius, float angle) {
  glm::ivec2 px = project(cam, {radius * std::cos(angle), 0.0f, radius * std::sin(angle)}, img.width);
  double sum = 0;
  for (int c = 0; c < 3; ++c) sum += img.at(px.x, px.y, c) / 3.0;
  return sum;
}

// Median or mean of the floor radiance over an annulus (the median is robust against the
// fireflies of caustic paths).
double floorAnnulus(const Image& img, const Camera& cam, float r0, float r1, bool median) {
  std::vector<double> v;
  for (float r = r0; r <= r1 + 1e-6f; r += (r1 - r0) / 4)
    for (int k = 0; k < 48; ++k) v.push_back(floorRadiance(img, cam, r, 2 * kPi * k / 48));
  if (!median) return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

TEST_CASE("the refraction caustic appears under the glass sphere, brighter than direct light, with both estimators") {
  Scene scene = causticScene(0.0f);
  const Camera& cam = scene.cameras[0];
  const int n = 64;
  for (Integrator integ : {Integrator::Naive, Integrator::Mis}) {
    RenderResult r = renderScene(scene, cam, smallSettings(n, n, integ), 256);
    // Focus: the floor straight under the sphere (the ball lens images the small light there).
    // Shadow: the outer ring of the sphere's shadow (radius about 0.4), past the spread of the
    // focused light: converged (naive 4096 spp, mis 1024 spp) it is 0.3 x the lit floor; the ring
    // nearer the focus (0.18-0.26) is 0.7 x, lit by the lens. Lit: open floor.
    double focus = 0;
    glm::ivec2 c = project(cam, glm::vec3(0.0f), n);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        for (int ch = 0; ch < 3; ++ch) focus += r.image.at(c.x + dx, c.y + dy, ch) / 27.0;
    double shadow = floorAnnulus(r.image, cam, 0.26f, 0.34f, true);
    double lit = floorAnnulus(r.image, cam, 0.6f, 0.9f, false);
    INFO(std::string(integratorName(integ)), ": focus ", focus, " shadow ", shadow, " lit ", lit);
    CHECK(lit > 0.02);
    CHECK(focus > 5.0 * lit);
    CHECK(shadow < 0.5 * lit);
    CHECK(r.stats.nonFinite == 0);
  }
}

TEST_CASE("mis aiming at the glass ball (caustic casters) matches naive and finds the caustic with less noise") {
  Scene scene = causticScene(0.0f);
  const Camera& cam = scene.cameras[0];
  const int n = 32, block = 4, renders = 8;
  std::uint64_t nonFinite = 0;
  std::vector<std::string> aimedDefines, plainDefines;
  BlockStats naive = blockStats(scene, cam, Integrator::Naive, n, n, block, 256, renders, 300, &nonFinite, 32);
  BlockStats aimed =
      blockStats(scene, cam, Integrator::Mis, n, n, block, 64, renders, 400, &nonFinite, 32, 0.5f, &aimedDefines);
  BlockStats plain =
      blockStats(scene, cam, Integrator::Mis, n, n, block, 64, renders, 500, &nonFinite, 32, 0.0f, &plainDefines);
  REQUIRE(hasDefine(aimedDefines, "CAUSTICA_CASTERS"));
  REQUIRE_FALSE(hasDefine(plainDefines, "CAUSTICA_CASTERS"));
  checkBlocksAgree("caustic scene, naive against mis with casters", naive, aimed);
  checkBlocksAgree("caustic scene, mis without casters against mis with casters", plain, aimed);
  CHECK(nonFinite == 0);
  // The focus under the ball and the blocks around it (3x3 blocks of 4x4 pixels): same samples per
  // pixel, so the variance of the mean compares per sample.
  glm::ivec2 c = project(cam, glm::vec3(0.0f), n) / block;
  double varAimed = 0, varPlain = 0;
  for (int by = c.y - 1; by <= c.y + 1; ++by)
    for (int bx = c.x - 1; bx <= c.x + 1; ++bx)
      for (int ch = 0; ch < 3; ++ch) {
        size_t i = (static_cast<size_t>(by) * aimed.blocksX + bx) * 3 + ch;
        varAimed += aimed.var[i];
        varPlain += plain.var[i];
      }
  INFO("variance around the focus: with casters ", varAimed, ", without ", varPlain);
  CHECK(varAimed < 0.5 * varPlain);
}

namespace {

// Mean and variance of the mean of the blocks [bx0, bx1) x [by0, by1) of `s` (all channels).
std::pair<double, double> blockRegion(const BlockStats& s, int bx0, int by0, int bx1, int by1) {
  // The variance of the region's mean across the renders: a pixel's three channels come from the same
  // paths, so summing the channels' variances as if independent would understate it (up to 3x).
  const double n = 3.0 * (bx1 - bx0) * (by1 - by0);
  const auto renders = static_cast<double>(s.perRender.size());
  std::vector<double> per;
  for (const std::vector<double>& r : s.perRender) {
    double m = 0.0;
    for (int by = by0; by < by1; ++by)
      for (int bx = bx0; bx < bx1; ++bx)
        for (int ch = 0; ch < 3; ++ch) m += r[(static_cast<size_t>(by) * s.blocksX + bx) * 3 + ch] / n;
    per.push_back(m);
  }
  double m = 0.0, v = 0.0;
  for (double x : per) m += x / renders;
  for (double x : per) v += (x - m) * (x - m) / (renders - 1);
  return {m, v / renders};  // the variance of the mean
}

// Manifold NEE against naive and against mis without it (and without caster guiding: the estimator
// manifold NEE improves on) on `scene`: blocks, image and quadrants
// (checkBlocksAgree), and the caustic region [bx0, bx1) x [by0, by1) of blocks within 4.5 standard
// errors; naiveBlocks: naive's blocks too. Returns the three estimates' BlockStats (naive, mis, manifold).
std::array<BlockStats, 3> checkManifoldAgrees(const std::string& what, const Scene& scene, int w, int h, int block,
                                             int sppNaive, int sppMis, int bx0, int by0, int bx1, int by1,
                                             bool naiveBlocks = true) {
  const Camera& cam = scene.cameras[0];
  const int renders = 8;
  std::uint64_t nonFinite = 0;
  std::vector<std::string> misDefines, manifoldDefines;
  BlockStats naive = blockStats(scene, cam, Integrator::Naive, w, h, block, sppNaive, renders, 700, &nonFinite, 32);
  BlockStats mis = blockStats(scene, cam, Integrator::Mis, w, h, block, sppMis, renders, 800, &nonFinite, 32, 0.5f,
                              &misDefines, ManifoldMode::Off, 0.0f);
  BlockStats manifold = blockStats(scene, cam, Integrator::Mis, w, h, block, sppMis, renders, 900, &nonFinite, 32, 0.5f,
                                   &manifoldDefines, ManifoldMode::On);
  REQUIRE_FALSE(hasDefine(misDefines, "CAUSTICA_MANIFOLD"));
  REQUIRE(hasDefine(manifoldDefines, "CAUSTICA_MANIFOLD"));
  checkBlocksAgree(what + ", naive against manifold NEE", naive, manifold, naiveBlocks);
  checkBlocksAgree(what + ", mis against manifold NEE", mis, manifold);
  CHECK(nonFinite == 0);
  const auto [mm, vm] = blockRegion(manifold, bx0, by0, bx1, by1);
  for (const BlockStats* other : {&naive, &mis}) {
    const auto [mo, vo] = blockRegion(*other, bx0, by0, bx1, by1);
    const std::string name = other == &naive ? "naive " : "mis ";
    const double se = std::sqrt(vm + vo);
    INFO(what, ", caustic region: ", name, mo, " manifold ", mm,
         ", standard error of the difference ", se, " (", 100.0 * se / mm, " % of the mean)");
    CHECK(std::abs(mo - mm) <= 4.5 * se);
    MESSAGE(what, ", caustic region, ", name, mo, " manifold ", mm,
            ": the smallest bias this run detects ", 100.0 * 4.5 * se / mm, " %");
  }
  return {naive, mis, manifold};
}

}  // namespace

TEST_CASE("manifold NEE matches naive and mis: glass ball caustic") {
  Scene scene = causticScene(0.0f);
  const int n = 32, block = 4;
  glm::ivec2 c = project(scene.cameras[0], glm::vec3(0.0f), n) / block;  // the focus under the ball
  const int f = longTests() ? 4 : 1;
  auto st = checkManifoldAgrees("glass ball", scene, n, n, block, 256 * f, 64 * f, c.x - 1, c.y - 1, c.x + 2, c.y + 2);
  // Same samples per pixel: the variance of the caustic region's mean compares per sample.
  const double vMis = blockRegion(st[1], c.x - 1, c.y - 1, c.x + 2, c.y + 2).second;
  const double vManifold = blockRegion(st[2], c.x - 1, c.y - 1, c.x + 2, c.y + 2).second;
  INFO("variance of the caustic region's mean: mis ", vMis, ", manifold ", vManifold);
  CHECK(vManifold < 0.5 * vMis);
}

TEST_CASE("manifold NEE matches naive and mis: mirror-caustic") {
  Scene scene = loadScene(sourcePath("assets/scenes/mirror-caustic.gltf"));
  scene.cameras = {sceneCamera(scene)};
  const int f = longTests() ? 4 : 1;
  // bench/scenes.json's caustic region [0.30, 0.50, 0.70, 0.85] in blocks of 4 of a 40 x 40 image.
  // Naive reaches the small lamp in too few samples per block (some blocks none: no variance to test
  // against); it is compared on the image, its quadrants and the caustic region.
  checkManifoldAgrees("mirror-caustic", scene, 40, 40, 4, 128 * f, 32 * f, 3, 5, 7, 8, false);
}

TEST_CASE("manifold auto: the off variant bit for bit where no caster qualifies or light tracing runs, the on one where all do without it") {
  // cornell-glass: a large lamp over both spheres (docs/path-tracer.md): no caster qualifies, the same
  // shader and the same bits as --manifold off. lamp-caustics: both casters under a 4-cm lamp qualify, so
  // with --light-tracing off the photon pass fills the same cells as under --manifold on: the same bits as
  // on. With light tracing (the default) auto leaves manifold NEE off wherever light tracing compiles.
  for (const auto& [name, same] : {std::pair<const char*, ManifoldMode>{"cornell-glass", ManifoldMode::Off},
                                   std::pair<const char*, ManifoldMode>{"lamp-caustics", ManifoldMode::On}}) {
    CAPTURE(name);
    Scene scene = loadScene(sourcePath(std::string("assets/scenes/") + name + ".gltf"));
    const Camera cam = sceneCamera(scene);
    RenderSettings autoSettings = smallSettings(24, 24);
    REQUIRE(autoSettings.manifold == ManifoldMode::Auto);  // the default
    REQUIRE(autoSettings.lightTracing);                    // the default
    RenderSettings offLt = autoSettings;
    offLt.manifold = ManifoldMode::Off;
    RenderResult lt = renderScene(scene, cam, autoSettings, 4), ltOff = renderScene(scene, cam, offLt, 4);
    CHECK(lt.defines == ltOff.defines);
    CHECK(hasDefine(lt.defines, "CAUSTICA_LIGHT_TRACE"));
    CHECK(lt.image.rgb == ltOff.image.rgb);
    autoSettings.lightTracing = false;
    RenderSettings other = autoSettings;
    other.manifold = same;
    RenderResult a = renderScene(scene, cam, autoSettings, 4), b = renderScene(scene, cam, other, 4);
    CHECK(a.defines == b.defines);
    CHECK(hasDefine(a.defines, "CAUSTICA_MANIFOLD") == (same == ManifoldMode::On));
    CHECK(a.image.rgb == b.image.rgb);
    RenderSettings off = autoSettings;
    off.manifold = ManifoldMode::Off;
    if (same == ManifoldMode::On) CHECK_FALSE(renderScene(scene, cam, off, 4).image.rgb == a.image.rgb);
  }
}

TEST_CASE("manifold auto: through the qualifying casters only, it matches mis without manifold NEE") {
  // A glass ball far under a 16-cm lamp (0.007 sr from its centre: qualifies) and a mirror ball close
  // beside the lamp (0.04 sr: does not): auto sends photons through the glass ball only, and the
  // bounce through the mirror keeps weight 1 (no cells of its caster). Any mismatch between the two
  // MIS sides (a weight for paths manifold NEE cannot make through the mirror) shows as a bias.
  const Scene s = lampOverGlassAndMirror();
  const GpuScene g = packScene(s, buildBvh(s.triangles));
  REQUIRE(g.casters.size() == 2);
  CHECK(manifoldCasterMask(ManifoldMode::Auto, g) != 0u);
  CHECK(manifoldCasterMask(ManifoldMode::Auto, g) != manifoldCasterMask(ManifoldMode::On, g));
  const int n = 32, block = 4, renders = 8, f = longTests() ? 4 : 1;
  std::uint64_t nonFinite = 0;
  std::vector<std::string> offDefines, autoDefines;
  BlockStats off = blockStats(s, s.cameras[0], Integrator::Mis, n, n, block, 64 * f, renders, 800, &nonFinite, 32, 0.5f,
                              &offDefines, ManifoldMode::Off);
  BlockStats autoStats = blockStats(s, s.cameras[0], Integrator::Mis, n, n, block, 64 * f, renders, 900, &nonFinite, 32,
                                    0.5f, &autoDefines, ManifoldMode::Auto);
  REQUIRE(hasDefine(autoDefines, "CAUSTICA_MANIFOLD"));
  REQUIRE_FALSE(hasDefine(offDefines, "CAUSTICA_MANIFOLD"));
  checkBlocksAgree("glass and mirror balls, auto against off", off, autoStats);
  CHECK(nonFinite == 0);
}

namespace {

// Per-pixel grey level (mean of the channels) of `renders` independent renders (seeds seedBase,
// seedBase + 1, ...) of 16 x 16 pixels: the mean of the renders and the variance of that mean. Pixels
// are independent, so a region's variance is the sum of its pixels' over n^2: an estimate with
// (renders - 1) x pixels degrees of freedom (768 for the whole image), whose k-sigma tolerance is
// close to the normal distribution's.
struct PixelStats {
  int w = 0, h = 0;
  std::vector<double> mean, var;
  std::vector<std::string> defines;  // the shader variant of the renders
};

PixelStats pixelStats(const Scene& scene, const Camera& cam, RenderSettings settings, int spp, int renders,
                      std::uint32_t seedBase, std::uint64_t* nonFinite) {
  PixelStats p;
  p.w = p.h = settings.width = settings.height = 16;
  const size_t n = static_cast<size_t>(p.w) * p.h;
  std::vector<std::vector<double>> per(renders, std::vector<double>(n));
  for (int r = 0; r < renders; ++r) {
    settings.seed = seedBase + static_cast<std::uint32_t>(r);
    RenderResult res = renderScene(scene, cam, settings, spp, 64);
    *nonFinite += res.stats.nonFinite;
    p.defines = res.defines;
    for (int y = 0; y < p.h; ++y)
      for (int x = 0; x < p.w; ++x)
        per[r][static_cast<size_t>(y) * p.w + x] = (res.image.at(x, y, 0) + res.image.at(x, y, 1) + res.image.at(x, y, 2)) / 3.0;
  }
  p.mean.assign(n, 0.0);
  p.var.assign(n, 0.0);
  for (size_t i = 0; i < n; ++i) {
    for (int r = 0; r < renders; ++r) p.mean[i] += per[r][i] / renders;
    for (int r = 0; r < renders; ++r) p.var[i] += (per[r][i] - p.mean[i]) * (per[r][i] - p.mean[i]) / (renders - 1);
    p.var[i] /= renders;  // variance of the mean
  }
  return p;
}

// Mean and variance of the mean of the pixels [x0, x1) x [y0, y1) of `p`.
std::pair<double, double> pixelRegion(const PixelStats& p, int x0, int y0, int x1, int y1) {
  double m = 0.0, v = 0.0;
  const double n = static_cast<double>(x1 - x0) * (y1 - y0);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      m += p.mean[static_cast<size_t>(y) * p.w + x] / n;
      v += p.var[static_cast<size_t>(y) * p.w + x] / (n * n);
    }
  return {m, v};
}

// A pinhole camera at cam's position that sees the part [x0, x1] x [y0, y1] (normalized coordinates
// of cam's square image, y down) of cam's view in a square image: the larger side of the box fills it.
// A caustic region rendered on its own gets every sample of a render.
Camera cropCamera(const Camera& cam, double x0, double y0, double x1, double y1) {
  const glm::vec3 f = glm::normalize(cam.forward), r = glm::normalize(glm::cross(f, cam.up)), u = glm::cross(r, f);
  const float t = std::tan(0.5f * cam.yfov);
  const float cx = static_cast<float>(x0 + x1) - 1.0f, cy = 1.0f - static_cast<float>(y0 + y1);
  Camera c = cam;
  c.forward = glm::normalize(f + cx * t * r + cy * t * u);
  c.up = glm::normalize(glm::cross(glm::cross(c.forward, u), c.forward));
  c.yfov = 2.0f * std::atan(t * static_cast<float>(std::max(x1 - x0, y1 - y0)));
  c.aspect = 0.0f;
  return c;
}

// The number of standard errors of the difference two estimates may differ by in the manifold NEE
// unbiasedness tests. The standard errors come from hundreds of degrees of freedom (pixelStats), so
// the false-failure rate per comparison is near the normal distribution's 7e-6.
constexpr double kManifoldSigmas = 4.5;

// One view of a manifold NEE unbiasedness case, rendered with each estimator at 16 x 16 pixels, 4
// independent renders each: the scene's image or its caustic region alone (cropCamera).
struct ManifoldView {
  std::string name;
  Camera camera;
  int sppNaive, sppMis, sppManifold;  // per render; 0: leave naive out (a lamp it finds too rarely)
  // Whether this view's mean against mis must resolve a 0.5 % bias (asserted: kManifoldSigmas standard
  // errors of the difference <= 0.5 % of the mean).
  bool sharp = false;
};

// What a sharp view must resolve (kManifoldSigmas standard errors of the difference, % of the mean): a
// 0.5 % bias then sits at 4.5 x 0.5 / 0.35 = 6.4 standard errors and fails the 4.5-sigma check in about
// 97 % of runs (asserting 0.5 % itself would fail it in only half of them).
constexpr double kSharpResolution = 0.35;

// One estimator of an unbiasedness comparison: its name, settings and samples per render (0: left out).
struct EstimatorRun {
  std::string name;
  RenderSettings settings;
  int spp = 0;
  std::uint32_t seedBase = 0;
};

// The tested estimator against each of `others` over a view and its four quadrants: each difference
// within kManifoldSigmas standard errors. Prints, per comparison, the smallest bias of the view's mean
// the run resolves (kManifoldSigmas standard errors of the difference, relative to the mean) and the
// largest over its quadrants; asserts the mean's against the first of `others` <= kSharpResolution
// for a sharp view. CAUSTICA_LONG_TESTS=1 takes longFactor times the samples. Returns the renders' shader
// variants (tested first).
std::vector<std::vector<std::string>> checkViewAgrees(const std::string& what, const Scene& scene, const ManifoldView& view,
                                                      const EstimatorRun& tested, const std::vector<EstimatorRun>& others,
                                                      int longFactor = 4) {
  const int f = longTests() ? longFactor : 1, renders = 4;
  std::uint64_t nonFinite = 0;
  const PixelStats t = pixelStats(scene, view.camera, tested.settings, tested.spp * f, renders, tested.seedBase, &nonFinite);
  std::vector<std::vector<std::string>> variants{t.defines};
  std::vector<std::pair<std::string, PixelStats>> stats;
  for (const EstimatorRun& o : others) {
    if (o.spp <= 0) continue;
    stats.emplace_back(o.name, pixelStats(scene, view.camera, o.settings, o.spp * f, renders, o.seedBase, &nonFinite));
    variants.push_back(stats.back().second.defines);
  }
  CHECK(nonFinite == 0);
  static const char* kQuadrant[] = {"", " top left", " top right", " bottom left", " bottom right"};
  for (size_t k = 0; k < stats.size(); ++k) {
    const auto& [name, other] = stats[k];
    double worstQuadrant = 0.0;
    for (int q = 0; q < 5; ++q) {
      const int x0 = q == 0 ? 0 : (q - 1) % 2 * 8, y0 = q == 0 ? 0 : (q - 1) / 2 * 8, side = q == 0 ? 16 : 8;
      const auto [mm, vm] = pixelRegion(t, x0, y0, x0 + side, y0 + side);
      const auto [mo, vo] = pixelRegion(other, x0, y0, x0 + side, y0 + side);
      const double se = std::sqrt(vm + vo), resolves = 100.0 * kManifoldSigmas * se / mo;
      INFO(what, ", ", view.name, std::string(kQuadrant[q]), ": ", tested.name, " ", mm, ", ", name, " ", mo,
           ", difference ", 100.0 * (mm - mo) / mo, " % = ", (mm - mo) / se, " standard errors (one: ", 100.0 * se / mo, " %)");
      CHECK(mo > 0.0);
      CHECK(std::abs(mm - mo) <= kManifoldSigmas * se);
      if (q > 0) worstQuadrant = std::max(worstQuadrant, resolves);
      if (q == 0) {
        MESSAGE(what, ", ", view.name, ", ", tested.name, " ", mm, " against ", name, " ", mo, ": difference ",
                100.0 * (mm - mo) / mo, " % (", (mm - mo) / se, " standard errors); resolves a bias of ", resolves, " %");
        if (k == 0 && view.sharp) CHECK(resolves <= kSharpResolution);
      }
    }
    MESSAGE(what, ", ", view.name, " quadrants against ", name, ": resolve a bias of ", worstQuadrant, " % or less");
  }
  return variants;
}

// The settings every estimator test below starts from: 16 x 16 pixels, mis, depth 32, `dispersion`.
RenderSettings estimatorTestSettings(DispersionMode dispersion) {
  RenderSettings s = smallSettings(16, 16, Integrator::Mis);
  s.dispersion = dispersion;
  s.maxDepth = 32;
  return s;
}

// An estimator added to mis (manifold NEE, caster guiding, light tracing: `with`, which compiles `define`)
// against mis without it (`without`, which does not) and against naive from `base` (checkViewAgrees;
// seeds seedBase, +1000 and +2000; `with` takes the view's sppManifold, `without` its sppMis).
void checkEstimatorUnbiased(const std::string& what, const Scene& scene, const ManifoldView& view, const char* define,
                            const RenderSettings& base, const EstimatorRun& with, const EstimatorRun& without,
                            std::uint32_t seedBase, int longFactor) {
  RenderSettings naive = base;
  naive.integrator = Integrator::Naive;
  const auto variants = checkViewAgrees(what, scene, view, {with.name, with.settings, view.sppManifold, seedBase},
                                        {{without.name, without.settings, view.sppMis, seedBase + 1000},
                                         {"naive", naive, view.sppNaive, seedBase + 2000}},
                                        longFactor);
  REQUIRE(hasDefine(variants[0], define));
  REQUIRE_FALSE(hasDefine(variants[1], define));
}

// Manifold NEE against mis without it and against naive.
void checkManifoldUnbiased(const std::string& what, const Scene& scene, const ManifoldView& view,
                           DispersionMode dispersion = DispersionMode::Rgb, int longFactor = 4) {
  RenderSettings settings = estimatorTestSettings(dispersion);
  settings.lightTracing = false;  // the eye-path estimators manifold NEE is one of
  RenderSettings on = settings, off = settings;
  on.manifold = ManifoldMode::On;
  off.manifold = ManifoldMode::Off;
  checkEstimatorUnbiased(what, scene, view, "CAUSTICA_MANIFOLD", settings, {"manifold", on}, {"mis", off}, 5000, longFactor);
}

// causticScene's focus: the part of its 64 x 64 image within `r` (normalized) of the floor under the ball.
Camera causticFocusCamera(const Scene& scene, double r) {
  const glm::ivec2 c = project(scene.cameras[0], glm::vec3(0.0f), 64);
  return cropCamera(scene.cameras[0], c.x / 64.0 - r, c.y / 64.0 - r, c.x / 64.0 + r, c.y / 64.0 + r);
}

// bench/scenes.json's caustic region of a bundled scene, seen by a crop of its camera.
ManifoldView causticRegion(const Scene& scene, double x0, double y0, double x1, double y1, int sppNaive, int sppMis,
                           int sppManifold) {
  return {"caustic region", cropCamera(sceneCamera(scene), x0, y0, x1, y1), sppNaive, sppMis, sppManifold};
}

}  // namespace

// Unbiasedness of manifold NEE at the resolution issue 33 asks for: a 0.5 % bias of the caustic
// region's mean and of the image mean fails (asserted: the printed resolution <= kSharpResolution). The time goes
// where each estimate is noisier: samples per estimator in proportion to (its standard error per
// sample) x (its seconds per sample), the split that minimises the total time for a given standard
// error of the difference.
//
// The glass ball under a 60 cm lamp seen only at its focus (the floor within 1 % of the image width
// of the point under the ball): mis converges there (its reference is not fireflies), and manifold NEE
// carries 58 % of the focus's mean (measured: with its contribution zeroed the focus drops from 1.785
// to 0.745). Measured: resolves 0.29 % against mis (0.87 % against naive); at half these samples scaling
// manifold NEE's contribution by 1.0086 (a 0.5 % bias of the focus's mean) failed it at 6.9 standard errors.
TEST_CASE("manifold NEE is unbiased: glass ball focus") {
  Scene scene = causticScene(0.0f, 0.3f);
  ManifoldView focus{"caustic region (focus)", causticFocusCamera(scene, 0.01), 2048, 16384, 3072, true};
  checkManifoldUnbiased("glass ball, 60 cm lamp", scene, focus);
}

// mirror-caustic's image and bench/scenes.json's caustic region, where manifold NEE carries 8 % and
// 16 % of the mean (the rest is direct and indirect light). Measured: resolves 0.30 % (image) and
// 0.32 % (caustic region) against mis. At 4/7 of these samples, with manifold NEE's whole estimate
// scaled by 0.995 the means failed at -7.0 and -7.8 standard errors; scaled by 1.005, quadrants at
// 4.6-5.1 (the means, which those seeds put 0.15-0.20 % below mis, at 3.9 and 3.3; other seeds put them +0.09 % and -0.005 %).
TEST_CASE("manifold NEE is unbiased: mirror-caustic") {
  Scene scene = loadScene(sourcePath("assets/scenes/mirror-caustic.gltf"));
  checkManifoldUnbiased("mirror-caustic", scene, {"image", sceneCamera(scene), 2048, 57344, 2464, true});
  ManifoldView region = causticRegion(scene, 0.30, 0.50, 0.70, 0.85, 2048, 57344, 2240);
  region.sharp = true;
  checkManifoldUnbiased("mirror-caustic", scene, region);
}

// The other scenes at what a few seconds each resolve (printed; CAUSTICA_LONG_TESTS=1 takes 4x). The
// glass ball's whole image is "manifold NEE matches naive and mis: glass ball caustic"'s.
TEST_CASE("manifold NEE is unbiased: lamp-caustics") {
  Scene scene = loadScene(sourcePath("assets/scenes/lamp-caustics.gltf"));
  checkManifoldUnbiased("lamp-caustics", scene, {"image", sceneCamera(scene), 1024, 1024, 256});
  checkManifoldUnbiased("lamp-caustics", scene, causticRegion(scene, 0.30, 0.52, 0.68, 0.82, 0, 1024, 256));
}

TEST_CASE("manifold NEE is unbiased: cornell-glass and cornell-dispersion") {
  Scene glass = loadScene(sourcePath("assets/scenes/cornell-glass.gltf"));
  checkManifoldUnbiased("cornell-glass", glass, causticRegion(glass, 0.14, 0.86, 0.44, 0.96, 1024, 1024, 256));
  Scene disp = loadScene(sourcePath("assets/scenes/cornell-dispersion.gltf"));
  checkManifoldUnbiased("cornell-dispersion", disp, causticRegion(disp, 0.30, 0.81, 0.65, 0.94, 1024, 1024, 256));
}

// Dispersion: manifold NEE joins each sample's wavelength (spectral) or colour channel (rgb) through a
// ball whose index depends on it; its rainbow-fringed focus against mis and naive in both modes.
TEST_CASE("manifold NEE is unbiased: dispersion, rgb and spectral") {
  Scene scene = causticScene(1.0f, 0.3f);
  ManifoldView focus{"caustic region (dispersed focus)", causticFocusCamera(scene, 0.03), 512, 1024, 256};
  checkManifoldUnbiased("dispersive glass ball, rgb", scene, focus, DispersionMode::Rgb);
  checkManifoldUnbiased("dispersive glass ball, spectral", scene, focus, DispersionMode::Spectral);
}

namespace {

// causticScene kept as meshes and instances: the floor, the lamp and the ball (a unit sphere placed
// by a rotated, scaled instance).
Scene instancedCausticScene() {
  Scene s;
  s.path = "instanced-caustic";
  s.materials = {diffuseMaterial(0.8f), emitterMaterial(18.0f), glassMaterial(1.5f)};
  const auto mesh = [&](auto add) { s.instances.push_back({addMesh(s, add), glm::dmat4(1.0)}); };
  const float h = 0.3f;
  mesh([&] { addQuad(s, {-1.5f, 0, 1.5f}, {1.5f, 0, 1.5f}, {1.5f, 0, -1.5f}, {-1.5f, 0, -1.5f}, 0); });
  mesh([&] { addQuad(s, {-h, 2.5f, -h}, {h, 2.5f, -h}, {h, 2.5f, h}, {-h, 2.5f, h}, 1); });
  mesh([&] { addSphere(s, glm::vec3(0.0f), 1.0f, 24, 2); });
  s.instances.back().world = glm::scale(glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 0.62, 0.0)),
                                                    0.7, glm::dvec3(0.3, 1.0, 0.2)),
                                        glm::dvec3(0.3));
  finishInstancedBounds(s);
  s.cameras.push_back(lookAt({0.0f, 1.4f, 1.9f}, {0.0f, 0.0f, 0.0f}, 0.9f));
  return s;
}

}  // namespace

// Instanced scenes: manifold NEE in the instanced scene against its flattened copy with the same seeds
// (the same paths up to rounding: measured 1.2e-5 apart, so a 0.1 % bias of the instanced path fails),
// and against mis in the instanced scene.
TEST_CASE("manifold NEE is unbiased: instanced caster") {
  const Scene inst = instancedCausticScene();
  Scene flat = inst;
  flattenInstances(flat);
  const Camera focus = causticFocusCamera(inst, 0.03);
  RenderSettings settings = smallSettings(16, 16, Integrator::Mis, 3);
  settings.manifold = ManifoldMode::On;
  const RenderResult a = renderScene(inst, focus, settings, 256, 64);
  const RenderResult b = renderScene(flat, focus, settings, 256, 64);
  REQUIRE(hasDefine(a.defines, "CAUSTICA_INSTANCED"));
  REQUIRE_FALSE(hasDefine(b.defines, "CAUSTICA_INSTANCED"));
  REQUIRE(hasDefine(a.defines, "CAUSTICA_MANIFOLD"));
  const std::array<double, 5> qa = quadrantMeans(a.image), qb = quadrantMeans(b.image);
  for (int q = 0; q < 5; ++q) {
    INFO("region ", q, " (image, then quadrants): instanced ", qa[q], ", flattened ", qb[q]);
    CHECK(qa[q] == Rel(qb[q], 0.001));
  }
  MESSAGE("instanced caster, focus: instanced ", qa[0], " flattened ", qb[0], ": differ by ",
          100.0 * (qa[0] - qb[0]) / qb[0], " %");
  checkManifoldUnbiased("instanced glass ball", inst, {"caustic region (focus)", focus, 0, 512, 128});
}

namespace {

// Caster guiding (--guide-probability, glsl/lib/casters.glsl) against the same estimator without it
// and against naive; manifold NEE as `manifold` says in both.
void checkGuidingUnbiased(const std::string& what, const Scene& scene, const ManifoldView& view, ManifoldMode manifold,
                          DispersionMode dispersion = DispersionMode::Rgb) {
  RenderSettings settings = estimatorTestSettings(dispersion);
  settings.manifold = manifold;
  settings.lightTracing = false;  // the eye-path estimators guiding is part of
  RenderSettings guided = settings, unguided = settings;
  guided.guideProbability = 0.5f;
  unguided.guideProbability = 0.0f;
  checkEstimatorUnbiased(what, scene, view, "CAUSTICA_GUIDING", settings, {"guided", guided}, {"unguided", unguided}, 8000, 4);
}

}  // namespace

// Unbiasedness of caster guiding where its lobes carry the caustic: the glass ball's focus under a
// 20 cm lamp (0.011 sr from the ball: guiding applies, guideCasterMask; without manifold NEE) and
// mirror-caustic's caustic region (with it, as auto chooses there: the guided bounce is the other side
// of manifold NEE's MIS weight), each asserted to resolve a 0.5 % bias of the mean against the unguided
// estimator (ManifoldView::sharp); the rest printed.
TEST_CASE("caster guiding is unbiased: glass ball focus and mirror-caustic") {
  Scene ball = causticScene(0.0f, 0.1f);
  checkGuidingUnbiased("glass ball, 20 cm lamp", ball,
                       {"caustic region (focus)", causticFocusCamera(ball, 0.01), 2048, 20480, 20480, true}, ManifoldMode::Off);
  Scene mirror = loadScene(sourcePath("assets/scenes/mirror-caustic.gltf"));
  ManifoldView region = causticRegion(mirror, 0.30, 0.50, 0.70, 0.85, 1024, 2048, 2048);
  region.sharp = true;
  checkGuidingUnbiased("mirror-caustic", mirror, region, ManifoldMode::On);
}

// The other caustic scenes where guiding applies, at what a few seconds each resolve (printed); and
// where it does not (cornell-glass's 0.064 sr lamp), the same shader variant and bits as without it.
TEST_CASE("caster guiding is unbiased: cornell-glass, lamp-caustics, dispersion") {
  Scene glass = loadScene(sourcePath("assets/scenes/cornell-glass.gltf"));
  RenderSettings on = smallSettings(16, 16, Integrator::Mis), off = on;
  off.guideProbability = 0.0f;
  const RenderResult a = renderScene(glass, sceneCamera(glass), on, 4), b = renderScene(glass, sceneCamera(glass), off, 4);
  CHECK_FALSE(hasDefine(a.defines, "CAUSTICA_GUIDING"));
  CHECK(a.image.rgb == b.image.rgb);
  Scene lamp = loadScene(sourcePath("assets/scenes/lamp-caustics.gltf"));
  checkGuidingUnbiased("lamp-caustics", lamp, causticRegion(lamp, 0.30, 0.52, 0.68, 0.82, 0, 512, 512), ManifoldMode::On);
  Scene disp = causticScene(1.0f, 0.1f);
  checkGuidingUnbiased("dispersive glass ball, spectral", disp,
                       {"caustic region (dispersed focus)", causticFocusCamera(disp, 0.03), 512, 1024, 1024}, ManifoldMode::Off,
                       DispersionMode::Spectral);
}

namespace {
// Light tracing (glsl/light_trace.comp) against mis without it and against naive, with manifold NEE off in
// all three (light tracing is not compiled beside it). lightPaths: its subpaths per pixel and sample (a crop
// of the image sees few of them).
void checkLightTracingUnbiased(const std::string& what, const Scene& scene, const ManifoldView& view, float lightPaths,
                               DispersionMode dispersion = DispersionMode::Rgb, int longFactor = 4) {
  RenderSettings settings = estimatorTestSettings(dispersion);
  settings.manifold = ManifoldMode::Off;
  RenderSettings on = settings, off = settings;
  on.lightTracing = true;
  on.lightPaths = lightPaths;
  off.lightTracing = false;
  checkEstimatorUnbiased(what, scene, view, "CAUSTICA_LIGHT_TRACE", settings, {"light tracing", on}, {"mis", off}, 11000,
                         longFactor);
}
}  // namespace

// Unbiasedness of light tracing at the resolution issue 33 asks for, where the eye paths converge too: the
// glass ball under a 60 cm lamp seen at its focus (manifold NEE's sharp case). There the light tracer
// carries 99.8 % of the mean (its splats zeroed, the focus drops from 1.784 to 0.0031), so a 0.5 % bias
// of its splats is one of the mean. Measured: resolves 0.27 % against mis (difference -0.06 %; at 4x the
// samples -0.03 % resolving 0.16 %). Its splats scaled by 1.005 moved the difference by +0.50 % with the
// same random numbers (measured at 2048 / 16 paths per pixel: +0.32 %, 4.4 standard errors; here that is
// +0.44 %, 7.4 standard errors: fails). The crop sees few subpaths, hence 64 per pixel.
TEST_CASE("light tracing is unbiased: glass ball focus") {
  Scene scene = causticScene(0.0f, 0.3f);
  checkLightTracingUnbiased("glass ball, 60 cm lamp", scene,
                            {"caustic region (focus)", causticFocusCamera(scene, 0.01), 2048, 16384, 1536, true}, 64.0f);
}

// cornell-glass, where it is the default: its caustic region and image, at what a few seconds resolve
// (printed; the eye paths are the noisy side here).
TEST_CASE("light tracing is unbiased: cornell-glass") {
  Scene glass = loadScene(sourcePath("assets/scenes/cornell-glass.gltf"));
  checkLightTracingUnbiased("cornell-glass", glass, causticRegion(glass, 0.14, 0.86, 0.44, 0.96, 1024, 4096, 512), 2.0f);
  checkLightTracingUnbiased("cornell-glass", glass, {"image", sceneCamera(glass), 1024, 4096, 512}, 0.125f);
}

// Dispersion (each subpath picks its channel or hero wavelength at its first dispersive event, as an eye
// path does), an instanced caster, and an orthographic camera (its importance 1/A, its connections
// parallel to the view).
TEST_CASE("light tracing is unbiased: dispersion, instances, orthographic camera") {
  Scene disp = causticScene(1.0f, 0.3f);
  const ManifoldView dispersed{"caustic region (dispersed focus)", causticFocusCamera(disp, 0.03), 0, 4096, 1024};
  checkLightTracingUnbiased("dispersive glass ball, rgb", disp, dispersed, 4.0f, DispersionMode::Rgb);
  checkLightTracingUnbiased("dispersive glass ball, spectral", disp, dispersed, 4.0f, DispersionMode::Spectral);
  const Scene inst = instancedCausticScene();
  checkLightTracingUnbiased("instanced glass ball", inst, {"caustic region (focus)", causticFocusCamera(inst, 0.03), 0, 4096, 1024},
                            4.0f);
  Scene ortho = causticScene(0.0f, 0.3f);
  Camera top = ortho.cameras[0];
  top.orthoHeight = 0.5f;
  checkLightTracingUnbiased("glass ball, orthographic camera", ortho, {"image", top, 0, 4096, 1024}, 1.0f);
}

// mirror-caustic, where light tracing is the default and eye paths still aim at the mirror from the
// vertices outside its family: the standing mirror (crop), whose reflection of the floor holds the
// caustic the eye paths carry (E S D S L: with aiming off there, 17x the image's relMSE), and the floor
// patch the mirror lights (bench/scenes.json's caustic region, the light tracer's). Each resolves a 0.5 %
// bias of its mean against mis (measured: the mirror 0.27 %, the patch 0.21 %).
TEST_CASE("light tracing is unbiased: mirror-caustic, caster aiming beside it") {
  Scene mirror = loadScene(sourcePath("assets/scenes/mirror-caustic.gltf"));
  const RenderResult byDefault = renderScene(mirror, sceneCamera(mirror), smallSettings(8, 8), 1);
  REQUIRE(hasDefine(byDefault.defines, "CAUSTICA_LIGHT_TRACE"));
  REQUIRE(hasDefine(byDefault.defines, "CAUSTICA_CASTERS"));
  const ManifoldView standing{"the mirror", cropCamera(sceneCamera(mirror), 0.66, 0.38, 0.83, 0.66), 0, 6144, 3072, true};
  checkLightTracingUnbiased("mirror-caustic", mirror, standing, 1.0f);
  ManifoldView patch = causticRegion(mirror, 0.30, 0.50, 0.70, 0.85, 0, 2048, 1024);
  patch.sharp = true;
  checkLightTracingUnbiased("mirror-caustic", mirror, patch, 1.0f);
}

// The other bundled scenes where it is the default: cornell-dispersion (a dispersive ball lens and prism;
// rgb, the default) and cornell-materials (coated, sheen and rough materials, whose vertices end the
// family, beside smooth glass), their caustic regions and images at what a few seconds resolve (printed).
TEST_CASE("light tracing is unbiased: cornell-dispersion and cornell-materials") {
  for (const char* name : {"cornell-dispersion", "cornell-materials"}) {
    Scene scene = loadScene(sourcePath(std::string("assets/scenes/") + name + ".gltf"));
    const bool disp = std::string(name) == "cornell-dispersion";
    const ManifoldView region = disp ? causticRegion(scene, 0.30, 0.81, 0.65, 0.94, 512, 1024, 256)
                                     : causticRegion(scene, 0.36, 0.86, 0.64, 0.97, 512, 1024, 256);
    checkLightTracingUnbiased(name, scene, region, 1.0f);
    checkLightTracingUnbiased(name, scene, {"image", sceneCamera(scene), 512, 1024, 256}, 0.125f);
  }
}

// The lamp embedded in a glass slab: light subpaths start inside glass and cross into the air, the one
// crossing an eye path makes the other way. Refraction scales radiance by 1 / eta^2 but not importance:
// scatterDelta's radiance factor kept would make the focus 2.25x too bright; the eye path's factor for
// that crossing made it 2.25x too dark (measured -55 %, 274 standard errors). Measured: +0.10 % (0.4 s.e.).
TEST_CASE("light tracing is unbiased: an emitter inside glass") {
  Scene scene = causticScene(0.0f, 0.3f);
  addBox(scene, {-0.45f, 2.4f, -0.45f}, {0.45f, 2.6f, 0.45f}, 2);
  finishBounds(scene);
  checkLightTracingUnbiased("glass ball under a lamp in a glass slab", scene,
                            {"caustic region (focus)", causticFocusCamera(scene, 0.03), 0, 4096, 1024}, 4.0f);
}

TEST_CASE("rgb and spectral dispersion agree in mean brightness, and spread the caustic into colours") {
  Scene scene = causticScene(1.0f);
  const int n = 48;
  RenderSettings rgb = smallSettings(n, n, Integrator::Mis);
  RenderSettings spectral = rgb;
  spectral.dispersion = DispersionMode::Spectral;
  RenderResult a = renderScene(scene, scene.cameras[0], rgb, 96);
  RenderResult b = renderScene(scene, scene.cameras[0], spectral, 96);
  for (int c = 0; c < 3; ++c) CHECK(meanOf(a.image, c) == doctest::Approx(meanOf(b.image, c)).epsilon(0.03));
  CHECK(a.stats.nonFinite == 0);
  CHECK(b.stats.nonFinite == 0);
  // Without dispersion the whole image is grey (white light, grey floor); with it, some pixels are
  // strongly coloured: the channels of the caustic separate.
  auto maxChroma = [](const Image& img) {
    double best = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        double r = img.at(x, y, 0), g = img.at(x, y, 1), bl = img.at(x, y, 2), m = (r + g + bl) / 3;
        if (m > 0.05) best = std::max(best, (std::max({r, g, bl}) - std::min({r, g, bl})) / m);
      }
    return best;
  };
  RenderResult plain = renderScene(causticScene(0.0f), scene.cameras[0], rgb, 96);
  INFO("chroma: plain ", maxChroma(plain.image), " rgb ", maxChroma(a.image), " spectral ", maxChroma(b.image));
  CHECK(maxChroma(a.image) > 2.0 * maxChroma(plain.image) + 0.2);
  CHECK(maxChroma(b.image) > 2.0 * maxChroma(plain.image) + 0.2);
}

namespace {

// An axis-aligned block of pixels [x0, x1) x [y0, y1).
struct Region {
  std::string name;
  int x0, y0, x1, y1;
};

// The whole image, its four quadrants and a 4 x 4 grid of blocks.
std::vector<Region> imageRegions(int w, int h) {
  std::vector<Region> r{{"whole image", 0, 0, w, h}};
  for (int qy = 0; qy < 2; ++qy)
    for (int qx = 0; qx < 2; ++qx)
      r.push_back({std::string("quadrant ") + (qy ? "bottom " : "top ") + (qx ? "right" : "left"), qx * w / 2,
                   qy * h / 2, (qx + 1) * w / 2, (qy + 1) * h / 2});
  for (int by = 0; by < 4; ++by)
    for (int bx = 0; bx < 4; ++bx)
      r.push_back({"block row " + std::to_string(by) + " column " + std::to_string(bx), bx * w / 4, by * h / 4,
                   (bx + 1) * w / 4, (by + 1) * h / 4});
  return r;
}

// Mean grey level (mean of the channels) of a region over two renders with independent seeds, and
// the variance of that mean. Pixels are independent, so the variance comes from the per-pixel
// differences of the two renders: Var((a + b) / 2) = E[(a - b)^2] / 4 per pixel, summed over the
// region / n^2. Two renders give an estimate with as many degrees of freedom as the region has pixels.
struct RegionEstimate {
  double mean = 0, var = 0;
};

std::vector<RegionEstimate> regionEstimates(const Image& a, const Image& b, const std::vector<Region>& regions) {
  std::vector<RegionEstimate> out;
  for (const Region& r : regions) {
    RegionEstimate e;
    double n = static_cast<double>(r.x1 - r.x0) * (r.y1 - r.y0);
    for (int y = r.y0; y < r.y1; ++y)
      for (int x = r.x0; x < r.x1; ++x) {
        double va = (a.at(x, y, 0) + a.at(x, y, 1) + a.at(x, y, 2)) / 3.0;
        double vb = (b.at(x, y, 0) + b.at(x, y, 1) + b.at(x, y, 2)) / 3.0;
        e.mean += (va + vb) / 2.0 / n;
        e.var += (va - vb) * (va - vb) / 4.0 / (n * n);
      }
    out.push_back(e);
  }
  return out;
}

// Renders a scene with naive and mis (two renders of half the samples each, independent seeds) at a
// depth limit of 2 and compares every region: the whole image, its quadrants and a 4 x 4 grid of
// blocks. Depth 2 keeps direct light (light sampling at the first vertex against the bounce that may
// hit the light), where light-sampling errors live, at a third of the full-depth cost per sample.
// The whole image and the quadrants must agree within kSigma standard errors; each block within 4,
// and one of the 16 may fall outside (small regions have skewed noise from rare hits: |z| up to 3.7
// seen in 192 clean block checks).
void checkRegionsAgree(const Scene& scene, const std::string& file, int sppNaive, int sppMis, std::uint32_t seedBase,
                       double kSigma, bool failsHalfPercent = false) {
  const double kSigmaBlock = 4.0;
  Camera cam = sceneCamera(scene);
  const int n = 32;
  std::uint64_t nonFinite = 0;
  auto render = [&](Integrator integ, std::uint32_t seed, int spp) {
    RenderSettings settings = smallSettings(n, n, integ, seed);
    settings.maxDepth = 2;
    RenderResult r = renderScene(scene, cam, settings, spp, 64);
    nonFinite += r.stats.nonFinite;
    return r.image;
  };
  std::vector<Region> regions = imageRegions(n, n);
  std::vector<RegionEstimate> naive = regionEstimates(render(Integrator::Naive, seedBase, sppNaive / 2),
                                                      render(Integrator::Naive, seedBase + 1, sppNaive / 2), regions);
  std::vector<RegionEstimate> mis = regionEstimates(render(Integrator::Mis, seedBase + 2, sppMis / 2),
                                                    render(Integrator::Mis, seedBase + 3, sppMis / 2), regions);
  int badBlocks = 0;
  std::string worstBlock;
  for (size_t i = 0; i < regions.size(); ++i) {
    double diff = mis[i].mean - naive[i].mean;
    double se = std::sqrt(naive[i].var + mis[i].var);
    std::string what = file + " " + regions[i].name + ": naive " + std::to_string(naive[i].mean) + ", mis " +
                       std::to_string(mis[i].mean) + ", difference " + std::to_string(100 * diff / naive[i].mean) +
                       " % = " + std::to_string(diff / se) + " standard errors";
    bool block = regions[i].name.rfind("block", 0) == 0;
    if (i == 0) MESSAGE(what, " (standard error ", 100 * se / naive[i].mean, " %)");
    if (i == 0 && failsHalfPercent) CHECK(kSigma * se <= 0.005 * naive[i].mean);  // a 0.5 % bias of the image fails
    bool ok = std::abs(diff) <= (block ? kSigmaBlock : kSigma) * se;
    if (block) {
      if (!ok) {
        ++badBlocks;
        worstBlock = what;
      }
    } else {
      INFO(what);
      CHECK(ok);
    }
  }
  INFO(badBlocks, " of 16 blocks differ by more than ", kSigmaBlock, " standard errors; e.g. ", worstBlock);
  CHECK(badBlocks <= 1);
  CHECK(nonFinite == 0);
}

void checkRegionsAgree(const std::string& file, int sppNaive, int sppMis, std::uint32_t seedBase, double kSigma) {
  checkRegionsAgree(loadScene(sourcePath(file)), file, sppNaive, sppMis, seedBase, kSigma);
}

}  // namespace

// 961 small lights over a floor with boxes (assets/scenes/many-lights.gltf): mis chooses lights with
// the light tree (app/accel/light_tree.h), whose probabilities depend on the shading point; the MIS
// weight at an emitter hit repeats that choice from the previous vertex. An error in either biases
// mis against naive. Depth 2 (direct light plus the bounce that competes with it in MIS).
// Measured noise (standard error of the difference / mean): whole image 0.14 %, quadrants 0.23-0.34 %;
// with 3.5 standard errors a 0.5 % bias of the whole image fails. Measured agreement: -0.07 %
// (z = -0.5). An MIS pdf 1.5x too large at emitter hits fails it (whole image -6.5 %, z = -25).
// Runtime on llvmpipe, 2 loaded cores: about 40 s.
TEST_CASE("naive and mis agree per region under many small lights (light tree)") {
  checkRegionsAgree("assets/scenes/many-lights.gltf", 32768, 8192, 800, 3.5);
}

// Lights made of many curved, tilted triangles, where every light-sampling shortcut that only holds
// for a flat, axis-aligned lamp shows. (A shadow ray started at the receiver's offset origin but
// aimed with the direction and length from the unmoved receiver ended behind the emitter and hit
// the sampled triangle itself: mis came out 2.5 % (tube) and 9.5 % (sheet) darker than naive over the
// whole image, 29 and 43 standard errors; both cases fail.)
//
// Measured noise (standard error of the mis - naive difference, relative to the region's mean):
// tube: whole image 0.09 %, top quadrants (around the lamp) 0.12-0.15 %, bottom quadrants 0.35-0.45 %,
// blocks 0.2-2.5 %. With 3.5 standard errors the tube case fails a bias of the whole image's mean
// from about 0.3 % and reliably (5.5 sigma) from 0.5 %, and of a top quadrant from about 0.5 %
// (reliably from 0.8 %). Checked by scaling mis by 0.995: the whole image then differs by -0.51 %
// (z = -5.7), the top-right quadrant by -0.62 % (z = -5.2), and the case fails. The sheet case has
// half the samples (whole image 0.22 %, quadrants 0.3-0.8 %) and a 4-sigma tolerance: it catches
// biases from about 0.9 % of the whole image; it covers double-sided emitters (the light point is
// moved off the side that faces the receiver). With its seeds its top-left quadrant sits at
// z = -3.3, a fluctuation: 16384 spp per estimator with other seeds agree to +0.12 % +- 0.21 %.
// Runtime on llvmpipe, 2 cores: about 30 s (tube) and 10 s (sheet).
TEST_CASE("naive and mis agree per region under a curved light: closed tube knot") {
  checkRegionsAgree("tests/data/scenes/tube-light.gltf", 12288, 9216, 600, 3.5);
}

TEST_CASE("naive and mis agree per region under a curved light: double-sided wavy sheet") {
  checkRegionsAgree("tests/data/scenes/sheet-light.gltf", 4096, 3072, 700, 4.0);
}

namespace {

// Directional albedo of GGX with F = 1 and height-correlated G2 at cos(theta_o) = cosO, by quadrature
// over microfacet normals distributed as D cos (independent of the shader and of the C++ sampler).
double ggxAlbedo(double cosO, double alpha) {
  auto lambda = [&](double c) { return (-1.0 + std::sqrt(1.0 + alpha * alpha * (1.0 - c * c) / (c * c))) / 2.0; };
  const int nXi = 1000, nPhi = 360;
  const double sinO = std::sqrt(std::max(0.0, 1.0 - cosO * cosO));
  double sum = 0;
  for (int a = 0; a < nXi; ++a) {
    double xi = (a + 0.5) / nXi, tan2 = alpha * alpha * xi / (1.0 - xi);
    double ch = 1.0 / std::sqrt(1.0 + tan2), sh = std::sqrt(tan2) * ch;
    for (int b = 0; b < nPhi; ++b) {
      double phi = 2 * kPiD * (b + 0.5) / nPhi;
      double oh = sinO * sh * std::cos(phi) + cosO * ch;
      double iz = 2 * oh * ch - cosO;
      if (oh <= 0 || iz <= 0) continue;
      sum += oh / (cosO * ch) / (1.0 + lambda(cosO) + lambda(iz));
    }
  }
  return sum / (double(nXi) * nPhi);
}

}  // namespace

// A flat rough metal with F0 = 1 (Schlick then gives F = 1 at every angle) inside a black sphere that
// emits radiance 1 everywhere: the camera looks straight at it through a narrow field of view
// (cos theta_o >= 0.9997), so every pixel sees exactly the GGX directional albedo E(1) of single
// scattering; 1 - E is the energy that multiple scattering between microfacets would return (not
// simulated; docs/materials.md lists E). The tolerance is 4.5 standard errors of the image mean
// (from the spread of its independent pixels), and the test asserts that this is below 0.5 %:
// measured standard errors 0.012-0.062 % at roughness 0.3 and 0.6 (256 spp), 0.10 % (naive) and 0.07 %
// (mis) at roughness 1 (640 spp), so a 0.5 % bias fails. Runtime on llvmpipe: about 80 s.
TEST_CASE("furnace: a rough metal with F0 = 1 reflects its GGX directional albedo with naive and mis") {
  for (float roughness : {0.3f, 0.6f, 1.0f}) {
    Scene s;
    Material sky = emitterMaterial(1.0f);
    sky.doubleSided = true;
    s.materials = {metalMaterial(glm::vec3(1.0f), roughness), sky};
    addQuad(s, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, 0);  // facing +z
    addSphere(s, {0, 0, 0}, 6.0f, 12, 1);
    finishBounds(s);
    const Camera cam = cameraAt({0.0f, 0.0f, 3.0f}, {0.0f, 0.0f, -1.0f}, {0.0f, 1.0f, 0.0f}, 0.04f);
    const double expected = ggxAlbedo(1.0, double(roughness) * roughness);
    for (Integrator integ : {Integrator::Naive, Integrator::Mis}) {
      const int n = 48;
      // Roughness 1 reflects least and noisiest (relative): 2.5 times the samples.
      RenderResult r = renderScene(s, cam, smallSettings(n, n, integ, 3), roughness < 1.0f ? 256 : 640, 64);
      CHECK(std::find(r.defines.begin(), r.defines.end(), "CAUSTICA_GGX") != r.defines.end());
      double mean = 0, var = 0;  // of the pixels' grey values, which are independent estimates
      std::vector<double> grey;
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) grey.push_back((r.image.at(x, y, 0) + r.image.at(x, y, 1) + r.image.at(x, y, 2)) / 3);
      for (double g : grey) mean += g / grey.size();
      for (double g : grey) var += (g - mean) * (g - mean) / (grey.size() - 1.0);
      const double se = std::sqrt(var / grey.size());
      const std::string what = "roughness " + std::to_string(roughness) + " " + integratorName(integ) + ": image mean " +
                               std::to_string(mean) + ", E(1) " + std::to_string(expected) + ", standard error " +
                               std::to_string(100 * se / expected) + " %";
      MESSAGE("GGX furnace ", what);
      INFO(what);
      CHECK(std::abs(mean - expected) <= 4.5 * se);
      CHECK(4.5 * se <= 0.005 * expected);  // the check above would fail a 0.5 % bias
      CHECK(r.stats.nonFinite == 0);
    }
  }
}

// The bundled scene of rough materials (rough gold, red plastic, frosted glass under two area
// lights): every GGX lobe's light sampling (vertexEval, vertexPdf) must agree with pure BSDF sampling,
// per region at depth 2 (direct light and the light seen through one rough refraction).
TEST_CASE("naive and mis agree per region: GGX lobes under two area lights") {
  checkRegionsAgree("assets/scenes/cornell-materials.gltf", 8192, 4096, 800, 4.0);
}

// One GGX lobe filling the view, lit by a square light, at depth 2 (direct light only): rough gold and
// red plastic floors under the light, and a frosted pane (a single quad: the space below it counts as
// inside the glass) with the light below it, seen through the pane. Light sampling of every lobe,
// including refraction, against pure BSDF sampling.
TEST_CASE("naive and mis agree per region: one GGX lobe filling the view") {
  for (int kind = 0; kind < 3; ++kind) {
    Scene s;
    Material m;
    m.baseColor = kind == 0 ? glm::vec4(1.0f, 0.766f, 0.336f, 1.0f) : kind == 1 ? glm::vec4(0.6f, 0.05f, 0.04f, 1.0f)
                                                                                : glm::vec4(1.0f);
    m.metallic = kind == 0 ? 1.0f : 0.0f;
    m.roughness = kind == 0 ? 0.5f : kind == 1 ? 0.3f : 0.6f;
    m.transmission = kind == 2 ? 1.0f : 0.0f;
    if (kind == 1) {
      m.specularF0 = glm::vec3(0.04f);
      m.specularF90 = 1.0f;
    }
    s.materials = {m, emitterMaterial(4.0f)};
    addQuad(s, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}, 0);  // facing +y
    const float h = kind == 2 ? 0.5f : 0.4f, y = kind == 2 ? -0.3f : 1.0f;  // the pane's light lies under all it shows
    if (kind == 2) addQuad(s, {-h, y, h}, {h, y, h}, {h, y, -h}, {-h, y, -h}, 1);  // facing +y, below the pane
    else addQuad(s, {-h, y, -h}, {h, y, -h}, {h, y, h}, {-h, y, h}, 1);           // facing -y, above the floor
    finishBounds(s);
    // The pane is seen from above, narrowly, so every pixel sees the light through it.
    s.cameras.push_back(kind == 2 ? lookAt({0.0f, 2.0f, 0.3f}, glm::vec3(0.0f), 0.35f)
                                  : lookAt({0.0f, 1.6f, 1.6f}, {0.0f, 0.0f, -0.3f}, 0.9f));
    const char* names[] = {"rough gold floor", "red plastic floor", "frosted pane over a light"};
    checkRegionsAgree(s, names[kind], 4096, 2048, 900 + 10 * kind, 4.0);
  }
}

// A Lambertian square under a small, distant light straight above it, with a normal map: texel 0
// flat, texel 1 tilted 60 degrees towards +u (nearest filtering). The square's uv stay inside texel 0,
// so without a transform the image equals the unmapped one; KHR_texture_transform's offset of half the
// texture moves every lookup to texel 1, and the radiance drops to cos(tilt): the 8-bit texel
// (238, 128, 191) decodes to a normal at cos = 0.4982 from the light. Same seed in all three renders,
// so the noise mostly cancels in the ratios; measured 0.99998 and 0.4985 (the light's extent moves the
// latter from the single-direction cosine by 0.07 %).
TEST_CASE("normal maps and KHR_texture_transform change the shading normal as the texel says") {
  Scene s;
  s.materials = {diffuseMaterial(0.8f), emitterMaterial(50.0f)};
  Texture map;
  map.width = 2;
  map.height = 1;
  map.rgba = {128, 128, 255, 255, 238, 128, 191, 255};
  map.nearest = true;
  s.textures.push_back(map);
  const glm::vec3 p[4] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  const glm::vec2 uv[4] = {{0.0f, 0.45f}, {0.45f, 0.45f}, {0.45f, 0.0f}, {0.0f, 0.0f}};  // u along +x, v down
  for (auto idx : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
    Triangle t{};
    TriangleUv tuv;
    for (int k = 0; k < 3; ++k) {
      t.p[k] = p[idx[k]];
      t.setNormal(k, glm::vec3(0, 0, 1));
      tuv.uv[k] = uv[idx[k]];
    }
    s.triangles.push_back(t);
    s.texcoords.push_back(tuv);
  }
  const float h = 0.3f;
  addQuad(s, {-h, h, 8}, {h, h, 8}, {h, -h, 8}, {-h, -h, 8}, 1);  // facing -z, down onto the square
  s.texcoords.resize(s.triangles.size());  // one per triangle: the light's (0, 0)
  finishBounds(s);
  const Camera cam = lookAt({0.0f, -0.5f, 3.0f}, glm::vec3(0.0f), 0.3f);
  auto render = [&](const Scene& scene) { return meanOf(renderScene(scene, cam, smallSettings(24, 24, Integrator::Mis, 5), 32).image); };
  const double plain = render(s);
  Scene mapped = s;
  mapped.materials[0].normalTexture = 0;
  const double flat = render(mapped);
  mapped.textures[0].uvRow0 = glm::vec3(1.0f, 0.0f, 0.5f);  // u' = u + 0.5: texel 1
  const double tilted = render(mapped);
  INFO("plain ", plain, ", mapped flat ", flat, ", mapped tilted ", tilted);
  CHECK(plain > 0.01);
  CHECK(flat / plain == Rel(1.0, 1e-4));
  CHECK(tilted / plain == Rel(0.4982, 0.01));
}

namespace {

// A white Lambertian sphere (radius 1, at the origin) under the given layers, inside a black sphere that
// emits radiance 1 everywhere, seen whole from 3.2 units away (every angle to the sphere's normal, and
// the enclosure around it): the white furnace of a material.
Scene layeredFurnace(float coat, float coatRoughness, glm::vec3 sheenColor, float sheenRoughness, float base = 1.0f,
                     int segments = 48) {
  Scene s;
  Material m = diffuseMaterial(base);
  m.clearcoat = coat;
  m.clearcoatRoughness = coatRoughness;
  m.sheenColor = sheenColor;
  m.sheenRoughness = sheenRoughness;
  Material sky = emitterMaterial(1.0f);
  sky.doubleSided = true;
  s.materials = {m, sky};
  addSphere(s, {0, 0, 0}, 1.0f, segments, 0);
  addSphere(s, {0, 0, 0}, 6.0f, 12, 1);
  finishBounds(s);
  s.cameras.push_back(lookAt({0.0f, 0.0f, 3.2f}, glm::vec3(0.0f), 0.75f));
  return s;
}

// Mean and standard error of the pixels' grey values (independent estimates) of an image.
std::pair<double, double> pixelMean(const Image& img) {
  std::vector<double> grey;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) grey.push_back((img.at(x, y, 0) + img.at(x, y, 1) + img.at(x, y, 2)) / 3);
  double mean = 0, var = 0;
  for (double g : grey) mean += g / double(grey.size());
  for (double g : grey) var += (g - mean) * (g - mean) / (double(grey.size()) - 1.0);
  return {mean, std::sqrt(var / double(grey.size()))};
}

}  // namespace

// The layers' white furnace on the GPU: a white base under a smooth clear coat keeps exactly what the
// coat does not reflect, so every pixel is 1 (each naive sample is 1 to rounding: the coat's pick over a
// white base is its weight); under a white sheen the layer takes max(sheenColor) E(cos_o) and gives back
// as much (1 to the albedo table's accuracy: 2e-4 on average); a rough coat loses GGX's single-scattering
// deficit on its share (below 1, never above). The tolerance is 4.5 standard errors of the image mean (its
// independent pixels), asserted to fail a 0.5 % bias. Measured: see the MESSAGEs (docs/materials.md).
TEST_CASE("furnace: clear coat and sheen over a white base give back what they take") {
  struct Case {
    const char* name;
    float coat, coatRoughness;
    glm::vec3 sheen;
    float sheenRoughness;
    bool exact;  // 1 in every pixel; else at most 1
  };
  const Case cases[] = {{"smooth clear coat", 1.0f, 0.0f, glm::vec3(0.0f), 0.0f, true},
                        {"white sheen, roughness 0.3", 0.0f, 0.0f, glm::vec3(1.0f), 0.3f, true},
                        {"white sheen, roughness 0.8, under a smooth coat", 1.0f, 0.0f, glm::vec3(1.0f), 0.8f, true},
                        {"rough clear coat (0.5)", 1.0f, 0.5f, glm::vec3(0.0f), 0.0f, false}};
  for (const Case& c : cases) {
    const Scene s = layeredFurnace(c.coat, c.coatRoughness, c.sheen, c.sheenRoughness);
    for (Integrator integ : {Integrator::Naive, Integrator::Mis}) {
      const int n = 40;
      RenderResult r = renderScene(s, s.cameras[0], smallSettings(n, n, integ, 7), 128, 64);
      CHECK(hasDefine(r.defines, c.coat > 0.0f ? "CAUSTICA_CLEARCOAT" : "CAUSTICA_SHEEN"));
      const auto [mean, se] = pixelMean(r.image);
      double hi = 0.0;
      for (float v : r.image.rgb) hi = std::max(hi, double(v));
      const std::string what = std::string(c.name) + " " + integratorName(integ) + ": image mean " +
                               std::to_string(mean) + ", standard error " + std::to_string(100 * se) + " %, brightest " +
                               std::to_string(hi);
      MESSAGE("layered furnace ", what);
      INFO(what);
      if (c.exact) CHECK(std::abs(mean - 1.0) <= 4.5 * se + 2e-4);
      else CHECK(mean <= 1.0 + 4.5 * se);
      CHECK(4.5 * se <= 0.005);
      if (c.exact && integ == Integrator::Naive && c.sheen == glm::vec3(0.0f)) CHECK(hi < 1.0 + 1e-4);  // each sample 1
      CHECK(r.stats.nonFinite == 0);
    }
  }
}

// ClearCoatTest's coat-only spheres (glTF sample models, as assimp ships them): a black base under a
// clear coat, which renders black where the coat is dropped. In the furnace (the black sphere emitting 1
// around it) a smooth coat over black reflects exactly its weight: each pixel is coatFresnel(cos theta)
// of its eye ray to the sphere's normal, 0.04 head-on rising to 1 at the rim. Compared over the pixels
// whose whole footprint sees the sphere at cos theta > 0.3 (away from the tessellated silhouette), against
// the pixel's mean over a 4 x 4 grid of its footprint (sphere of 192 segments: at 48 the facets alone
// bias the region by 0.24 %); tolerance 4.5 standard errors of that region's
// mean, asserted to fail a 0.5 % bias. A rough coat (0.5) over black is lit too, by at most the smooth
// coat's share (GGX loses energy, never gains it).
TEST_CASE("ClearCoatTest: a black base under only a clear coat shows the coat's reflection, not black") {
  const int n = 40;
  const Scene smooth = layeredFurnace(1.0f, 0.0f, glm::vec3(0.0f), 0.0f, 0.0f, 192);
  const Camera& cam = smooth.cameras[0];
  const float tanHalf = std::tan(0.5f * cam.yfov);
  const glm::vec3 right = glm::normalize(glm::cross(cam.forward, cam.up)) * tanHalf, up = cam.up * tanHalf;
  // cos theta of the eye ray through image point (px, py) (pixels, top-left origin) to the unit sphere's
  // normal where it hits it; -1 where it misses.
  auto cosAt = [&](float px, float py) {
    const glm::vec3 d = glm::normalize(cam.forward + (px / n * 2.0f - 1.0f) * right + (1.0f - py / n * 2.0f) * up);
    const float b = glm::dot(cam.position, d), c = glm::dot(cam.position, cam.position) - 1.0f;
    const float disc = b * b - c;
    if (disc < 0.0f) return -1.0f;
    const glm::vec3 p = cam.position + (-b - std::sqrt(disc)) * d;
    return -glm::dot(d, glm::normalize(p));
  };
  std::vector<std::pair<int, double>> inner;  // pixel index, expected value
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      double sum = 0.0;
      bool inside = true;
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
          const float cosTheta = cosAt(float(x) + (float(i) + 0.5f) / 4.0f, float(y) + (float(j) + 0.5f) / 4.0f);
          inside = inside && cosTheta > 0.3f;
          sum += coatFresnel(cosTheta) / 16.0;
        }
      if (inside) inner.emplace_back(y * n + x, sum);
    }
  REQUIRE(inner.size() > 300);
  auto regionMean = [&](const Image& img) {
    double mean = 0.0, var = 0.0, expected = 0.0;
    std::vector<double> diff;
    for (const auto& [k, e] : inner) {
      const double g = (img.rgb[3 * k] + img.rgb[3 * k + 1] + img.rgb[3 * k + 2]) / 3.0;
      diff.push_back(g - e);
      mean += g / double(inner.size());
      expected += e / double(inner.size());
    }
    double bias = 0.0;
    for (double d : diff) bias += d / double(diff.size());
    for (double d : diff) var += (d - bias) * (d - bias) / (double(diff.size()) - 1.0);
    return std::array<double, 3>{mean, expected, std::sqrt(var / double(diff.size()))};
  };
  for (Integrator integ : {Integrator::Naive, Integrator::Mis}) {
    const RenderResult r = renderScene(smooth, cam, smallSettings(n, n, integ, 11), 256, 64);
    CHECK(hasDefine(r.defines, "CAUSTICA_CLEARCOAT"));
    const auto [mean, expected, se] = regionMean(r.image);
    const std::string what = std::string("smooth coat over black ") + integratorName(integ) + ": inner mean " +
                             std::to_string(mean) + ", coatFresnel " + std::to_string(expected) + ", standard error " +
                             std::to_string(100 * se / expected) + " %";
    MESSAGE(what);
    INFO(what);
    CHECK(std::abs(mean - expected) <= 4.5 * se);
    CHECK(4.5 * se <= 0.005 * expected);
    CHECK(r.stats.nonFinite == 0);
    const RenderResult rough =
        renderScene(layeredFurnace(1.0f, 0.5f, glm::vec3(0.0f), 0.0f, 0.0f), cam, smallSettings(n, n, integ, 12), 64, 64);
    const double roughMean = regionMean(rough.image)[0];
    INFO("rough coat (0.5) over black: inner mean ", roughMean);
    CHECK(roughMean > 0.5 * expected);
    CHECK(roughMean <= expected * 1.01);
  }
}

// The textures of KHR_materials_specular (specularTexture A, specularColorTexture RGB) and
// KHR_materials_transmission (transmissionTexture R) scale their factors per hit: a material whose
// textures hold the value 128 (linear 128 / 255; the colour texture white) renders what the same material
// with the factor 128 / 255 written out renders, sample for sample (same lobe picks, same weights; only
// float rounding of F0 differs), and differently from the factor alone (the textures are not ignored).
TEST_CASE("specular and transmission textures scale their factors as the factors would") {
  const float half = 128.0f / 255.0f;
  for (int kind = 0; kind < 2; ++kind) {
    Scene s;
    Texture t;
    t.width = t.height = 1;
    t.rgba = kind == 0 ? std::vector<std::uint8_t>{255, 255, 255, 128} : std::vector<std::uint8_t>{128, 0, 0, 255};
    s.textures.push_back(t);
    Material textured = diffuseMaterial(glm::vec3(0.6f, 0.3f, 0.1f));
    textured.roughness = 0.4f;
    textured.specularF0 = glm::vec3(0.04f);
    textured.specularF90 = 1.0f;
    Material factor = textured;
    if (kind == 0) {  // the plastic lobe: F0 = 0.04 x A, F90 = A
      textured.specularTexture = textured.specularColorTexture = 0;
      factor.specularF0 = glm::vec3(0.04f * half);
      factor.specularF90 = half;
    } else {  // rough glass of weight transmission x R
      textured.transmission = 1.0f;
      textured.transmissionTexture = 0;
      factor.transmission = half;
    }
    Material untextured = textured;
    untextured.specularTexture = untextured.specularColorTexture = untextured.transmissionTexture = -1;
    const Material light = emitterMaterial(4.0f);
    auto render = [&](const Material& m) {
      Scene scene = s;
      scene.materials = {m, light};
      addQuad(scene, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}, 0);
      addQuad(scene, {-0.5f, 1.0f, -0.5f}, {0.5f, 1.0f, -0.5f}, {0.5f, 1.0f, 0.5f}, {-0.5f, 1.0f, 0.5f}, 1);
      scene.texcoords.assign(scene.triangles.size(), TriangleUv{});
      finishBounds(scene);
      const Camera cam = lookAt({0.0f, 1.6f, 1.6f}, {0.0f, 0.0f, -0.3f}, 0.9f);
      return renderScene(scene, cam, smallSettings(24, 24, Integrator::Mis, 3), 16);
    };
    const RenderResult a = render(textured), b = render(factor), c = render(untextured);
    CHECK(hasDefine(a.defines, "CAUSTICA_FACTOR_TEXTURES"));
    CHECK_FALSE(hasDefine(b.defines, "CAUSTICA_FACTOR_TEXTURES"));
    double worst = 0.0;
    for (std::size_t i = 0; i < a.image.rgb.size(); ++i)
      worst = std::max(worst, double(std::abs(a.image.rgb[i] - b.image.rgb[i])) / (1e-3 + double(b.image.rgb[i])));
    const double ma = meanOf(a.image), mb = meanOf(b.image), mc = meanOf(c.image);
    const std::string what = kind == 0 ? "specular texture" : "transmission texture";
    INFO(what, ": mean ", ma, ", factor ", mb, ", texture ignored ",
         mc, "; worst pixel ", worst);
    CHECK(worst < 1e-3);
    CHECK(std::abs(mc / mb - 1.0) > 0.02);
  }
}

// One layered material filling the view under a square light, at depth 2 (direct light only): the coat's
// and the sheen's light sampling (vertexEval, vertexPdf about the coat's own normal) against pure BSDF
// sampling, per region; the whole image must be sharp enough to fail a 0.5 % bias. The last case lights a
// white floor with an unlit, cut-out (alpha MASK) quad under a clear coat: emission only where the quad is
// present and darkened by its coat, alike in both estimators.
TEST_CASE("naive and mis agree per region: clear coat, sheen and an unlit cut-out light") {
  for (int kind = 0; kind < 5; ++kind) {
    Scene s;
    Material m = diffuseMaterial(glm::vec3(0.6f, 0.05f, 0.04f));
    m.roughness = 0.4f;
    m.specularF0 = glm::vec3(0.04f);
    m.specularF90 = 1.0f;
    Material light = emitterMaterial(4.0f);
    const char* names[] = {"red plastic under a smooth clear coat", "red plastic under a rough coat (0.3, weight 0.7)",
                           "velvet: sheen (0.9, 0.6, 0.3) roughness 0.3 over dark red", "sheen under a coat, coated light",
                           "white floor under an unlit coated cut-out light"};
    if (kind == 1) {
      m.clearcoat = 0.7f;
      m.clearcoatRoughness = 0.3f;
    } else if (kind == 0) {
      m.clearcoat = 1.0f;
    }
    if (kind == 2 || kind == 3) {
      m.baseColor = glm::vec4(0.15f, 0.02f, 0.02f, 1.0f);
      m.sheenColor = glm::vec3(0.9f, 0.6f, 0.3f);
      m.sheenRoughness = 0.3f;
    }
    if (kind == 3) {
      m.clearcoat = 0.5f;
      m.clearcoatRoughness = 0.2f;
      light.clearcoat = 1.0f;
    }
    if (kind == 4) {
      m = diffuseMaterial(0.8f);
      light.emission = glm::vec3(3.0f, 2.0f, 1.0f);  // an unlit surface: its colour emitted, nothing reflected
      light.unlit = true;
      light.clearcoat = 1.0f;
      light.alphaFromTexture = true;
      light.alphaCutoff = 0.5f;
      light.baseColorTexture = 0;  // a 2 x 2 checker of alpha: half of the quad is cut out
      Texture t;
      t.width = t.height = 2;
      t.rgba = {255, 255, 255, 255, 255, 255, 255, 0, 255, 255, 255, 0, 255, 255, 255, 255};
      t.nearest = true;
      s.textures.push_back(t);
    }
    s.materials = {m, light};
    addQuad(s, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, {-2, 0, -2}, 0);  // facing +y
    const float h = 1.0f;  // a large light: the naive estimate's noise is what limits the test
    addQuad(s, {-h, 1.0f, -h}, {h, 1.0f, -h}, {h, 1.0f, h}, {-h, 1.0f, h}, 1);  // facing -y
    if (kind == 4) {  // the checker over the light quad: u along x, v along z
      s.texcoords.assign(s.triangles.size(), TriangleUv{});
      const glm::vec2 uv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      s.texcoords[2].uv[0] = uv[0], s.texcoords[2].uv[1] = uv[1], s.texcoords[2].uv[2] = uv[2];
      s.texcoords[3].uv[0] = uv[0], s.texcoords[3].uv[1] = uv[2], s.texcoords[3].uv[2] = uv[3];
    }
    finishBounds(s);
    s.cameras.push_back(lookAt({0.0f, 1.6f, 1.6f}, {0.0f, 0.0f, -0.3f}, 0.9f));
    const int spp = kind == 4 ? 2 : 1;  // the cut-out light's naive estimate is the noisiest
    checkRegionsAgree(s, names[kind], 4096 * spp, 2048 * spp, 1000 + 10 * kind, 4.0, true);
  }
}
