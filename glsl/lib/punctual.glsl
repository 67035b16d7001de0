// punctual.glsl — next-event estimation of KHR_lights_punctual lights (PunctualParams UBO,
// gpu_layout.h): one light chosen by power, its own shadow ray; delta lights, so no MIS.
// Units: intensity as radiance x area (point, spot: irradiance I / d^2), directional as irradiance.

// glTF's recommended smooth spot falloff: 0 outside the outer cone, 1 inside the inner one, a
// squared linear ramp in cos(angle) between. Twin of spotFalloff in app/scene/punctual_lights.cpp.
float spotFalloff(float cosTheta, float cosOuter, float cosInner) {
  float scale = 1.0 / max(1.0e-3, cosInner - cosOuter);
  float t = clamp((cosTheta - cosOuter) * scale, 0.0, 1.0);
  return t * t;
}

#ifdef CAUSTICA_PUNCTUAL
layout(std140, binding = CAUSTICA_BINDING_PUNCTUAL) uniform PunctualBlock { PunctualParams punctual; };

// The light whose cumulative selection probability first exceeds u (binary search; u in [0, 1)).
uint pickPunctualLight(float u) {
  uint lo = 0u, hi = punctual.count.x - 1u;
  if (lo < hi) do {  // bottom-tested: no extra masked step at the end (environment.glsl, sampleEnvironment)
    uint mid = (lo + hi) / 2u;
    if (u < punctual.light[mid].select.y) hi = mid;
    else lo = mid + 1u;
  } while (lo < hi);
  return lo;
}

// Chooses one punctual light for a vertex at p (error bound pError, geometric normal ng on the side
// the path is on) and traces its shadow ray. On success: wi, the unit direction towards the light,
// and li, the radiance it delivers along wi divided by the probability of choosing it (a delta
// distribution in direction: the caller multiplies by the BSDF value and cos at wi, no pdf), and
// dist, the distance to the light (3e38 for a directional light). False if it is occluded, behind
// the surface or outside a spot's cone. shadowRays counts the shadow rays traced.
bool samplePunctualLight(vec3 p, vec3 pError, vec3 ng, float u, out vec3 wi, out vec3 li, out float dist,
                         inout uint shadowRays) {
  wi = vec3(0.0);
  li = vec3(0.0);
  dist = 0.0;
  if (punctual.count.x == 0u) return false;
  PunctualLight l = punctual.light[pickPunctualLight(u)];
  uint type = uint(l.position.w);
  vec3 from = offsetRayOrigin(p, pError, ng);
  if (type == kPunctualDirectional) {
    wi = -l.direction.xyz;
    dist = 3.0e38;
    li = l.intensity.rgb;  // irradiance on a surface facing the light
  } else {
    vec3 toLight = l.position.xyz - from;
    float d2 = dot(toLight, toLight);
    if (!(d2 > 0.0)) return false;
    dist = sqrt(d2);
    wi = toLight / dist;
    li = l.intensity.rgb / d2;
    if (type == kPunctualSpot) li *= spotFalloff(dot(-wi, l.direction.xyz), l.direction.w, l.intensity.w);
  }
  if (dot(ng, wi) <= 0.0 || maxComponent(li) <= 0.0) return false;
  li /= l.select.x;
  ++shadowRays;
  return !traceOccluded(from, wi, type == kPunctualDirectional ? 3.0e38 : dist * (1.0 - 1.0e-4));
}
#endif

#ifdef CAUSTICA_SPOT_EMITTERS
// Emission factor of a --light-radius sphere made from a spot light (kMatSpotEmitter), for light
// leaving it in the unit direction wo: the spot's falloff, so that the sphere's far field is the spot's.
float spotEmitterFactor(Material m, vec3 wo) {
  if ((m.tex.z & kMatSpotEmitter) == 0u) return 1.0;
  return spotFalloff(dot(wo, m.absorption.xyz), m.absorption.w, m.emission.w);
}
#endif
