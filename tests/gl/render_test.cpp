// render_test.cpp — accuracy of the path tracer against ground truth on llvmpipe: furnaces with known
// answers, an invisible glass sphere, naive vs MIS agreement, a caustic where optics puts it, rgb vs
// spectral dispersion, reproducibility, and no non-finite samples.
#include <doctest/doctest.h>

#include <cmath>

#include "core/sampling.h"
#include "gl_test_util.h"

using namespace caustica;
using namespace caustica::test;

namespace {

RenderSettings small(int w, int h, Integrator integrator, std::uint32_t seed = 1) {
  RenderSettings s;
  s.width = w;
  s.height = h;
  s.integrator = integrator;
  s.seed = seed;
  return s;
}

// Per-block means of several independent renders (different seeds) for a statistical comparison.
struct BlockStats {
  int blocksX = 0, blocksY = 0;
  std::vector<double> mean, var;  // per block and channel: mean of the renders, variance of that mean
};

BlockStats blockStats(const Scene& scene, const Camera& cam, Integrator integrator, int w, int h, int block, int spp,
                      int renders, std::uint32_t seedBase, std::uint64_t* nonFinite) {
  BlockStats b;
  b.blocksX = w / block;
  b.blocksY = h / block;
  size_t nb = static_cast<size_t>(b.blocksX) * b.blocksY * 3;
  std::vector<std::vector<double>> per(renders, std::vector<double>(nb, 0.0));
  for (int r = 0; r < renders; ++r) {
    RenderResult res = renderScene(scene, cam, small(w, h, integrator, seedBase + r), spp);
    *nonFinite += res.stats.nonFinite;
    for (int y = 0; y < b.blocksY * block; ++y)
      for (int x = 0; x < b.blocksX * block; ++x)
        for (int c = 0; c < 3; ++c)
          per[r][(static_cast<size_t>(y / block) * b.blocksX + x / block) * 3 + c] += res.image.at(x, y, c) / (block * block);
  }
  b.mean.assign(nb, 0.0);
  b.var.assign(nb, 0.0);
  for (size_t i = 0; i < nb; ++i) {
    for (int r = 0; r < renders; ++r) b.mean[i] += per[r][i] / renders;
    for (int r = 0; r < renders; ++r) b.var[i] += (per[r][i] - b.mean[i]) * (per[r][i] - b.mean[i]) / (renders - 1);
    b.var[i] /= renders;  // variance of the mean
  }
  return b;
}

// naive and mis must agree within noise: per block, |difference| within 4.5 standard errors (plus a
// small relative slack for the variance estimate's own noise), and the image means within 3 %.
void checkEstimatorsAgree(const std::string& scenePath, int w, int h, int sppNaive, int sppMis) {
  Scene scene = loadScene(sourcePath(scenePath));
  Camera cam = sceneCamera(scene);
  std::uint64_t nonFinite = 0;
  const int block = 8, renders = 4;
  BlockStats a = blockStats(scene, cam, Integrator::Naive, w, h, block, sppNaive, renders, 100, &nonFinite);
  BlockStats b = blockStats(scene, cam, Integrator::Mis, w, h, block, sppMis, renders, 200, &nonFinite);
  int bad = 0;
  double sumA = 0, sumB = 0;
  std::string worst;
  for (size_t i = 0; i < a.mean.size(); ++i) {
    double diff = std::abs(a.mean[i] - b.mean[i]);
    double tol = 4.5 * std::sqrt(a.var[i] + b.var[i]) + 0.02 * std::max(a.mean[i], b.mean[i]) + 1e-4;
    if (diff > tol) {
      ++bad;
      worst = "block " + std::to_string(i / 3) + " channel " + std::to_string(i % 3) + ": naive " +
              std::to_string(a.mean[i]) + " mis " + std::to_string(b.mean[i]) + " tol " + std::to_string(tol);
    }
    sumA += a.mean[i];
    sumB += b.mean[i];
  }
  INFO(scenePath, ": ", bad, " of ", a.mean.size(), " block channels disagree; e.g. ", worst);
  CHECK(bad <= 1);  // one in ~200 may fall outside 4.5 sigma with an estimated variance
  CHECK(sumA / sumB == doctest::Approx(1.0).epsilon(0.03));
  CHECK(nonFinite == 0);
}

}  // namespace

TEST_CASE("furnace: walls of albedo 0.5 emitting 1 give radiance 2 everywhere") {
  for (const char* file : {"tests/data/scenes/furnace.gltf", "tests/data/scenes/furnace-glass.gltf"}) {
    Scene scene = loadScene(sourcePath(file));
    for (Integrator integ : {Integrator::Naive, Integrator::Mis}) {
      RenderResult r = renderScene(scene, sceneCamera(scene), small(32, 32, integ), 64);
      INFO(file, " ", integratorName(integ));
      for (int c = 0; c < 3; ++c) CHECK(meanOf(r.image, c) == doctest::Approx(2.0).epsilon(0.01));
      int farOff = 0;
      for (float v : r.image.rgb) farOff += std::abs(v - 2.0f) > 0.6f;
      CHECK(farOff == 0);
      CHECK(r.stats.nonFinite == 0);
    }
  }
}

TEST_CASE("a clear glass sphere inside a uniformly emitting black enclosure is invisible") {
  Scene scene = loadScene(sourcePath("tests/data/scenes/glass-in-white-enclosure.gltf"));
  for (Integrator integ : {Integrator::Naive, Integrator::Mis}) {
    RenderResult r = renderScene(scene, sceneCamera(scene), small(32, 32, integ), 16);
    INFO(integratorName(integ));
    CHECK(meanOf(r.image) == doctest::Approx(1.0).epsilon(0.005));
    float lo = 1e9f, hi = -1e9f;
    for (float v : r.image.rgb) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    CHECK(lo > 0.9f);  // no dark silhouette, no bright rim: energy neither lost nor created
    CHECK(hi < 1.1f);
  }
}

TEST_CASE("naive and mis converge to the same image: Cornell box") {
  checkEstimatorsAgree("assets/scenes/cornell-box.gltf", 32, 32, 128, 32);
}

TEST_CASE("naive and mis converge to the same image: glass and mirror spheres") {
  checkEstimatorsAgree("tests/data/scenes/small-cornell.gltf", 32, 32, 128, 32);
}

TEST_CASE("naive and mis converge to the same image: bunny-shaped light") {
  checkEstimatorsAgree("assets/scenes/cornell-bunny-light.gltf", 32, 32, 128, 32);
}

TEST_CASE("same seed, same image; another seed, another image") {
  Scene scene = loadScene(sourcePath("tests/data/scenes/small-cornell.gltf"));
  RenderResult a = renderScene(scene, sceneCamera(scene), small(16, 16, Integrator::Mis, 5), 4, 4);
  RenderResult b = renderScene(scene, sceneCamera(scene), small(16, 16, Integrator::Mis, 5), 4, 1);  // other split
  RenderResult c = renderScene(scene, sceneCamera(scene), small(16, 16, Integrator::Mis, 6), 4, 4);
  double maxDiff = 0, otherDiff = 0;
  for (size_t i = 0; i < a.image.rgb.size(); ++i) {
    maxDiff = std::max(maxDiff, double(std::abs(a.image.rgb[i] - b.image.rgb[i])));
    otherDiff = std::max(otherDiff, double(std::abs(a.image.rgb[i] - c.image.rgb[i])));
  }
  CHECK(maxDiff <= 1e-5);  // only the order of float additions may differ
  CHECK(otherDiff > 1e-3);
}
