// light_tree_test.cpp — the light tree (app/accel/light_tree.h): its choice probabilities over all
// triangles sum to 1 from any shading point, sampled frequencies match lightTreePdf (chi-square), a
// triangle it never picks cannot light the point (no bias), leaves stay within the trail's bits, and
// the tree is the same for the emitters scaled, moved and given in another order.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "accel/light_tree.h"

using namespace caustica;

namespace {

// Random small triangles in a 10^3 box with random powers over 4 decades; some two-sided.
std::vector<LightTreeItem> randomLights(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-5.0f, 5.0f), off(-0.3f, 0.3f), expo(-2.0f, 2.0f), unit(0.0f, 1.0f);
  std::vector<LightTreeItem> items;
  for (int i = 0; i < n; ++i) {
    LightTreeItem t;
    t.tri = static_cast<std::uint32_t>(2 * i + 1);  // not every triangle emits
    glm::vec3 c(pos(rng), pos(rng), pos(rng));
    for (auto& v : t.v) v = c + glm::vec3(off(rng), off(rng), off(rng));
    t.power = std::pow(10.0, expo(rng));
    t.twoSided = unit(rng) < 0.2f;
    items.push_back(t);
  }
  return items;
}

// Probability that sampleLightTree(p, n) stops at a dead end: an inner node it reached whose two
// children both have zero importance (their tighter bounds show that nothing below lights p; the
// sample then contributes nothing, which is unbiased). Every other path ends at a leaf.
double deadEndMass(const std::vector<gpu::LightNode>& nodes, glm::vec3 p, glm::vec3 n, std::uint32_t i = 0, float q = 1.0f) {
  const gpu::LightNode& node = nodes[i];
  if (i == 0 && (node.link.y & gpu::kLightNodeLeaf)) return lightImportance(node, p, n) > 0.0f ? 0.0 : 1.0;
  if (node.link.y & gpu::kLightNodeLeaf) return 0.0;
  float il = lightImportance(nodes[node.link.x], p, n), ir = lightImportance(nodes[node.link.x + 1], p, n);
  if (!(il + ir > 0.0f)) return q;
  float pl = il / (il + ir);
  double dead = 0.0;
  if (pl > 0.0f) dead += deadEndMass(nodes, p, n, node.link.x, q * pl);
  if (pl < 1.0f) dead += deadEndMass(nodes, p, n, node.link.x + 1, q * (1.0f - pl));
  return dead;
}

glm::vec3 randomDir(std::mt19937& rng) {
  std::normal_distribution<float> g;
  glm::vec3 d(g(rng), g(rng), g(rng));
  return glm::normalize(d);
}

}  // namespace

TEST_CASE("light tree: one leaf per emitter, children adjacent, leafOf maps back") {
  auto items = randomLights(300, 1);
  LightTree t = buildLightTree(items, 601);
  REQUIRE(t.nodes.size() == 2 * items.size() - 1);
  int leaves = 0;
  for (std::uint32_t i = 0; i < t.nodes.size(); ++i)
    if (t.nodes[i].link.y & gpu::kLightNodeLeaf) {
      ++leaves;
      CHECK(t.leafOf[t.nodes[i].link.x] == i);
    }
  CHECK(leaves == 300);
  for (std::uint32_t k = 0; k < 601; k += 2) CHECK(t.leafOf[k] == gpu::kInvalidIndex);
  CHECK(t.nodes[0].boundsMin.w == doctest::Approx([&] { double s = 0; for (auto& x : items) s += x.power; return s; }()).epsilon(1e-5));
  CHECK(t.maxDepth <= CAUSTICA_LIGHT_TREE_DEPTH);
  // One emitter: the root is its leaf, chosen with probability 1 from its front.
  LightTree one = buildLightTree({items[0]}, 2);
  REQUIRE(one.nodes.size() == 1);
  CHECK(buildLightTree({}, 3).nodes.empty());
}

