// intersect.cpp — C++ twin of the watertight ray-triangle test in glsl/lib/intersect.glsl and of its
// leaf loop; positions and distances in world (or object) space, t in units of |ray.dir|.
#include "accel/intersect.h"

#include <algorithm>
#include <cmath>

#include "accel/spawn.h"

namespace caustica {

bool isZeroAreaTriangle(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2) {
  const glm::vec3 n = glm::cross(p1 - p0, p2 - p0);
  return n.x == 0.0f && n.y == 0.0f && n.z == 0.0f;
}

void packedTrianglePositions(const glm::vec3* p, glm::vec3& q0, glm::vec3& q1, glm::vec3& q2) {
  const bool point = isZeroAreaTriangle(p[0], p[1], p[2]);
  q0 = p[0];
  q1 = point ? p[0] : p[1];
  q2 = point ? p[0] : p[2];
}

namespace {

// Cyclic permutation that moves axis kz to z (keeps handedness; both faces are accepted anyway).
inline glm::vec3 permuteToKz(const glm::vec3& a, int kz) {
  return kz == 0 ? glm::vec3(a.y, a.z, a.x) : (kz == 1 ? glm::vec3(a.z, a.x, a.y) : a);
}

}  // namespace

RayShear makeRayShear(const glm::vec3& dir) {
  const glm::vec3 ad = glm::abs(dir);
  RayShear s;
  s.kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  const glm::vec3 d = permuteToKz(dir, s.kz);
  s.sz = d.z == 0.0f ? 0.0f : 1.0f / d.z;
  s.sx = -d.x * s.sz;
  s.sy = -d.y * s.sz;
  return s;
}

// Woop, Benthin, Wald 2013 ("Watertight ray/triangle intersection"), in the form of pbrt-v4's
// IntersectTriangle: translate to the ray origin, permute so the largest direction component is z,
// shear so the ray is +z, then 2D edge functions. Shared edges give exactly negated edge functions,
// so no ray passes between two triangles. Exactly zero edge functions are recomputed in double.
bool intersectTriangleSheared(const glm::vec3& origin, const RayShear& rs, const glm::vec3& p0, const glm::vec3& p1,
                              const glm::vec3& p2, float tmax, float& t, float& u, float& v) {
  if (rs.sz == 0.0f) return false;  // zero direction
  const float sx = rs.sx, sy = rs.sy, sz = rs.sz;
  const int kz = rs.kz;

  const glm::vec3 a = permuteToKz(p0 - origin, kz);
  const glm::vec3 b = permuteToKz(p1 - origin, kz);
  const glm::vec3 c = permuteToKz(p2 - origin, kz);
  const float ax = a.x + sx * a.z, ay = a.y + sy * a.z;
  const float bx = b.x + sx * b.z, by = b.y + sy * b.z;
  const float cx = c.x + sx * c.z, cy = c.y + sy * c.z;

  float e0 = bx * cy - by * cx;  // edge function opposite p0 (weight of p0)
  float e1 = cx * ay - cy * ax;  // opposite p1
  float e2 = ax * by - ay * bx;  // opposite p2
  if (e0 == 0.0f || e1 == 0.0f || e2 == 0.0f) {  // products of floats are exact in double
    e0 = float(double(bx) * double(cy) - double(by) * double(cx));
    e1 = float(double(cx) * double(ay) - double(cy) * double(ax));
    e2 = float(double(ax) * double(by) - double(ay) * double(bx));
  }
  if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f)) return false;
  const float det = e0 + e1 + e2;
  if (det == 0.0f) return false;  // ray in the triangle's plane
  // Zero-area triangles can pass the test above once their vertices are rounded in ray space (in a
  // scratch search the t error bound below then rejected every one, docs/architecture.md "Traversal",
  // but that is not proven). The GLSL twin has no such check: packedTrianglePositions stores them as
  // one point, which det == 0 rejects; this check keeps the reference right for any vertices.
  if (isZeroAreaTriangle(p0, p1, p2)) return false;

  const float az = sz * a.z, bz = sz * b.z, cz = sz * c.z;
  const float tScaled = e0 * az + e1 * bz + e2 * cz;
  const float invDet = 1.0f / det;
  const float tt = tScaled * invDet;
  if (!(tt > 0.0f && tt < tmax)) return false;  // also rejects NaN
  // t must be conservatively positive: beyond the bound of its own rounding error (pbrt-v4), so a
  // ray spawned past a hit point's error box never re-hits the surface it leaves. Like pbrt-v4's,
  // this bound is right for unit-length directions only (it mixes units of t with world units):
  // every caller normalises (a short unnormalised shadow ray lost real occluders at 1e-4 scale).
  const float maxZt = std::max(std::fabs(az), std::max(std::fabs(bz), std::fabs(cz)));
  const float maxXt = std::max(std::fabs(ax), std::max(std::fabs(bx), std::fabs(cx)));
  const float maxYt = std::max(std::fabs(ay), std::max(std::fabs(by), std::fabs(cy)));
  const float deltaZ = gammaBound(3) * maxZt;
  const float deltaX = gammaBound(5) * (maxXt + maxZt);
  const float deltaY = gammaBound(5) * (maxYt + maxZt);
  const float deltaE = 2.0f * (gammaBound(2) * maxXt * maxYt + deltaY * maxXt + deltaX * maxYt);
  const float maxE = std::max(std::fabs(e0), std::max(std::fabs(e1), std::fabs(e2)));
  const float deltaT = 3.0f * (gammaBound(3) * maxE * maxZt + deltaE * maxZt + deltaZ * maxE) * std::fabs(invDet);
  if (tt <= deltaT) return false;
  t = tt;
  u = e1 * invDet;
  v = e2 * invDet;
  return true;
}

bool intersectLeaf(const std::vector<gpu::TriGeom>& tris, std::uint32_t ref, const glm::vec3& origin,
                   const RayShear& rs, bool anyHit, float& closest, Hit& hit) {
  const std::uint32_t first = ref & gpu::kBvhFirstMask;
  const std::uint32_t count = (ref >> gpu::kBvhCountShift) & 15u;
  bool found = false;
  for (std::uint32_t i = first; i < first + count; ++i) {
    const gpu::TriGeom& g = tris[i];
    float t, u, v;
    if (intersectTriangleSheared(origin, rs, glm::vec3(g.v0), glm::vec3(g.v1), glm::vec3(g.v2), closest, t, u, v)) {
      closest = t;
      hit.t = t;
      hit.u = u;
      hit.v = v;
      hit.tri = i;
      found = true;
      if (anyHit) break;
    }
  }
  return found;
}

bool intersectTriangle(const Ray& ray, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                       float tmax, float& t, float& u, float& v) {
  return intersectTriangleSheared(ray.origin, makeRayShear(ray.dir), p0, p1, p2, tmax, t, u, v);
}

}  // namespace caustica
