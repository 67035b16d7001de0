// whitted.comp — the Whitted ray tracer (render mode "whitted", docs/render-modes.md): Phong shading
// from the point lights (point_lights.glsl) with sharp shadow rays, recursive mirror reflection and
// glass refraction with Fresnel weights and total internal reflection, no global illumination.
// One jittered eye ray per pixel per dispatch (anti-aliasing by accumulation); radiance is linear.
#include "lib/bindings.glsl"
#include "lib/rng.glsl"
#include "lib/sampling.glsl"
#include "lib/spawn.glsl"
#include "lib/intersect.glsl"
bool whittedOccluder(uint material);  // below: emitters do not occlude in this mode
#define CAUSTICA_OCCLUDER_FILTER(tri, material) whittedOccluder(material)
#include "lib/traverse.glsl"
#include "lib/camera.glsl"
#include "lib/textures.glsl"
#include "lib/microfacet.glsl"
#include "lib/materials.glsl"
#include "lib/point_lights.glsl"
#include "lib/surface.glsl"
#include "lib/accumulate.glsl"
#ifdef CAUSTICA_TRANSPARENT
#include "lib/coverage.glsl"
#endif
#include "lib/adaptive.glsl"

layout(local_size_x = CAUSTICA_WORKGROUP_X, local_size_y = CAUSTICA_WORKGROUP_Y) in;

shared uint groupCounts[4];  // primary, secondary, shadow rays, non-finite samples

uint gSecondaryRays = 0u;
uint gShadowRays = 0u;

// The recursion as an explicit stack of pending rays, each with the weight it contributes with.
// Depth is capped at kWhittedMaxDepth (and the --max-depth setting) and the rays of one sample at
// kWhittedMaxRays: llvmpipe caps a shader's nested loop iterations (docs/architecture.md).
const uint kWhittedStack = 16u;
const uint kWhittedMaxDepth = 8u;
const uint kWhittedMaxRays = 32u;
const float kWhittedMinWeight = 1.0e-3;  // rays that would add less than this fraction are dropped

struct PendingRay {
  vec3 org;
  vec3 dir;
  vec3 weight;  // throughput from the camera (per channel)
  vec3 sigma;   // absorption coefficient of the medium it travels in (per scene unit)
  uint depth;   // segments before it
};
PendingRay gStack[kWhittedStack];
uint gSp = 0u;

void pushRay(vec3 org, vec3 dir, vec3 weight, vec3 sigma, uint depth) {
  if (gSp < kWhittedStack && maxComponent(weight) > kWhittedMinWeight) {
    gStack[gSp] = PendingRay(org, dir, weight, sigma, depth);
    ++gSp;
  }
}

// Any hit with 0 < t < tmax that is not an emitter: the point lights stand in for the emissive
// triangles, which therefore cast no shadows (a light's centre may lie inside its closed mesh).
// traceOccluded with whittedOccluder as its filter (traverse.glsl, CAUSTICA_OCCLUDER_FILTER).
// material: the tested triangle's TriGeom.v0.w, fetched with its positions.
bool whittedOccluder(uint material) { return !isEmissive(materialAt(material)); }
bool occludedByNonEmitter(vec3 org, vec3 dir, float tmax) { return traceOccluded(org, dir, tmax); }

// Direct light from every point light at p, with a sharp shadow ray each (radiance towards wv).
vec3 directLight(vec3 p, vec3 pError, vec3 ng, vec3 ns, vec3 wv, vec3 base, float roughness, vec3 sigma) {
  vec3 sum = vec3(0.0);
  vec3 from = offsetRayOrigin(p, pError, ng);
  for (uint i = 0u; i < pointLights.count.x; ++i) {
    PointLight l = pointLights.light[i];
    vec3 toLight = l.position.xyz - p;
    float dist2 = dot(toLight, toLight);
    if (!(dist2 > 0.0)) continue;
    float dist = sqrt(dist2);
    vec3 wl = toLight / dist;
    float cosSurf = dot(ns, wl);
    if (cosSurf <= 0.0 || dot(ng, wl) <= 0.0) continue;
    vec3 intensity = pointLightIntensity(l, -wl);
    if (!(maxComponent(intensity) > 0.0)) continue;
    ++gShadowRays;
    vec3 seg = l.position.xyz - from;
    float segLen = length(seg);
    if (segLen > 0.0 && occludedByNonEmitter(from, seg / segLen, segLen * (1.0 - 1.0e-4))) continue;
    vec3 transmittance = vec3(1.0);
#ifdef CAUSTICA_VOLUME
    transmittance = exp(-sigma * dist);
#endif
    sum += phongBrdf(base, roughness, ns, wl, wv) * intensity * (cosSurf / dist2) * transmittance;
  }
  return sum;
}