TEST_CASE("light tree: leavesBySource lists every leaf in its item's source order") {
  auto items = randomLights(300, 2);
  for (std::size_t i = 0; i < items.size(); ++i) items[i].source = static_cast<std::uint32_t>((i * 7919u) % 300u);
  LightTree t = buildLightTree(items, 601);
  REQUIRE(t.leavesBySource.size() == items.size());
  std::vector<std::uint32_t> triOfSource(300);
  for (const auto& it : items) triOfSource[it.source] = it.tri;
  for (std::uint32_t s = 0; s < 300; ++s) {
    const gpu::LightNode& leaf = t.nodes[t.leavesBySource[s]];
    REQUIRE((leaf.link.y & gpu::kLightNodeLeaf) != 0u);
    CHECK(leaf.link.x == triOfSource[s]);
  }
}

// The sum is 1 minus the mass of dead ends (deadEndMass), which is reported; the chi-square test below
// shows the sampler draws each triangle with the probability lightTreePdf gives.
TEST_CASE("light tree: the probabilities of all triangles sum to 1 at random points") {
  auto items = randomLights(500, 2);
  LightTree t = buildLightTree(items, 1001);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-7.0f, 7.0f);
  int sampled = 0;
  double meanDead = 0.0;
  for (int k = 0; k < 200; ++k) {
    glm::vec3 p(pos(rng), pos(rng), pos(rng));
    glm::vec3 n = k % 5 == 0 ? glm::vec3(0.0f) : randomDir(rng);
    double sum = 0.0;
    for (const auto& it : items) sum += lightTreePdf(t.nodes, p, n, t.leafOf[it.tri]);
    std::uint32_t tri;
    float pmf;
    bool ok = sampleLightTree(t.nodes, p, n, 0.5f, tri, pmf);
    double dead = deadEndMass(t.nodes, p, n);
    meanDead += dead / 200.0;
    INFO("point ", k, " sum ", sum, " dead ends ", dead);
    CHECK(std::abs(sum + dead - 1.0) <= 1e-4);
    if (ok) {
      ++sampled;
      CHECK(pmf == lightTreePdf(t.nodes, p, n, t.leafOf[tri]));  // the same arithmetic: exactly equal
    }
  }
  MESSAGE("mean probability of a dead end over 200 random points: ", meanDead);
  CHECK(meanDead < 0.1);  // measured 0.040 (random points and orientations: many lights face away)
  CHECK(sampled >= 190);  // points among scattered lights in every direction are nearly always lit
}

TEST_CASE("light tree: sampled frequencies match lightTreePdf (chi-square)") {
  auto items = randomLights(60, 3);
  LightTree t = buildLightTree(items, 121);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (glm::vec3 p : {glm::vec3(0.1f, 0.2f, 0.3f), glm::vec3(4.0f, -3.0f, 2.0f), glm::vec3(-8.0f, 1.0f, 0.0f)}) {
    glm::vec3 n = glm::normalize(glm::vec3(0.3f, 1.0f, -0.2f));
    const int samples = 400000;
    std::vector<double> count(t.nodes.size(), 0.0);
    for (int s = 0; s < samples; ++s) {
      std::uint32_t tri;
      float pmf;
      if (sampleLightTree(t.nodes, p, n, unit(rng), tri, pmf)) count[t.leafOf[tri]] += 1.0;
    }
    // Pool cells with expected count < 20 into one; chi-square over the rest.
    double chi2 = 0.0, pooledObs = 0.0, pooledExp = 0.0;
    int dof = -1;
    for (const auto& it : items) {
      std::uint32_t leaf = t.leafOf[it.tri];
      double e = samples * static_cast<double>(lightTreePdf(t.nodes, p, n, leaf));
      if (e < 20.0) {
        pooledObs += count[leaf];
        pooledExp += e;
        if (e == 0.0) CHECK(count[leaf] == 0.0);
        continue;
      }
      chi2 += (count[leaf] - e) * (count[leaf] - e) / e;
      ++dof;
    }
    if (pooledExp >= 20.0) {
      chi2 += (pooledObs - pooledExp) * (pooledObs - pooledExp) / pooledExp;
      ++dof;
    }
    // chi-square with dof degrees of freedom: mean dof, sd sqrt(2 dof); 1e-4 quantile below mean + 5.5 sd.
    INFO("p = (", p.x, ", ", p.y, ", ", p.z, "): chi2 ", chi2, " with ", dof, " degrees of freedom");
    REQUIRE(dof >= 10);
    CHECK(chi2 <= dof + 5.5 * std::sqrt(2.0 * dof));
  }
}

