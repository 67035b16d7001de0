// shard_merge_test.cpp — a render split into N shards (Renderer::startAtSample at each share's first
// sample), merged by mergeShards, equals one renderer's render of the same samples: sample counts and
// the half image's counts exactly, every image value within kMergeUlps units in the last place (the
// order of float summation: docs/render-farm.md states this bound).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <cstring>

#include "cli/image_settings.h"
#include "cli/shard.h"
#include "gl_test_util.h"

using namespace caustica;
using namespace caustica::test;

namespace {

// One machine's Kahan sum S stands for S - c with |c| up to half an ulp of S; the merge rounds its
// double total once (half an ulp); both sides then divide by the same count (half an ulp each).
// Measured on llvmpipe: at most 2 ulps, in 1-6 % of the values, over 40,000 values (cornell-glass and
// cornell-box, 1 to 50 shards, 21 to 400 spp); the tests print it. Allowed: 3 (relative 3.6e-7).
constexpr std::int64_t kMergeUlps = 3;

// Distance in units in the last place between two finite floats of the same sign (0: equal bits).
std::int64_t ulps(float a, float b) {
  if (a == b) return 0;
  std::int32_t ia, ib;
  std::memcpy(&ia, &a, 4);
  std::memcpy(&ib, &b, 4);
  if ((ia < 0) != (ib < 0)) return std::int64_t(1) << 40;  // opposite signs: far apart
  return std::llabs(std::int64_t(ia) - std::int64_t(ib));
}

struct Comparison {
  std::int64_t maxUlps = 0;
  std::size_t differing = 0, values = 0;
};

Comparison compare(const std::vector<float>& a, const std::vector<float>& b) {
  Comparison c;
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::int64_t u = ulps(a[i], b[i]);
    c.maxUlps = std::max(c.maxUlps, u);
    c.differing += u != 0;
  }
  c.values = a.size();
  return c;
}

cli::Checkpoint shardPartial(const Scene& scene, const Camera& camera, const RenderSettings& rs, int k, int n, int spp) {
  const cli::SampleShare share = cli::shareOf(k, n, spp);
  Renderer r(testShaderLibrary(), scene, camera, rs);
  r.startAtSample(share.first);
  const int count = int(share.end - share.first);
  // Passes of other sizes than the straight render's: the samples do not depend on the split.
  for (int done = 0; done < count;) {
    const int pass = std::min(count - done, 3);
    r.renderPass(pass);
    done += pass;
  }
  cli::Checkpoint ck;
  ck.state = r.saveAccumulation();
  ck.seed = rs.seed;
  ck.sceneHash = 1;
  ck.identity = cli::accumulationIdentity(cli::ImageSettings{rs}, camera);
  ck.shard = share;
  return ck;
}

void checkShardsEqualOne(const Scene& scene, const RenderSettings& rs, int spp, std::initializer_list<int> shardCounts) {
  const Camera camera = sceneCamera(scene);
  Renderer straight(testShaderLibrary(), scene, camera, rs);
  straight.renderPass(spp);
  const AccumulationState one = straight.saveAccumulation();
  const Image oneImage = straight.image();
  CHECK(meanOf(oneImage) > 0.01);
  for (int n : shardCounts) {
    CAPTURE(n);
    std::vector<cli::MergePart> parts;
    for (int k = 1; k <= n; ++k) parts.push_back({"part" + std::to_string(k), shardPartial(scene, camera, rs, k, n, spp)});
    const cli::MergeResult merged = cli::mergeShards(parts, false);
    const AccumulationState& m = merged.merged.state;
    REQUIRE(m.accum.size() == one.accum.size());
    CHECK(m.spp == spp);
    for (std::size_t p = 3; p < m.accum.size(); p += 4) {
      CHECK(m.accum[p] - m.comp[p] == one.accum[p] - one.comp[p]);  // every pixel's sample count, exactly
      CHECK(m.half[p] == one.half[p]);                               // and its odd-numbered samples'
    }
    if (!one.coverage.empty()) CHECK(m.coverage == one.coverage);  // hits are counts: exact
    const Image mergedImage = meanImage(m.width, m.height, m.accum, m.coverage.empty() ? nullptr : &m.coverage);
    const Comparison c = compare(mergedImage.rgb, oneImage.rgb);
    const Comparison h = compare(m.half, one.half);
    MESSAGE(n << " shards of " << spp << " spp: image values " << c.differing << " of " << c.values
              << " differ, by at most " << c.maxUlps << " ulp; half-image sums by at most " << h.maxUlps << " ulp");
    CHECK(c.maxUlps <= kMergeUlps);
    // The half image is a plain float sum (no compensation): one machine's rounding error grows with its
    // samples (measured: 10 ulps at 200 odd samples), the merge's double sum has almost none.
    CHECK(h.maxUlps <= spp / 2 + 2);
    if (!oneImage.alpha.empty()) CHECK(mergedImage.alpha == oneImage.alpha);
  }
}

}  // namespace

TEST_CASE("shards merged equal one render: Cornell box with glass, 1 to 16 shards of 21 spp") {
  const Scene scene = loadScene(sourcePath("assets/scenes/cornell-glass.gltf"));
  RenderSettings rs;
  rs.width = 24;
  rs.height = 18;
  rs.seed = 5;
  checkShardsEqualOne(scene, rs, 21, {1, 2, 3, 5, 16});
}

TEST_CASE("shards merged equal one render: manifold NEE (its photon pass the same in every shard), 3 shards of 12 spp") {
  const Scene scene = loadScene(sourcePath("assets/scenes/cornell-glass.gltf"));
  RenderSettings rs;
  rs.width = 24;
  rs.height = 18;
  rs.seed = 7;
  rs.manifold = ManifoldMode::On;
  checkShardsEqualOne(scene, rs, 12, {3});
}

TEST_CASE("shards merged equal one render: a transparent background's coverage, 64 spp in 4 shards") {
  Scene scene = loadScene(sourcePath("assets/scenes/sun-glass.gltf"));
  scene.background.kind = Background::Kind::Transparent;
  scene.environment = uniformEnvironment(glm::vec3(1.0f));
  RenderSettings rs;
  rs.width = 16;
  rs.height = 16;
  checkShardsEqualOne(scene, rs, 64, {4});
}
