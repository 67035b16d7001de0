// intersect.h — C++ twin of the watertight ray-triangle test in glsl/lib/intersect.glsl (the ray's shear,
// one triangle, one BVH leaf) and the rule for what a TriGeom stores of a zero-area triangle. World or
// object space; t in units of |ray.dir|.
#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "shared/gpu_layout.h"

namespace caustica {

struct Ray {
  glm::vec3 origin{0.0f};
  glm::vec3 dir{0.0f, 0.0f, 1.0f};  // unit length for a trustworthy hit (intersectTriangle's t bound); t in units of |dir|
};

struct Hit {
  float t = std::numeric_limits<float>::infinity();
  float u = 0.0f, v = 0.0f;  // barycentrics of p1 and p2
  std::uint32_t tri = gpu::kInvalidIndex;  // index in TriGeom (leaf) order
  bool found() const { return tri != gpu::kInvalidIndex; }
};

// True when cross(p1 - p0, p2 - p0), computed in float, is exactly 0: a triangle that never hits.
bool isZeroAreaTriangle(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2);
// The positions a TriGeom stores for triangle p[3]: p itself, or, for a zero-area triangle, p[0] three
// times (the GLSL triangle test has no zero-area check: a point is rejected by its det == 0, see
// intersect.glsl). Every packer of TriGeom goes through this.
void packedTrianglePositions(const glm::vec3* p, glm::vec3& q0, glm::vec3& q1, glm::vec3& q2);

// The ray-only part of the watertight test: the axis permuted to z and the shear onto +z. Twin of
// RayShear/makeRayShear() in intersect.glsl; the traversal computes it once per ray.
struct RayShear {
  int kz = 2;       // axis of the largest |dir| component
  float sx = 0.0f;  // -d.x / d.z of the permuted direction
  float sy = 0.0f;  // -d.y / d.z
  float sz = 0.0f;  // 1 / d.z (0 for a zero direction: nothing hits)
};
RayShear makeRayShear(const glm::vec3& dir);

// intersectTriangle with the ray's shear precomputed. Twin of intersectTriangleSheared() in intersect.glsl,
// which has no zero-area test of its own (it relies on packedTrianglePositions; the same hits on
// packed TriGeom, see there) and is written as straight-line code for llvmpipe (the same decisions).
bool intersectTriangleSheared(const glm::vec3& origin, const RayShear& rs, const glm::vec3& p0, const glm::vec3& p1,
                              const glm::vec3& p2, float tmax, float& t, float& u, float& v);

// The triangles of one leaf (`ref`: first | count << kBvhCountShift) against a sheared ray, as the C++
// traversals (one-level, 4-wide, two-level) test a leaf: each hit nearer than `closest` becomes `hit`
// and the new `closest`; with anyHit the first hit ends the test. Returns whether any triangle was hit.
bool intersectLeaf(const std::vector<gpu::TriGeom>& tris, std::uint32_t ref, const glm::vec3& origin,
                   const RayShear& rs, bool anyHit, float& closest, Hit& hit);

// Watertight ray-triangle test (Woop, Benthin, Wald 2013). Twin of intersectTriangle() in intersect.glsl.
// Returns true and fills t,u,v when the ray hits with 0 < t < tmax.
bool intersectTriangle(const Ray& ray, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                       float tmax, float& t, float& u, float& v);

}  // namespace caustica