TEST_CASE("light tree: a triangle never chosen cannot light the point (the estimate stays unbiased)") {
  auto items = randomLights(300, 4);
  for (auto& it : items) it.twoSided = false;
  LightTree t = buildLightTree(items, 601);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> pos(-7.0f, 7.0f), unit(0.0f, 1.0f);
  int zeros = 0;
  for (int k = 0; k < 100; ++k) {
    glm::vec3 p(pos(rng), pos(rng), pos(rng));
    glm::vec3 n = randomDir(rng);
    for (const auto& it : items) {
      if (lightTreePdf(t.nodes, p, n, t.leafOf[it.tri]) > 0.0f) continue;
      ++zeros;
      glm::vec3 nl = glm::cross(it.v[1] - it.v[0], it.v[2] - it.v[0]);
      for (int s = 0; s < 16; ++s) {  // random points x on the triangle: p must lie behind its front face
        float a = unit(rng), b = unit(rng);
        if (a + b > 1.0f) { a = 1.0f - a; b = 1.0f - b; }
        glm::vec3 x = it.v[0] + a * (it.v[1] - it.v[0]) + b * (it.v[2] - it.v[0]);
        CHECK(glm::dot(nl, p - x) <= 1e-5f * glm::length(nl));
      }
    }
  }
  CHECK(zeros > 1000);  // about half the one-sided lights face away from any point
}

TEST_CASE("light tree: leaves stay within the 32-bit trail on a geometric progression of lights") {
  // Powers and positions growing by 1.5x: the cost model would peel one light per level (depth ~200).
  std::vector<LightTreeItem> items;
  for (int i = 0; i < 200; ++i) {
    LightTreeItem t;
    t.tri = static_cast<std::uint32_t>(i);
    float x = std::pow(1.5f, static_cast<float>(i % 60)) * (i < 60 ? 1.0f : 1.0f + 0.001f * static_cast<float>(i));
    t.v[0] = glm::vec3(x, 0, 0);
    t.v[1] = glm::vec3(x + 0.01f, 0, 0);
    t.v[2] = glm::vec3(x, 0, 0.01f);
    t.power = std::pow(1.5, i % 60);
    items.push_back(t);
  }
  LightTree t = buildLightTree(items, 200);
  CHECK(t.maxDepth <= CAUSTICA_LIGHT_TREE_DEPTH);
  double sum = 0.0;
  glm::vec3 p(3.0f, 1.0f, 0.5f);
  for (std::uint32_t i = 0; i < 200; ++i) sum += lightTreePdf(t.nodes, p, glm::vec3(0, 1, 0), t.leafOf[i]);
  CHECK(std::abs(sum + deadEndMass(t.nodes, p, glm::vec3(0, 1, 0)) - 1.0) <= 1e-4);
}

