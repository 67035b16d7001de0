// brute_force.h — the reference the traversal tests compare against: every triangle tested with the
// same watertight routine, the closest hit kept (shared by bvh_test and bvh_wide_test).
#pragma once

#include <vector>

#include "accel/bvh.h"
#include "accel/intersect.h"

namespace caustica::test {

// Closest hit over all of `tris` (TriGeom order) with 0 < t < tmax.
inline Hit bruteClosest(const std::vector<gpu::TriGeom>& tris, const Ray& ray, float tmax) {
  Hit best;
  float closest = tmax;
  for (std::uint32_t i = 0; i < tris.size(); ++i) {
    float t, u, v;
    if (intersectTriangle(ray, glm::vec3(tris[i].v0), glm::vec3(tris[i].v1), glm::vec3(tris[i].v2), closest, t, u, v)) {
      closest = t;
      best.t = t;
      best.u = u;
      best.v = v;
      best.tri = i;
    }
  }
  return best;
}

}  // namespace caustica::test
