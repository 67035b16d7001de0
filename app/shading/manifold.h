// manifold.h — C++ twins of the arithmetic of glsl/lib/manifold.glsl (manifold next-event estimation):
// ray differentials carried through the specular events of a caster chain (transfer to a surface,
// refraction, reflection, the derivative of an interpolated shading normal) and the direction
// parameters of the Newton solve. Same names, same arithmetic. World space; directions unit.
#pragma once
#include <glm/glm.hpp>

namespace caustica {

// The derivative of a hit's unit shading normal as the hit point moves in the triangle's plane
// (normalDiffOn): barycentric gradients gu, gv, vertex-normal differences dn1, dn2 and the sign of the
// shading normal over the interpolated normal's length (0: no interpolated normal, constant).
struct NormalDiff {
  glm::vec3 gu{0.0f}, gv{0.0f}, dn1{0.0f}, dn2{0.0f};
  float scale = 0.0f;
};
// Triangle p0, p1, p2 with vertex normals n0, n1, n2, hit at barycentrics (u, v) of p1, p2; ns the unit
// shading normal there (either side).
NormalDiff normalDiffOn(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2, const glm::vec3& n0,
                        const glm::vec3& n1, const glm::vec3& n2, float u, float v, const glm::vec3& ns);
glm::vec3 normalDerivative(const NormalDiff& nd, const glm::vec3& ns, const glm::vec3& dp);
// The change of the hit point on the plane (normal ng) that the ray (unit d) meets at distance t, for
// a change dO of its origin and dD of its direction (Igehy 1999).
glm::vec3 transferDiff(const glm::vec3& dO, const glm::vec3& dD, const glm::vec3& d, float t, const glm::vec3& ng);
// Refraction of unit d through unit n (facing against d), r = n_incident / n_transmitted, with the
// direction's differential dD and the normal's dN (and a second pair dD2, dN2). False on total
// internal reflection (or d arriving from behind n).
bool refractDiff(const glm::vec3& d, const glm::vec3& n, float r, glm::vec3& dOut, const glm::vec3& dD,
                 const glm::vec3& dN, glm::vec3& dDOut, const glm::vec3& dD2, const glm::vec3& dN2, glm::vec3& dDOut2);
// The differential of reflect(d, n) for differentials dD of d and dN of n.
glm::vec3 reflectDiff(const glm::vec3& d, const glm::vec3& n, const glm::vec3& dD, const glm::vec3& dN);
// Gnomonic direction parameters about a unit axis (orthonormalBasis frame): w = normalize(axis + a t + b b).
glm::vec3 manifoldDirection(const glm::vec3& axis, const glm::vec2& ab);
glm::vec2 manifoldParams(const glm::vec3& axis, const glm::vec3& w);

}  // namespace caustica
