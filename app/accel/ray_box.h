// ray_box.h — the ray/box guards shared by the one- and two-level C++ traversals (bvh.cpp, tlas.cpp).
// Twins of safeInverse() and intersectAabb() in glsl/lib/intersect.glsl; distances in units of |dir|.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

namespace caustica::raybox {

constexpr float kDirTiny = 1e-20f;
// Relative widening of a box's exit distance: covers the rounding of the slab distances and of t.
constexpr float kBoxPad = 1.0f + 1.0f / (1 << 20);
constexpr float kBig = 3.0e38f;

// Guarded reciprocal: |d| < 1e-20 becomes +-1e-20 (sign by d >= 0, as in GLSL), so never inf or NaN.
inline glm::vec3 safeInverse(const glm::vec3& d) {
  glm::vec3 r;
  for (int a = 0; a < 3; ++a) {
    const float g = std::fabs(d[a]) < kDirTiny ? (d[a] >= 0.0f ? kDirTiny : -kDirTiny) : d[a];
    r[a] = 1.0f / g;
  }
  return r;
}

// Slab test. tnear: entry distance clamped to >= 0. An exit distance of exactly 0 (origin on a slab
// plane with a guarded ~0 direction component) is treated as "inside" so that rays lying on a box face
// still visit it; this is conservative.
inline bool intersectAabb(const glm::vec3& org, const glm::vec3& invDir, const glm::vec3& bmin,
                          const glm::vec3& bmax, float tmax, float& tnear) {
  const glm::vec3 t0 = (bmin - org) * invDir;
  const glm::vec3 t1 = (bmax - org) * invDir;
  const glm::vec3 lo = glm::min(t0, t1);
  glm::vec3 hi = glm::max(t0, t1);
  for (int a = 0; a < 3; ++a) hi[a] = hi[a] == 0.0f ? kBig : hi[a];
  tnear = std::max(std::max(lo.x, lo.y), std::max(lo.z, 0.0f));
  const float tfar = std::min(std::min(hi.x, hi.y), std::min(hi.z, tmax)) * kBoxPad;
  return tnear <= tfar;
}

}  // namespace caustica::raybox
