// bvh_wide_test.cpp — the 4-wide BVH collapsed from the binary tree (structure: every binary leaf once,
// boxes bit for bit, stack bound) and its C++ traversal twin against brute force and the binary twin.
#include <doctest/doctest.h>
#include "scene/assets.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "accel/bvh.h"
#include "accel/bvh_traverse.h"
#include "brute_force.h"
#include "accel/bvh_wide.h"
#include "scene/obj_mesh.h"

using namespace caustica;

namespace {

const float kInf = std::numeric_limits<float>::infinity();

struct Rng {
  std::mt19937 gen;
  explicit Rng(unsigned seed) : gen(seed) {}
  float uniform(float a = 0.0f, float b = 1.0f) { return std::uniform_real_distribution<float>(a, b)(gen); }
  int index(int n) { return std::uniform_int_distribution<int>(0, n - 1)(gen); }
  glm::vec3 inBox(glm::vec3 lo, glm::vec3 hi) { return {uniform(lo.x, hi.x), uniform(lo.y, hi.y), uniform(lo.z, hi.z)}; }
  glm::vec3 onSphere() {
    float z = uniform(-1.0f, 1.0f), phi = uniform(0.0f, 6.2831853f), r = std::sqrt(std::max(0.0f, 1 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }
};

Ray makeRay(glm::vec3 o, glm::vec3 d) {
  Ray r;
  r.origin = o;
  r.dir = glm::normalize(d);
  return r;
}

using test::bruteClosest;  // brute_force.h

// Half random rays through an enlarged bounding box, half aimed at points on random triangles; every
// 13th axis-aligned with exact zeros.
std::vector<Ray> mixedRays(const std::vector<Triangle>& tris, int count, Rng& rng) {
  Bounds b;
  for (const Triangle& t : tris)
    for (const glm::vec3& p : t.p) b.grow(p);
  const glm::vec3 c = 0.5f * (b.min + b.max), h = 0.75f * (b.max - b.min) + 1e-3f;
  std::vector<Ray> rays;
  for (int i = 0; i < count; ++i) {
    const glm::vec3 o = rng.inBox(c - 2.0f * h, c + 2.0f * h);
    if (i % 13 == 0) {
      glm::vec3 d(0.0f);
      d[rng.index(3)] = rng.index(2) ? 1.0f : -1.0f;
      rays.push_back(makeRay(o, d));
    } else if (i % 2 == 0) {
      rays.push_back(makeRay(o, rng.onSphere()));
    } else {
      const Triangle& t = tris[rng.index(int(tris.size()))];
      float u = rng.uniform(), v = rng.uniform();
      if (u + v > 1.0f) u = 1.0f - u, v = 1.0f - v;
      rays.push_back(makeRay(o, t.p[0] + u * (t.p[1] - t.p[0]) + v * (t.p[2] - t.p[0]) - o));
    }
  }
  return rays;
}

std::vector<Triangle> randomSoup(int count, Rng& rng) {
  std::vector<Triangle> tris;
  for (int i = 0; i < count; ++i) {
    const glm::vec3 c = rng.inBox(glm::vec3(-1.0f), glm::vec3(1.0f));
    const float size = std::pow(10.0f, rng.uniform(-3.0f, -0.3f));
    tris.push_back(makeTriangle(c + size * rng.onSphere(), c + size * rng.onSphere(), c + size * rng.onSphere()));
  }
  for (int i = 0; i < count / 10; ++i) {  // exactly degenerate ones: they never hit
    const glm::vec3 p = rng.inBox(glm::vec3(-1.0f), glm::vec3(1.0f));
    tris.push_back(makeTriangle(p, p, rng.inBox(glm::vec3(-1.0f), glm::vec3(1.0f))));
  }
  return tris;
}

// Wide traversal against brute force (closest: same t, u, v; a different triangle only as a tie) and
// against the binary twin; any hit against brute force at several tmax. Returns the disagreements.
int countWideMismatches(const std::vector<Triangle>& tris, const std::vector<Ray>& rays, int* hits,
                        const BvhShape& shape = {}) {
  const Bvh bvh = buildBvh(tris, shape.build);
  const BvhWide wide = packBvhWideNodes(bvh.nodes, shape.collapse);
  const std::vector<gpu::TriGeom> geom = packTriGeom(tris, bvh);
  int bad = 0, found = 0;
  for (const Ray& ray : rays) {
    const Hit a = traceClosest(wide.nodes, geom, ray);
    const Hit b = bruteClosest(geom, ray, kInf);
    const Hit c = traceClosest(bvh.nodes, geom, ray);
    bool ok = a.found() == b.found() && c.found() == a.found();
    if (ok && a.found()) {
      ++found;
      float t, u, v;
      const gpu::TriGeom& g = geom[a.tri];
      const bool self = intersectTriangle(ray, glm::vec3(g.v0), glm::vec3(g.v1), glm::vec3(g.v2), kInf, t, u, v);
      ok = a.t == b.t && a.t == c.t && self && t == a.t && u == a.u && v == a.v;
    }
    const float tOcc[] = {kInf, b.found() ? 0.5f * b.t : 1.0f, b.found() ? 2.0f * b.t : 0.1f};
    for (float tmax : tOcc) ok = ok && traceOccluded(wide.nodes, geom, ray, tmax) == (b.found() && b.t < tmax);
    bad += !ok;
  }
  *hits = found;
  return bad;
}

// Walks the wide tree: every binary leaf must appear exactly once, with its box bit for bit; every
// inner wide node has 2..4 children, each one a binary node's box.
void checkStructure(const Bvh& bvh, const BvhWide& wide) {
  std::map<std::uint32_t, int> leafSeen;  // packed leaf ref -> times seen
  struct Box {
    glm::vec3 lo, hi;
  };
  std::map<std::uint32_t, Box> leafOf;  // every leaf ref of the binary nodes and its box
  for (const gpu::BvhNode& b : bvh.nodes) {
    if ((b.left & gpu::kBvhLeafBit) && b.left != gpu::kBvhEmptyRef) leafOf[b.left] = {b.lmin, b.lmax};
    if ((b.right & gpu::kBvhLeafBit) && b.right != gpu::kBvhEmptyRef) leafOf[b.right] = {b.rmin, b.rmax};
  }
  std::vector<std::uint32_t> work{0};
  std::size_t visited = 0;
  int badBoxes = 0, badCounts = 0;
  while (!work.empty()) {
    const gpu::BvhWideNode& n = wide.nodes.at(work.back());
    work.pop_back();
    ++visited;
    int used = 0;
    for (int k = 0; k < 4; ++k) {
      const std::uint32_t ref = n.child[k];
      if (ref == gpu::kBvhEmptyRef) {
        badBoxes += !(n.minX[k] == kInf && n.maxX[k] == kInf && n.minZ[k] == kInf);
        continue;
      }
      ++used;
      if (ref & gpu::kBvhLeafBit) {
        ++leafSeen[ref];
        const auto it = leafOf.find(ref);
        REQUIRE(it != leafOf.end());
        const Box& b = it->second;
        badBoxes += !(n.minX[k] == b.lo.x && n.minY[k] == b.lo.y && n.minZ[k] == b.lo.z && n.maxX[k] == b.hi.x &&
                      n.maxY[k] == b.hi.y && n.maxZ[k] == b.hi.z);
      } else {
        REQUIRE(ref < wide.nodes.size());
        work.push_back(ref);
      }
    }
    badCounts += (used < 2 && wide.nodes.size() > 1) || used > 4;
  }
  CHECK(visited == wide.nodes.size());  // every node reached once
  CHECK(leafSeen.size() == leafOf.size());
  int twice = 0;
  for (const auto& [ref, times] : leafSeen) twice += times != 1;
  CHECK(twice == 0);
  CHECK(badBoxes == 0);
  CHECK(badCounts == 0);
  CHECK(wide.stackNeed <= CAUSTICA_BVH_WIDE_STACK);
  CHECK(wide.depth <= bvh.depth);
}

// Walks a wide tree of any collapse: every triangle 0..triangleCount-1 in exactly one leaf, leaves of
// 1..maxLeaf triangles, every slot's box containing its subtree's triangles, 2..4 children per node
// (a one-leaf tree: 1), every node reached once, stack need within the traversal's. Returns the mean
// number of children per wide node.
double checkCover(const BvhWide& wide, const std::vector<gpu::TriGeom>& geom, int maxLeaf) {
  std::vector<int> seen(geom.size(), 0);
  std::vector<int> reached(wide.nodes.size(), 0);
  int badBoxes = 0, badLeaves = 0, badCounts = 0, slots = 0;
  // Returns the subtree's triangle bounds; checks each slot's box against them.
  struct Walk {
    const BvhWide& w;
    const std::vector<gpu::TriGeom>& g;
    std::vector<int>& seen;
    std::vector<int>& reached;
    int maxLeaf;
    int &badBoxes, &badLeaves, &badCounts, &slots;
    Bounds node(std::uint32_t index) {
      Bounds all;
      REQUIRE(index < w.nodes.size());
      ++reached[index];
      const gpu::BvhWideNode& n = w.nodes[index];
      int used = 0;
      for (int k = 0; k < 4; ++k) {
        const std::uint32_t ref = n.child[k];
        if (ref == gpu::kBvhEmptyRef) continue;
        ++used;
        Bounds b;
        if (ref & gpu::kBvhLeafBit) {
          const std::uint32_t first = ref & gpu::kBvhFirstMask, count = (ref >> gpu::kBvhCountShift) & 15u;
          badLeaves += count < 1 || int(count) > maxLeaf;
          for (std::uint32_t i = first; i < first + count; ++i) {
            REQUIRE(i < g.size());
            ++seen[i];
            b.grow(glm::vec3(g[i].v0)), b.grow(glm::vec3(g[i].v1)), b.grow(glm::vec3(g[i].v2));
          }
        } else {
          b = node(ref);
        }
        badBoxes += !(n.minX[k] <= b.min.x && n.minY[k] <= b.min.y && n.minZ[k] <= b.min.z && n.maxX[k] >= b.max.x &&
                      n.maxY[k] >= b.max.y && n.maxZ[k] >= b.max.z);
        all.grow(b.min), all.grow(b.max);
      }
      slots += used;
      badCounts += (used < 2 && w.nodes.size() > 1) || used > 4;
      return all;
    }
  } walk{wide, geom, seen, reached, maxLeaf, badBoxes, badLeaves, badCounts, slots};
  walk.node(0);
  CHECK(std::count(seen.begin(), seen.end(), 1) == std::ptrdiff_t(seen.size()));  // every triangle exactly once
  CHECK(std::count(reached.begin(), reached.end(), 1) == std::ptrdiff_t(reached.size()));
  CHECK(badBoxes == 0);
  CHECK(badLeaves == 0);
  CHECK(badCounts == 0);
  CHECK(wide.stackNeed <= CAUSTICA_BVH_WIDE_STACK);
  return double(slots) / double(wide.nodes.size());
}

}  // namespace

TEST_CASE("bvh wide: SAH collapse covers every triangle once, fills the slots, agrees with brute force") {
  const std::vector<Triangle> bunny = loadObjTriangles(sourceDir() + "/assets/meshes/bunny.obj");
  Rng rng(8);
  const std::vector<Triangle> soup = randomSoup(2000, rng);
  const char* specs[] = {"collapse=sah", "collapse=sah,wideleaf=0", "collapse=sah,wideleaf=8,leaf=1",
                         "collapse=sah,wideleaf=4,leaf=2,cl=1,ct=0.5", "collapse=sah,leaf=8,wideleaf=15"};
  for (const std::vector<Triangle>* tris : {&bunny, &soup}) {
    const Bvh greedyBvh = buildBvh(*tris);
    const BvhWide greedy = packBvhWideNodes(greedyBvh.nodes, parseBvhShape("collapse=greedy").collapse);
    const double greedyFill = checkCover(greedy, packTriGeom(*tris, greedyBvh), 4);
    for (const char* spec : specs) {
      const std::string specName = spec;
    CAPTURE(specName);
      const BvhShape shape = parseBvhShape(spec);
      const Bvh bvh = buildBvh(*tris, shape.build);
      const BvhWide wide = packBvhWideNodes(bvh.nodes, shape.collapse);
      const double fill = checkCover(wide, packTriGeom(*tris, bvh), std::max(shape.build.maxLeafSize, shape.collapse.maxLeafSize));
      MESSAGE(specName << ": " << wide.nodes.size() << " wide nodes, " << fill << " children per node (greedy "
                   << greedy.nodes.size() << ", " << greedyFill << "), depth " << wide.depth << ", stack need " << wide.stackNeed);
      if (shape.build.maxLeafSize == 4) CHECK(wide.nodes.size() < greedy.nodes.size());  // the slots are filled better
      int hits = 0;
      CHECK(countWideMismatches(*tris, mixedRays(*tris, 3000, rng), &hits, shape) == 0);
      CHECK(hits > 1000);
    }
  }
}

TEST_CASE("bvh wide: collapse keeps every leaf once, boxes bit for bit, 2-4 children per node") {
  const std::vector<Triangle> bunny = loadObjTriangles(sourceDir() + "/assets/meshes/bunny.obj");
  const Bvh bvh = buildBvh(bunny);
  Rng rng(5);
  const std::vector<Triangle> soup = randomSoup(3000, rng);
  const Bvh soupBvh = buildBvh(soup);
  // The greedy collapse, and the SAH one without merged leaves: both keep the binary leaves as they are.
  for (const char* spec : {"collapse=greedy", "collapse=sah,wideleaf=0"}) {
    const std::string specName = spec;
    CAPTURE(specName);
    const WideCollapseOptions options = parseBvhShape(spec).collapse;
    const BvhWide wide = packBvhWideNodes(bvh.nodes, options);
    checkStructure(bvh, wide);
    // Each wide node stands for up to three binary inner nodes; near the leaves many stand for one or two.
    MESSAGE(specName << ": bunny: " << bvh.nodes.size() << " binary inner nodes, " << wide.nodes.size() << " wide, depth "
                 << bvh.depth << " -> " << wide.depth << ", stack need " << wide.stackNeed);
    CHECK(wide.nodes.size() * 5 < bvh.nodes.size() * 3);
    checkStructure(soupBvh, packBvhWideNodes(soupBvh.nodes, options));
  }
}

TEST_CASE("bvh wide: agrees with brute force and the binary twin (bunny, random soup with degenerates)") {
  const std::vector<Triangle> bunny = loadObjTriangles(sourceDir() + "/assets/meshes/bunny.obj");
  Rng rng(6);
  int hits = 0;
  CHECK(countWideMismatches(bunny, mixedRays(bunny, 12000, rng), &hits) == 0);
  CHECK(hits > 5000);
  const std::vector<Triangle> soup = randomSoup(1500, rng);
  CHECK(countWideMismatches(soup, mixedRays(soup, 15000, rng), &hits) == 0);
  CHECK(hits > 6000);
}

TEST_CASE("bvh wide: empty and single-triangle trees") {
  Rng rng(7);
  {
    const std::vector<Triangle> none;
    const Bvh bvh = buildBvh(none);
    const BvhWide wide = packBvhWideNodes(bvh.nodes);
    REQUIRE(wide.nodes.size() == 1);
    for (int i = 0; i < 100; ++i) {
      const Ray ray = makeRay(rng.inBox(glm::vec3(-1.0f), glm::vec3(1.0f)), rng.onSphere());
      CHECK_FALSE(traceClosest(wide.nodes, {}, ray).found());
      CHECK_FALSE(traceOccluded(wide.nodes, {}, ray, kInf));
    }
  }
  const std::vector<Triangle> one{makeTriangle({0, 0, 0}, {2, 0, 0}, {0, 2, 0})};
  const Bvh bvh = buildBvh(one);
  const BvhWide wide = packBvhWideNodes(bvh.nodes);
  REQUIRE(wide.nodes.size() == 1);
  CHECK(wide.nodes[0].child[0] == (gpu::kBvhLeafBit | 1u << gpu::kBvhCountShift));
  CHECK(wide.nodes[0].child[1] == gpu::kBvhEmptyRef);
  const std::vector<gpu::TriGeom> geom = packTriGeom(one, bvh);
  const Hit hit = traceClosest(wide.nodes, geom, makeRay({0.5f, 0.5f, 3}, {0, 0, -1}));
  CHECK(hit.tri == 0u);
  CHECK(hit.t == 3.0f);
  CHECK_FALSE(traceClosest(wide.nodes, geom, makeRay({0.5f, 0.5f, 3}, {0, 0, 1})).found());
  CHECK_FALSE(traceClosest(wide.nodes, geom, makeRay({0.5f, 0.5f, 3}, {0, 0, -1}), 2.5f).found());
  CHECK(traceOccluded(wide.nodes, geom, makeRay({0.5f, 0.5f, 3}, {0, 0, -1}), 3.5f));
  CHECK_FALSE(traceOccluded(wide.nodes, geom, makeRay({0.5f, 0.5f, 3}, {0, 0, -1}), 2.5f));
}
