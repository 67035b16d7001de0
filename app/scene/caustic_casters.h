// casters.h — finds a scene's caustic casters: bounding spheres of its connected glass and mirror
// objects, which the mis integrator aims diffuse bounces at (glsl/lib/casters.glsl).
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace caustica {

struct CausticCaster {
  glm::vec4 sphere;  // xyz centre, w radius (world space, scene units)
  bool refractive;   // some triangle in it transmits (glass); else mirrors only
  bool operator==(const CausticCaster& o) const { return sphere == o.sphere && refractive == o.refractive; }
};

// Bounding spheres of the connected components of triangles whose material reflects or refracts
// specularly (metallic > 0 or transmission > 0). Objects whose sphere is wider than a quarter of the
// scene's diagonal (a mirror wall, say) are left out: aiming at them is no better than cosine
// sampling. At most maxCasters spheres: when there are more objects, neighbours along the widest
// axis are grouped and each group gets one sphere.
std::vector<CausticCaster> findCausticCasters(const Scene& scene, int maxCasters);

// How far (radians) beyond the lights' cone a refractive caster's cone may lie and still be aimed at.
constexpr float kCasterLightMargin = 0.0f;

// A sphere around every emissive triangle (xyz centre, w radius); w = -1 when nothing emits.
glm::vec4 emitterBoundingSphere(const Scene& scene);

}  // namespace caustica
