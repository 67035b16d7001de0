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
  // Some triangle in it has a delta (smooth) lobe: roughness^2 below the shaders' kDeltaAlpha.
  bool smooth = false;
  // The emitters' summed solid angle seen from the sphere's centre (steradians, emitting sides only;
  // rateCastersForManifold).
  float emitterSolidAngle = 0.0f;
  // --manifold auto joins light through it (manifoldAutoEligible); set by rateCastersForManifold.
  bool manifoldAuto = false;
  bool operator==(const CausticCaster& o) const {
    return sphere == o.sphere && refractive == o.refractive && smooth == o.smooth &&
           emitterSolidAngle == o.emitterSolidAngle && manifoldAuto == o.manifoldAuto;
  }
};

// Bounding spheres of the connected components of triangles whose material reflects or refracts
// specularly (metallic > 0 or transmission > 0). Objects whose sphere is wider than a quarter of the
// scene's diagonal (a mirror wall, say) are left out: aiming at them is no better than cosine
// sampling. At most maxCasters spheres: when there are more objects, neighbours along the widest
// axis are grouped and each group gets one sphere.
std::vector<CausticCaster> findCausticCasters(const Scene& scene, int maxCasters);

// --manifold auto's rule (docs/path-tracer.md, "Manifold next-event estimation"): manifold NEE pays
// where the emitters a caster focuses are small as seen from it, since then the bounce through the
// caster rarely reaches them; under a large lamp caster aiming already finds the caustic and the
// Newton solve only costs. A caster qualifies when it is smooth and the emitters' summed solid angle
// seen from its centre is positive and below kManifoldAutoSolidAngle (steradians), chosen by measurement.
constexpr float kManifoldAutoSolidAngle = 0.015f;
bool manifoldAutoEligible(const CausticCaster& c);

// Sets each caster's emitterSolidAngle (from the emissive triangles of `emitters`, each counted from
// the side it emits to: both for a double-sided material) and manifoldAuto.
void rateCastersForManifold(std::vector<CausticCaster>& casters, const Scene& emitters);

// The solid angle (steradians) triangle abc subtends at the origin (Van Oosterom and Strackee 1983).
float triangleSolidAngle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);

// How far (radians) beyond the lights' cone a refractive caster's cone may lie and still be aimed at.
constexpr float kCasterLightMargin = 0.0f;

// A sphere around every emissive triangle (xyz centre, w radius); w = -1 when nothing emits.
glm::vec4 emitterBoundingSphere(const Scene& scene);

}  // namespace caustica