vec3 traceWhitted(uvec2 pixel, inout uvec4 rng) {
  gSp = 0u;
  vec3 eyeOrg, eyeDir;
  eyeRay(pixel, rand2(rng), eyeOrg, eyeDir);
  pushRay(eyeOrg, eyeDir, vec3(1.0), vec3(0.0), 0u);
  uint maxDepth = min(frame.options.x, kWhittedMaxDepth);
  vec3 radiance = vec3(0.0);
  for (uint rays = 0u; rays < kWhittedMaxRays && gSp > 0u; ++rays) {
    PendingRay r = gStack[--gSp];
    if (rays > 0u) ++gSecondaryRays;
    Hit hit;
    if (!traceClosest(r.org, r.dir, 3.0e38, hit)) {
#ifdef CAUSTICA_TRANSPARENT
      if (rays == 0u) gCameraRayMissed = true;  // the eye ray: alpha 0 for this sample (coverage.glsl)
#endif
      continue;
    }
    vec3 w = r.weight;
#ifdef CAUSTICA_VOLUME
    w *= exp(-r.sigma * hit.t);
#endif
    Surface sf;
    if (!surfaceAt(hit, r.dir, false, sf)) continue;  // surface.glsl (Phong shading takes no normal map)

    vec4 base = materialBaseColor(sf.m, sf.uv, sf.color);
    float alpha = 1.0;
#ifdef CAUSTICA_OPACITY
    alpha = base.a;
    if (alpha < 1.0) pushRay(offsetRayOrigin(sf.p, sf.pError, -sf.ng), r.dir, w * (1.0 - alpha), r.sigma, r.depth);
#endif
#ifdef CAUSTICA_CLEARCOAT
    // The clear coat: a mirror reflection about the coat normal with its Fresnel weight; the material
    // below gets the rest (the sheen is not drawn in this mode).
    float coatWeight = alpha * materialCoat(sf.m, sf.uv).x * coatFresnel(dot(r.dir, sf.nc));
    if (r.depth + 1u < maxDepth && coatWeight > 0.0) {
      vec3 rc = reflect(r.dir, sf.nc);
      if (dot(rc, sf.ng) <= 0.0) rc = reflect(r.dir, sf.ng);
      pushRay(offsetRayOrigin(sf.p, sf.pError, sf.ng), rc, w * coatWeight, r.sigma, r.depth + 1u);
    }
    w *= 1.0 - coatWeight;
#endif
    if (surfaceEmits(sf)) radiance += w * alpha * materialEmission(sf.m, sf.uv);  // present with its opacity
    float metal = 0.0, trans = 0.0;
#ifdef CAUSTICA_MIRROR
    metal = sf.m.params.x;
#endif
#ifdef CAUSTICA_GLASS
    trans = materialTransmission(sf.m, sf.uv);
#endif
    float diffuseWeight = alpha * (1.0 - metal) * (1.0 - trans);
    if (diffuseWeight > 0.0)
      radiance += w * diffuseWeight * directLight(sf.p, sf.pError, sf.ng, sf.ns, -r.dir, base.rgb, phongRoughness(sf.m), r.sigma);
    if (r.depth + 1u >= maxDepth) continue;
#ifdef CAUSTICA_MIRROR
    if (metal > 0.0) {
      vec3 rd = reflect(r.dir, sf.ns);
      if (dot(rd, sf.ng) <= 0.0) rd = reflect(r.dir, sf.ng);
      pushRay(offsetRayOrigin(sf.p, sf.pError, sf.ng), rd, w * alpha * metal * base.rgb, r.sigma, r.depth + 1u);
    }
#endif
#ifdef CAUSTICA_GLASS
    float glassWeight = alpha * (1.0 - metal) * trans;
    if (glassWeight > 0.0) {
      float eta = sf.front ? sf.m.params.w : 1.0 / sf.m.params.w;  // n_transmitted / n_incident (at 587.6 nm)
      vec3 n = sf.ns;
      float cosI = -dot(r.dir, n);
      float f = fresnelDielectric(cosI, eta);
      vec3 rt;
      bool refracted = f < 1.0 && refractDir(r.dir, n, 1.0 / eta, rt) && dot(rt, sf.ng) < 0.0;
      if (!refracted) f = 1.0;  // total internal reflection (or a misleading shading normal)
      vec3 rr = reflect(r.dir, n);
      if (dot(rr, sf.ng) <= 0.0) rr = reflect(r.dir, sf.ng);
      pushRay(offsetRayOrigin(sf.p, sf.pError, sf.ng), rr, w * glassWeight * f, r.sigma, r.depth + 1u);
      if (refracted) {
        vec3 sigmaInside = vec3(0.0);
#ifdef CAUSTICA_VOLUME
        sigmaInside = mediumBeyond(sf);
#endif
        // Radiance is compressed by eta^2 entering a denser medium (as in the path tracer).
        pushRay(offsetRayOrigin(sf.p, sf.pError, -sf.ng), rt, w * glassWeight * (1.0 - f) * base.rgb / (eta * eta), sigmaInside,
                r.depth + 1u);
      }
    }
#endif
  }
  return radiance;
}

void main() {
  uvec2 pixel;
  bool valid = dispatchedPixel(pixel);  // adaptive.glsl: rows of frame.tile, or a live tile
  if (gl_LocalInvocationIndex == 0u) {
    groupCounts[0] = 0u;
    groupCounts[1] = 0u;
    groupCounts[2] = 0u;
    groupCounts[3] = 0u;
  }
  memoryBarrierShared();
  barrier();
  uint primary = 0u, bad = 0u;
  if (valid) {
    uvec4 rng = rngSeed(pixel.y * frame.frame.x + pixel.x, frame.frame.z, frame.frame.w);
    vec3 l = traceWhitted(pixel, rng);
    primary = 1u;
    bool finite = !(any(isnan(l)) || any(isinf(l)));
    if (!finite) bad = 1u;
    accumulate(ivec2(pixel), finite ? l : vec3(0.0), finite ? 1.0 : 0.0);
#ifdef CAUSTICA_TRANSPARENT
    accumulateCoverage(ivec2(pixel), finite && !gCameraRayMissed ? 1.0 : 0.0);
#endif
  }
  atomicAdd(groupCounts[0], primary);
  atomicAdd(groupCounts[1], gSecondaryRays);
  atomicAdd(groupCounts[2], gShadowRays);
  atomicAdd(groupCounts[3], bad);
  memoryBarrierShared();
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    atomicAdd(counters.primaryRays, groupCounts[0]);
    atomicAdd(counters.secondaryRays, groupCounts[1]);
    atomicAdd(counters.shadowRays, groupCounts[2]);
    atomicAdd(counters.nonFinite, groupCounts[3]);
  }
}
