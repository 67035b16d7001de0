// tlas_test.cpp — instancing's two-level BVH (app/accel/tlas.*): rays through an instanced scene hit
// what they hit in the same scene flattened (flattenInstances + the one-level BVH).
#include <doctest/doctest.h>

#include <cmath>
#include <random>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "accel/bvh.h"
#include "accel/bvh_traverse.h"
#include "accel/tlas.h"
#include "scene/scene.h"
#include "util/error.h"

namespace {

using namespace caustica;

// Two meshes (a closed-ish blob of random triangles and a quad) placed by rotated, scaled, mirrored
// and translated instances.
Scene instancedScene(std::uint32_t seed, int instances) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Scene s;
  for (int i = 0; i < 300; ++i) {
    const glm::vec3 c(u(rng), u(rng), u(rng));
    s.triangles.push_back(makeTriangle(c, c + 0.2f * glm::vec3(u(rng), u(rng), u(rng)),
                                       c + 0.2f * glm::vec3(u(rng), u(rng), u(rng)), 0));
  }
  s.meshes.push_back({0, 300, 0});
  s.triangles.push_back(makeTriangle({-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, 1));
  s.triangles.push_back(makeTriangle({-1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, 1));
  s.meshes.push_back({300, 2, 1});
  for (Triangle& t : s.triangles) {
    const glm::vec3 n = glm::normalize(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
    for (int k = 0; k < 3; ++k) t.setNormal(k, n);
  }
  for (int i = 0; i < instances; ++i) {
    glm::dmat4 m(1.0);
    m = glm::translate(m, glm::dvec3(4.0 * (i % 4), 4.0 * (i / 4), 0.5 * u(rng)));
    m = glm::rotate(m, 3.0 * double(u(rng)), glm::normalize(glm::dvec3(u(rng), u(rng), u(rng) + 2.0)));
    m = glm::scale(m, glm::dvec3(i % 3 == 0 ? -1.0 : 1.0, 0.5 + 0.5 * (i % 2), 1.0 + 0.25 * (i % 5)));
    s.instances.push_back({std::uint32_t(i % 3 == 2 ? 1 : 0), m});
  }
  return s;
}

}  // namespace

TEST_CASE("two-level BVH: closest and any hits equal the flattened scene's") {
  const Scene inst = instancedScene(7, 16);
  Scene flat = inst;
  flattenInstances(flat);
  REQUIRE(flat.triangles.size() == 11 * 300 + 5 * 2);  // nothing dropped: indices line up
  std::vector<std::uint32_t> prefix;
  std::uint32_t total = 0;
  for (const Instance& in : inst.instances) {
    prefix.push_back(total);
    total += inst.meshes[in.mesh].triangleCount;
  }
  const Bvh flatBvh = buildBvh(flat.triangles);
  const std::vector<gpu::TriGeom> flatTris = packTriGeom(flat.triangles, flatBvh);
  const InstancedBvh two = buildInstancedBvh(inst);
  CHECK(two.tris.size() == 302);  // each mesh once
  CHECK(two.instances.size() == 16);
  CHECK(two.depth < 2 * CAUSTICA_BVH_STACK);

  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int hits = 0, same = 0, mismatched = 0;
  const int kRays = 4000;
  for (int r = 0; r < kRays; ++r) {
    const glm::vec3 target(-2.0f + 16.0f * u(rng), -2.0f + 8.0f * u(rng), -1.5f + 3.0f * u(rng));
    const glm::vec3 origin = target + 20.0f * glm::normalize(glm::vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.2f));
    Ray ray;
    ray.origin = origin;
    ray.dir = glm::normalize(target - origin);
    const Hit a = traceClosest(flatBvh.nodes, flatTris, ray);
    const InstancedHit b = traceClosest(two, ray);
    CHECK(traceOccluded(two, ray, 1e30f) == b.hit.found());
    if (a.found() != b.hit.found()) {
      ++mismatched;  // a grazing ray through a shared edge may go either way after rounding
      continue;
    }
    if (!a.found()) continue;
    ++hits;
    CHECK(std::abs(a.t - b.hit.t) <= 1e-4f * a.t);
    const std::uint32_t source = two.triSource[b.hit.tri];
    const std::uint32_t flatIndex = prefix[b.instance] + (source - inst.meshes[inst.instances[b.instance].mesh].firstTriangle);
    if (flatBvh.order[a.tri] == flatIndex) ++same;
    if (traceOccluded(two, ray, 0.5f * a.t) != traceOccluded(flatBvh.nodes, flatTris, ray, 0.5f * a.t)) ++mismatched;
  }
  MESSAGE("rays hitting: ", hits, ", same triangle: ", same, ", mismatched: ", mismatched);
  CHECK(hits > kRays / 10);
  CHECK(same >= hits - hits / 200);     // ties between overlapping triangles may resolve differently
  CHECK(mismatched <= kRays / 500);
}

TEST_CASE("two-level BVH: a scene without instances is refused; one mesh many times costs one mesh") {
  Scene plain;
  plain.triangles.push_back(makeTriangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  CHECK_THROWS_AS(buildInstancedBvh(plain), Error);
  const Scene inst = instancedScene(3, 64);
  const InstancedBvh two = buildInstancedBvh(inst);
  CHECK(two.tris.size() == 302);
  CHECK(two.nodes.size() < 63 + 2 * 302);  // top level (one leaf per instance) + the meshes' trees
}
