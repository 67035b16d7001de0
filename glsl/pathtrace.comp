// pathtrace.comp — the path tracer entry shader: one invocation per pixel and one sample per
// dispatch; eye rays bounce until they reach emitters (naive) or also sample lights (CAUSTICA_MIS).
// Radiance is linear; throughput is per RGB channel; wavelengths in nm.
#include "lib/bindings.glsl"
#include "lib/rng.glsl"
#include "lib/sampling.glsl"
#include "lib/spawn.glsl"
#include "lib/intersect.glsl"
#include "lib/traverse.glsl"
#include "lib/camera.glsl"
#include "lib/textures.glsl"
#include "lib/spectral.glsl"
#include "lib/materials.glsl"
#include "lib/lights.glsl"
#if defined(CAUSTICA_PUNCTUAL) || defined(CAUSTICA_SPOT_EMITTERS)
#include "lib/punctual.glsl"
#endif
#ifdef CAUSTICA_CASTERS
#include "lib/casters.glsl"
#endif
#include "lib/accumulate.glsl"
#include "lib/adaptive.glsl"

layout(local_size_x = CAUSTICA_WORKGROUP_X, local_size_y = CAUSTICA_WORKGROUP_Y) in;

shared uint groupCounts[4];  // primary, secondary, shadow rays, non-finite samples

uint gSecondaryRays = 0u;
const uint kMaxPassThroughs = 256u;  // alpha pass-throughs a path may make beyond its bounces
uint gShadowRays = 0u;

#ifdef CAUSTICA_PUNCTUAL
// The diffuse lobe's BSDF value times cos at wi (ns: shading normal on the path's side); a new lobe
// evaluates its own here, so the light estimators below serve every non-delta vertex alike.
vec3 diffuseBsdfCos(vec3 albedo, vec3 ns, vec3 wi) { return albedo * (INV_PI * max(dot(ns, wi), 0.0)); }

// Punctual-light next-event estimate at a non-delta vertex (punctual.glsl): its own shadow ray,
// no MIS (a delta light cannot be hit by a bounce). sigma: absorption of the medium the vertex is in.
vec3 addPunctualLight(vec3 p, vec3 pError, vec3 ng, vec3 ns, vec3 albedo, vec3 sigma, float u) {
  vec3 wi, li;
  float dist;
  if (!samplePunctualLight(p, pError, ng, u, wi, li, dist, gShadowRays)) return vec3(0.0);
#ifdef CAUSTICA_VOLUME
  if (any(greaterThan(sigma, vec3(0.0)))) li *= exp(-sigma * dist);
#endif
  return diffuseBsdfCos(albedo, ns, wi) * li;
}
#endif