namespace {

// Small symmetric lamps as a scene has them: a 16-triangle fan (a disc lamp, 2 cm), a 4x4 grid of
// quads (a 4-cm panel) tilted and another axis-aligned, a strip of LEDs and a ring of 12 small squares,
// with a few random emitters around; in double in their own frame, then placed by `world` and rounded
// to float as a loader does. `source` is the triangle's place in the scene, `tri` its place in `order` (a BVH's).
std::vector<LightTreeItem> lampScene(const glm::dmat4& world, const std::vector<std::uint32_t>& order) {
  std::vector<std::array<glm::dvec3, 3>> tris;
  const glm::dmat4 tilt = glm::rotate(glm::dmat4(1.0), 0.3, glm::dvec3(1.0, 0.2, 0.5));
  auto add = [&](const glm::dmat4& frame, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    tris.push_back({glm::dvec3(frame * glm::dvec4(a, 1.0)), glm::dvec3(frame * glm::dvec4(b, 1.0)),
                    glm::dvec3(frame * glm::dvec4(c, 1.0))});
  };
  const glm::dmat4 disc = glm::translate(glm::dmat4(1.0), glm::dvec3(-0.3, 0.9, 0.1)) * tilt;
  for (int i = 0; i < 16; ++i) {
    const double a0 = 2.0 * 3.14159265358979 * i / 16, a1 = 2.0 * 3.14159265358979 * (i + 1) / 16;
    add(disc, glm::dvec3(0.0), glm::dvec3(0.01 * std::cos(a1), 0.0, 0.01 * std::sin(a1)),
        glm::dvec3(0.01 * std::cos(a0), 0.0, 0.01 * std::sin(a0)));
  }
  const glm::dmat4 panel = glm::translate(glm::dmat4(1.0), glm::dvec3(0.25, 1.1, -0.2)) * tilt;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double x = -0.02 + 0.01 * i, z = -0.02 + 0.01 * j;
      add(panel, glm::dvec3(x, 0, z), glm::dvec3(x, 0, z + 0.01), glm::dvec3(x + 0.01, 0, z + 0.01));
      add(panel, glm::dvec3(x, 0, z), glm::dvec3(x + 0.01, 0, z + 0.01), glm::dvec3(x + 0.01, 0, z));
    }
  // An axis-aligned panel: its x and z splits cost the same, and its centroids lie on bucket boundaries.
  const glm::dmat4 square = glm::translate(glm::dmat4(1.0), glm::dvec3(0.137, 1.213, -0.311));
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double x = -0.02 + 0.01 * i, z = -0.02 + 0.01 * j;
      add(square, glm::dvec3(x, 0, z), glm::dvec3(x, 0, z + 0.01), glm::dvec3(x + 0.01, 0, z + 0.01));
      add(square, glm::dvec3(x, 0, z), glm::dvec3(x + 0.01, 0, z + 0.01), glm::dvec3(x + 0.01, 0, z));
    }
  // A strip of 13 LEDs 1 cm apart: their centroids lie on the 12 buckets' boundaries.
  for (int i = 0; i < 13; ++i) {
    const glm::dmat4 f = glm::translate(glm::dmat4(1.0), glm::dvec3(-0.271 + 0.01 * i, 0.917, 0.333));
    add(f, glm::dvec3(-0.002, 0, -0.002), glm::dvec3(-0.002, 0, 0.002), glm::dvec3(0.002, 0, 0.002));
    add(f, glm::dvec3(-0.002, 0, -0.002), glm::dvec3(0.002, 0, 0.002), glm::dvec3(0.002, 0, -0.002));
  }
  const glm::dmat4 ring = glm::translate(glm::dmat4(1.0), glm::dvec3(0.0, 1.3, 0.4));
  for (int i = 0; i < 12; ++i) {
    const glm::dmat4 f = ring * glm::rotate(glm::dmat4(1.0), 2.0 * 3.14159265358979 * i / 12, glm::dvec3(0, 1, 0)) *
                         glm::translate(glm::dmat4(1.0), glm::dvec3(0.05, 0.0, 0.0));
    add(f, glm::dvec3(-0.004, 0, -0.004), glm::dvec3(-0.004, 0, 0.004), glm::dvec3(0.004, 0, 0.004));
    add(f, glm::dvec3(-0.004, 0, -0.004), glm::dvec3(0.004, 0, 0.004), glm::dvec3(0.004, 0, -0.004));
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> pos(-1.0, 1.0), off(-0.05, 0.05);
  for (int i = 0; i < 20; ++i) {
    const glm::dvec3 c(pos(rng), pos(rng) + 1.0, pos(rng));
    tris.push_back({c + glm::dvec3(off(rng), off(rng), off(rng)), c + glm::dvec3(off(rng), off(rng), off(rng)),
                    c + glm::dvec3(off(rng), off(rng), off(rng))});
  }
  std::vector<LightTreeItem> items(tris.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    LightTreeItem& t = items[k];
    t.tri = static_cast<std::uint32_t>(k);
    t.source = order[k];
    for (int v = 0; v < 3; ++v) t.v[v] = glm::vec3(world * glm::dvec4(tris[order[k]][v], 1.0));
    glm::dvec3 e1 = tris[order[k]][1] - tris[order[k]][0], e2 = tris[order[k]][2] - tris[order[k]][0];
    t.power = 0.5 * glm::length(glm::cross(e1, e2)) * 1e4 * (order[k] < 16 ? 3.0 : 1.0);  // area x radiance, unscaled
  }
  return items;
}

