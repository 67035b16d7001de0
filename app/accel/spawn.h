// spawn.h — C++ twins of glsl/lib/spawn.glsl: conservative error bounds of hit points and ray origins
// moved just past them, so a spawned ray never re-hits its own surface (world space, scene units).
#pragma once
#include <glm/glm.hpp>

namespace caustica {

// gamma(n) = n u / (1 - n u), u = 2^-24: bound on the relative error of n chained float operations.
float gammaBound(int n);
// Absolute error bound, per axis, of the point b0 p0 + b1 p1 + b2 p2 computed in float.
glm::vec3 hitPointError(float b0, float b1, float b2, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2);
float nextFloatUp(float v);
float nextFloatDown(float v);
// Moves p (error bound pError) along the unit normal n (pointing to the side the ray leaves into)
// past the error box and one float step further.
glm::vec3 offsetRayOrigin(const glm::vec3& p, const glm::vec3& pError, const glm::vec3& n);

}  // namespace caustica