// One path sample for the pixel; returns its radiance estimate (may be non-finite: the caller checks).
vec3 tracePath(uvec2 pixel, inout uvec4 rng) {
  vec3 org = frame.camPos.xyz;
  vec3 dir = eyeRayDirection(pixel, rand2(rng));
  vec3 beta = vec3(1.0);   // path throughput
  float etaScale = 1.0;    // product of eta^2 over refractions: beta * etaScale is free of radiance scaling
  vec3 radiance = vec3(0.0);
  vec3 filt = vec3(1.0);   // per-channel weight of the wavelength(s) the path carries (dispersion)
  float lambda = 0.0;      // nm; 0 while the path still carries every wavelength
  float prevPdf = 0.0;     // solid-angle pdf of the last BSDF sample (diffuse lobe)
  bool prevDelta = true;   // last direction came from the camera or a delta lobe: no MIS on emitter hits
  vec3 sigma = vec3(0.0);  // absorption coefficient of the medium the ray travels in (per scene unit)
  uint maxDepth = frame.options.x;
  bool firstDiffuse = true;  // no diffuse vertex yet on this path

  uint passThroughs = 0u;  // alpha pass-throughs: not bounces, so they do not consume the depth cap
  for (uint depth = 0u; depth < maxDepth; ++depth) {
    if (depth + passThroughs > 0u) ++gSecondaryRays;
    Hit hit;
    if (!traceClosest(org, dir, 3.0e38, hit)) break;
#ifdef CAUSTICA_VOLUME
    beta *= exp(-sigma * hit.t);
#endif
    TriGeom g = triGeom[hit.tri];
    TriShade s = triShade[hit.tri];
    float b0 = 1.0 - hit.u - hit.v;
    vec3 p = b0 * g.v0.xyz + hit.u * g.v1.xyz + hit.v * g.v2.xyz;
    vec3 pError = hitPointError(b0, hit.u, hit.v, g.v0.xyz, g.v1.xyz, g.v2.xyz);  // spawn.glsl
    vec3 cr = cross(g.v1.xyz - g.v0.xyz, g.v2.xyz - g.v0.xyz);
    float crLen = length(cr);
    if (!(crLen > 0.0)) break;
    vec3 ngFront = cr / crLen;              // geometric normal of the front (counter-clockwise) face
    bool front = dot(dir, ngFront) < 0.0;
    vec3 ng = front ? ngFront : -ngFront;   // geometric normal on the side the ray came from
    vec3 nsRaw = b0 * s.n0.xyz + hit.u * s.n1.xyz + hit.v * s.n2.xyz;
    float nsLen = length(nsRaw);
    vec3 ns = nsLen > 1.0e-12 ? nsRaw / nsLen : ngFront;
    if (dot(ns, ngFront) < 0.0) ns = -ns;
    if (!front) ns = -ns;                   // shading normal on the side the ray came from
    vec2 uv = b0 * vec2(s.n0.w, s.vt.x) + hit.u * vec2(s.n1.w, s.vt.y) + hit.v * vec2(s.n2.w, s.vt.z);
    Material m = materials[floatBitsToUint(g.v0.w)];

    // Emission, weighted against light sampling when the last bounce could have sampled it.
    if (isEmissive(m) && (front || (m.tex.z & kMatDoubleSided) != 0u)) {
      float w = 1.0;
#ifdef CAUSTICA_SPOT_EMITTERS
      w *= spotEmitterFactor(m, -dir);  // a --light-radius sphere of a spot light emits into its cone
#endif
#ifdef CAUSTICA_MIS
      if (!prevDelta) {
        float pdfLight = lightPdfArea(m) * hit.t * hit.t / max(abs(dot(ngFront, dir)), 1.0e-12);
        w = powerHeuristic(prevPdf, pdfLight);
      }
#endif
      radiance += beta * filt * materialEmission(m, uv) * w;
    }

    vec4 base = materialBaseColor(m, uv);
#ifdef CAUSTICA_OPACITY
    if (base.a < 1.0 && rand01(rng) >= base.a) {  // pass straight through (a delta event)
      org = offsetRayOrigin(p, pError, -ng);
      prevDelta = true;
      if (passThroughs < kMaxPassThroughs) {  // up to that many layers of cut-outs are free
        ++passThroughs;
        --depth;  // uint: wraps to the maximum at depth 0, and the loop's ++depth brings it back
      }
      continue;
    }
#endif

    vec3 newDir;
    uint lobe = chooseLobe(m, rand01(rng));
    if (lobe == kLobeDiffuse) {
#ifdef CAUSTICA_CASTERS
      // Cosine sampling mixed with directions aimed at glass and mirror objects (casters.glsl): more
      // paths reach the caustics they focus; the mixture pdf keeps the estimate unbiased and enters MIS.
      // Only at the path's first diffuse vertex (the caustics the camera sees; deeper vertices gain
      // less than they cost, docs/path-tracer.md), and not at the last vertex the depth limit allows.
      float uChoose = rand01(rng);
      if (firstDiffuse && depth + 1u < maxDepth) prepareCasters(p, ns, uChoose);
      else gCasterUsable = 0u;
      firstDiffuse = false;
      float uPick = rand01(rng);
      newDir = sampleDiffuseDirection(ns, uPick, rand2(rng));
#endif
#ifdef CAUSTICA_MIS
      // Light sampling only where the BSDF-sampled ray that competes with it in MIS will still be
      // traced (not at the last vertex the depth limit allows), so both estimators end alike.
      LightSample ls;
      if (depth + 1u < maxDepth && sampleLight(rand01(rng), rand01(rng), rand2(rng), ls)) {
        vec3 toLight = ls.p - p;
        float dist2 = dot(toLight, toLight);
        float dist = sqrt(dist2);
        vec3 wl = toLight / max(dist, 1.0e-30);
        float cosLight = -dot(ls.n, wl);
        float cosSurf = dot(ns, wl);
        if ((cosLight > 0.0 || (ls.twoSided && cosLight < 0.0)) && cosSurf > 0.0 && dot(ng, wl) > 0.0 && dist > 0.0) {
          vec3 nLight = cosLight > 0.0 ? ls.n : -ls.n;  // the emitter's geometric normal on p's side
          cosLight = abs(cosLight);
          float pdfLight = ls.pdfArea * dist2 / cosLight;
          ++gShadowRays;
          // The shadow ray joins two points each moved off its own surface past its error bound
          // (spawn.glsl; pbrt-v4's SpawnRayTo): p along ng, the light point along its normal on p's
          // side. The whole segment lies strictly on the lit side of the light's triangle, which
          // therefore cannot occlude its own sample at any angle, distance or scale. (Reusing wl and
          // dist from the unmoved p shifted the ray's end behind the emitter whenever ng and the
          // light's normal point alike: curved lights came out dark, 3-10 %.)
          vec3 from = offsetRayOrigin(p, pError, ng);
          vec3 to = offsetRayOrigin(ls.p, ls.pError, nLight);
          vec3 seg = to - from;
          float segLen = length(seg);
          if (segLen > 0.0 && !traceOccluded(from, seg / segLen, segLen * (1.0 - 1.0e-4))) {
#ifdef CAUSTICA_CASTERS
            float pdfBsdf = diffuseDirectionPdf(ns, wl);
#else
            float pdfBsdf = cosSurf * INV_PI;
#endif
            float w = powerHeuristic(pdfLight, pdfBsdf);
            vec3 transmittance = vec3(1.0);
#ifdef CAUSTICA_VOLUME
            transmittance = exp(-sigma * dist);  // the shadow ray runs inside the same medium
#endif
#ifdef CAUSTICA_SPOT_EMITTERS
            ls.le *= spotEmitterFactor(materials[ls.material], -wl);
#endif
            radiance += beta * filt * base.rgb * (INV_PI * cosSurf * w / pdfLight) * ls.le * transmittance;
          }
        }
      }
#endif
#ifdef CAUSTICA_PUNCTUAL
      // Punctual lights: their own estimate, added to the emitters' (a sum of unbiased estimates);
      // in both integrators, since a bounce never finds a delta light.
      float uPunctual = rand01(rng);
      if (depth + 1u < maxDepth) radiance += beta * filt * addPunctualLight(p, pError, ng, ns, base.rgb, sigma, uPunctual);
#endif
#ifdef CAUSTICA_CASTERS
      float cosOut = dot(newDir, ns);
      if (dot(newDir, ng) <= 0.0 || cosOut <= 0.0) break;  // below the true surface: absorbed
      float pdfDir = diffuseDirectionPdf(ns, newDir);
      beta *= base.rgb * (cosOut * INV_PI / pdfDir);
      prevPdf = pdfDir;
#else
      vec3 t, b;
      orthonormalBasis(ns, t, b);
      vec3 local = sampleCosineHemisphere(rand2(rng));
      newDir = normalize(local.x * t + local.y * b + local.z * ns);
      float cosOut = dot(newDir, ns);
      if (dot(newDir, ng) <= 0.0 || cosOut <= 0.0) break;  // below the true surface: absorbed
      beta *= base.rgb;
      prevPdf = cosOut * INV_PI;
#endif
      prevDelta = false;
    }
#ifdef CAUSTICA_MIRROR
    else if (lobe == kLobeMirror) {
      newDir = reflect(dir, ns);
      if (dot(newDir, ng) <= 0.0) newDir = reflect(dir, ng);
      beta *= base.rgb;
      prevDelta = true;
    }
#endif
#ifdef CAUSTICA_GLASS
    else {
      float ior = m.params.w;
#ifdef CAUSTICA_DISPERSION
      if ((m.tex.z & kMatDispersive) != 0u) {
        if (lambda == 0.0) {  // the path keeps one wavelength from its first dispersive event on
#ifdef CAUSTICA_SPECTRAL
          lambda = kLambdaMin + (kLambdaMax - kLambdaMin) * rand01(rng);
          filt = channelSensitivity(lambda) * (kLambdaMax - kLambdaMin);
#else
          int c = min(int(rand01(rng) * 3.0), 2);
          lambda = kChannelLambda[c];
          filt = vec3(0.0);
          filt[c] = 3.0;
#endif
        }
        ior = cauchyIor(ior, m.absorption.w, lambda);
      }
#endif
      float eta = front ? ior : 1.0 / ior;  // n_transmitted / n_incident
      bool transmitted;
      float u = rand01(rng);
      float weight = sampleDielectric(dir, ns, eta, u, newDir, transmitted);
      if (transmitted ? dot(newDir, ng) >= 0.0 : dot(newDir, ng) <= 0.0)  // shading normal misled: use ng
        weight = sampleDielectric(dir, ng, eta, u, newDir, transmitted);
      beta *= weight;
      if (transmitted) {
        beta *= base.rgb;  // KHR_materials_transmission: transmitted light is tinted by the base colour
        etaScale *= eta * eta;
      }
#ifdef CAUSTICA_VOLUME
      if (transmitted) sigma = (front && (m.tex.z & kMatHasVolume) != 0u) ? m.absorption.rgb : vec3(0.0);
#endif
      prevDelta = true;
    }
#endif

    // Russian roulette after a few bounces, on the throughput without the eta^2 radiance scaling
    // (inside glass that factor is not an energy loss and must not end paths; pbrt-v4 does the same).
    if (depth >= 3u) {
      float q = min(maxComponent(beta) * etaScale, 1.0);
      if (rand01(rng) >= q) break;
      beta /= q;
    }
    dir = newDir;
    org = offsetRayOrigin(p, pError, dot(dir, ng) > 0.0 ? ng : -ng);
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
  // One sample per invocation: more would run into llvmpipe's cap on nested loop iterations
  // (see Renderer::renderRows); the host dispatches once per sample.
  uint primary = 0u, bad = 0u;
  if (valid) {
    uvec4 rng = rngSeed(pixel.y * frame.frame.x + pixel.x, frame.frame.z, frame.frame.w);
    vec3 l = tracePath(pixel, rng);
    primary = 1u;
    bool finite = !(any(isnan(l)) || any(isinf(l)));
    if (!finite) bad = 1u;  // counted and reported; not part of the pixel's mean (neither as black)
    accumulate(ivec2(pixel), finite ? l : vec3(0.0), finite ? 1.0 : 0.0);
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