// The tree's shape: each node's kind, and for a leaf the source of its emitter, its depth and trail.
std::vector<std::string> treeShape(const LightTree& t, const std::vector<LightTreeItem>& items) {
  std::vector<std::uint32_t> sourceOf(items.size());
  for (const auto& it : items) sourceOf[it.tri] = it.source;
  std::vector<std::string> shape;
  for (const gpu::LightNode& n : t.nodes)
    shape.push_back((n.link.y & gpu::kLightNodeLeaf) ? "leaf " + std::to_string(sourceOf[n.link.x]) + " depth " +
                                                           std::to_string(n.link.w) + " trail " + std::to_string(n.link.z)
                                                     : std::string("inner"));
  return shape;
}

}  // namespace

TEST_CASE("light tree: the same tree for the emitters scaled by 1e-4..1e4, moved, and given in another order") {
  // Each rule of the builder's scale invariance (light_tree.cpp) is needed here: without the source
  // order, the snapped centroids, the cost tie or the cone of nearly parallel normals some tree differs.
  constexpr std::size_t kTris = 16 + 32 + 32 + 26 + 24 + 20;
  std::vector<std::uint32_t> identity(kTris);
  for (std::uint32_t i = 0; i < kTris; ++i) identity[i] = i;
  const auto refItems = lampScene(glm::dmat4(1.0), identity);
  const LightTree ref = buildLightTree(refItems, kTris);
  const std::vector<std::string> refShape = treeShape(ref, refItems);
  std::mt19937 rng(11);
  for (double scale : {1e-4, 1e-3, 1e-2, 0.1, 1.0, 3.0, 10.0, 1e2, 1e3, 1e4})
    for (double move : {0.0, 0.7, 3.0}) {
      std::vector<std::uint32_t> order = identity;
      std::shuffle(order.begin(), order.end(), rng);  // the BVH's order changes with rounding
      const glm::dmat4 world = glm::scale(glm::translate(glm::dmat4(1.0), move * scale * glm::dvec3(1.0, -0.7, 0.4)),
                                          glm::dvec3(scale));
      auto items = lampScene(world, order);
      for (auto& it : items) it.power *= scale * scale;
      const LightTree t = buildLightTree(items, kTris);
      CAPTURE(scale);
      CAPTURE(move);
      const std::vector<std::string> shape = treeShape(t, items);
      REQUIRE(shape.size() == refShape.size());
      int differ = 0;
      for (std::size_t i = 0; i < shape.size(); ++i) {
        differ += shape[i] != refShape[i];
      }
      CHECK(differ == 0);
      // The bounds scale with the scene; the cones and relative powers are the same up to rounding.
      for (std::size_t i = 0; i < shape.size(); ++i) {
        CHECK(t.nodes[i].boundsMax.w == doctest::Approx(ref.nodes[i].boundsMax.w).epsilon(1e-4));
        CHECK(glm::dot(glm::vec3(t.nodes[i].axis), glm::vec3(ref.nodes[i].axis)) > 0.9999f);
        CHECK(t.nodes[i].boundsMin.w / float(scale * scale) == doctest::Approx(ref.nodes[i].boundsMin.w).epsilon(1e-5));
      }
    }
}
