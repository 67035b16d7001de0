// ray_box.h — the ray/box guards and the binary node visit shared by the one- and two-level C++ traversals
// (bvh_traverse.cpp, tlas.cpp).
// Twins of safeInverse() and intersectAabb() in glsl/lib/intersect.glsl; distances in units of |dir|.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>

#include "shared/gpu_layout.h"

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

// One binary node's two child boxes against the ray (world or object space; t in units of |dir|):
// `near` is the child to visit next, `far` (entry distance `farT`) the other; returns how many were
// entered (0, 1: only `near`, or 2). Twin of bvhVisitNode() in glsl/lib/traverse.glsl.
inline int bvhVisitNode(const gpu::BvhNode& node, const glm::vec3& org, const glm::vec3& invDir, float tmax,
                        std::uint32_t& near, std::uint32_t& far, float& farT) {
  float tl, tr;
  const bool hl = intersectAabb(org, invDir, node.lmin, node.lmax, tmax, tl);
  const bool hr = intersectAabb(org, invDir, node.rmin, node.rmax, tmax, tr);
  const bool leftFirst = hl && (!hr || tl <= tr);
  near = leftFirst ? node.left : node.right;
  far = leftFirst ? node.right : node.left;
  farT = leftFirst ? tr : tl;
  return int(hl) + int(hr);
}

}  // namespace caustica::raybox
