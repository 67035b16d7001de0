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
#include "lib/microfacet.glsl"
#include "lib/materials.glsl"
#include "lib/lights.glsl"
#ifdef CAUSTICA_ENV
#include "lib/environment.glsl"
#endif
#if defined(CAUSTICA_PUNCTUAL) || defined(CAUSTICA_SPOT_EMITTERS)
#include "lib/punctual.glsl"
#endif
#ifdef CAUSTICA_CASTERS
#include "lib/casters.glsl"
#endif
#include "lib/vertex.glsl"
#include "lib/accumulate.glsl"
#ifdef CAUSTICA_TRANSPARENT
#include "lib/coverage.glsl"
#endif
#include "lib/adaptive.glsl"

layout(local_size_x = CAUSTICA_WORKGROUP_X, local_size_y = CAUSTICA_WORKGROUP_Y) in;

shared uint groupCounts[4];  // primary, secondary, shadow rays, non-finite samples

uint gSecondaryRays = 0u;
const uint kMaxPassThroughs = 256u;  // alpha pass-throughs a path may make beyond its bounces
uint gShadowRays = 0u;
#ifdef CAUSTICA_ENV
#include "lib/environment_light.glsl"
#endif

#ifdef CAUSTICA_PUNCTUAL
// Punctual-light next-event estimate at a non-delta vertex v (punctual.glsl): its own shadow ray, no
// MIS (a delta light cannot be hit by a bounce); the BSDF through vertexEval, like every light kind.
vec3 addPunctualLight(Vertex v, float u) {
  vec3 wi, li;
  float dist;
  if (!samplePunctualLight(v.p, v.pError, v.ng, u, wi, li, dist, gShadowRays)) return vec3(0.0);
#ifdef CAUSTICA_VOLUME
  vec3 sigma = dot(v.ng, wi) > 0.0 ? v.sigmaAbove : v.sigmaBelow;  // the medium the shadow ray runs in
  if (any(greaterThan(sigma, vec3(0.0)))) li *= exp(-sigma * dist);
#endif
  return vertexEval(v, wi) * li;
}
#endif

// The index of refraction of a glass hit for the wavelength the path carries (nm; 0 = all). The first
// dispersive event picks the path's wavelength (hero wavelength, or one RGB channel) and its filter.
float glassIor(Material m, inout float lambda, inout vec3 filt, inout uvec4 rng) {
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
  return ior;
}

// One path sample for the pixel; returns its radiance estimate (may be non-finite: the caller checks).
vec3 tracePath(uvec2 pixel, inout uvec4 rng) {
  vec3 org = frame.camPos.xyz;
  vec3 dir = eyeRayDirection(pixel, rand2(rng));
  vec3 beta = vec3(1.0);   // path throughput
  float etaScale = 1.0;    // product of eta^2 over refractions: beta * etaScale is free of radiance scaling
  vec3 radiance = vec3(0.0);
  vec3 filt = vec3(1.0);   // per-channel weight of the wavelength(s) the path carries (dispersion)
  float lambda = 0.0;      // nm; 0 while the path still carries every wavelength
  float prevPdf = 0.0;     // solid-angle pdf of the last BSDF sample (non-delta lobes)
  bool prevDelta = true;   // last direction came from the camera or a delta lobe: no MIS on emitter hits
  vec3 prevP = vec3(0.0), prevN = vec3(0.0);  // last vertex's point and shading normal (light-tree pdf for MIS)
  vec3 sigma = vec3(0.0);  // absorption coefficient of the medium the ray travels in (per scene unit)
  uint maxDepth = frame.options.x;
  bool firstDiffuse = true;  // no diffuse vertex yet on this path

  uint passThroughs = 0u;  // alpha pass-throughs: not bounces, so they do not consume the depth cap
  for (uint depth = 0u; depth < maxDepth; ++depth) {
    if (depth + passThroughs > 0u) ++gSecondaryRays;
    Hit hit;
    if (!traceClosest(org, dir, 3.0e38, hit)) {
#ifdef CAUSTICA_TRANSPARENT
      if (depth == 0u) gCameraRayMissed = true;  // alpha 0 for this sample (coverage.glsl)
#endif
#ifdef CAUSTICA_ENV
      radiance += beta * filt * escapedRadiance(dir, depth == 0u, prevDelta, prevPdf);  // environment_light.glsl
#endif
      break;
    }
#ifdef CAUSTICA_VOLUME
    beta *= exp(-sigma * hit.t);
#endif
#ifdef CAUSTICA_INSTANCED
    InstanceXform xf = instanceXform(hit.inst);
    TriGeom g;
    vec3 sn0, sn1, sn2;
    vec2 st0, st1, st2;
    instanceHitTriangle(hit, xf, g, sn0, sn1, sn2, st0, st1, st2);  // instances.glsl: world space
#else
    TriGeom g = triGeomAt(hit.tri);
    vec3 sn0, sn1, sn2;
    vec2 st0, st1, st2;
    triNormals(hit.tri, sn0, sn1, sn2);  // tri_shade.glsl
    triUvs(hit.tri, st0, st1, st2);
#endif
    float b0 = 1.0 - hit.u - hit.v;
    vec3 p = b0 * g.v0.xyz + hit.u * g.v1.xyz + hit.v * g.v2.xyz;
    vec3 pError = hitPointError(b0, hit.u, hit.v, g.v0.xyz, g.v1.xyz, g.v2.xyz);  // spawn.glsl
#ifdef CAUSTICA_INSTANCED
    pError += instancePointError(g, xf);
#endif
    vec3 cr = cross(g.v1.xyz - g.v0.xyz, g.v2.xyz - g.v0.xyz);
    float crLen = length(cr);
    if (!(crLen > 0.0)) break;
    vec3 ngFront = cr / crLen;              // geometric normal of the front (counter-clockwise) face
    bool front = dot(dir, ngFront) < 0.0;
    vec3 ng = front ? ngFront : -ngFront;   // geometric normal on the side the ray came from
    vec3 nsRaw = b0 * sn0 + hit.u * sn1 + hit.v * sn2;
    float nsLen = length(nsRaw);
    vec3 ns = nsLen > 1.0e-12 ? nsRaw / nsLen : ngFront;
    if (dot(ns, ngFront) < 0.0) ns = -ns;
    vec2 uv = b0 * st0 + hit.u * st1 + hit.v * st2;
    Material m = materials[floatBitsToUint(g.v0.w)];
#ifdef CAUSTICA_TEXTURES
    ns = applyNormalMap(m, ns, uv, g.v0.xyz, g.v1.xyz, g.v2.xyz, st0, st1, st2);
#endif
    if (!front) ns = -ns;                   // shading normal on the side the ray came from

    // Emission, weighted against light sampling when the last bounce could have sampled it.
    if (isEmissive(m) && (front || (m.tex.z & kMatDoubleSided) != 0u)) {
      float w = 1.0;
#ifdef CAUSTICA_SPOT_EMITTERS
      w *= spotEmitterFactor(m, -dir);  // a --light-radius sphere of a spot light emits into its cone
#endif
#ifdef CAUSTICA_MIS
      if (!prevDelta) {
#ifdef CAUSTICA_INSTANCED
        float pdfLight = instanceLightPdfArea(g, xf, prevP, prevN) * hit.t * hit.t / max(abs(dot(ngFront, dir)), 1.0e-12);
#else
        float pdfLight = lightPdfArea(hit.tri, prevP, prevN) * hit.t * hit.t / max(abs(dot(ngFront, dir)), 1.0e-12);
#endif
        w *= powerHeuristic(prevPdf, pdfLight);
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
    vec2 metalRough = materialMetalRough(m, uv);
    uint lobe = chooseLobe(m, metalRough.x, metalRough.y, rand01(rng));
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
#if defined(CAUSTICA_MIS) || defined(CAUSTICA_PUNCTUAL)
      // The Lambertian vertex as every light estimate below sees it (vertex.glsl), built once.
      Vertex v = makeVertex(makeBsdf(m, kLobeDiffuse, base.rgb, 1.0, 1.0), p, pError, ng, ns, dir, sigma, sigma);
#endif
#ifdef CAUSTICA_MIS
      // Light sampling only where the BSDF-sampled ray that competes with it in MIS will still be
      // traced (not at the last vertex the depth limit allows), so both estimators end alike.
      if (depth + 1u < maxDepth) {
        radiance += beta * filt * sampleEmitterLight(v, rng, gShadowRays);
      }
#ifdef CAUSTICA_ENV
      // The environment's own next-event estimate (an independent shadow ray; environment_light.glsl).
      // Not inside an absorbing medium: the ray could only leave through its boundary.
      vec2 uEnv = rand2(rng);
      if (depth + 1u < maxDepth && sigma == vec3(0.0)) radiance += beta * filt * addEnvironmentLight(v, uEnv);
#endif
#endif
#ifdef CAUSTICA_PUNCTUAL
      // Punctual lights: their own estimate, added to the emitters' (a sum of unbiased estimates);
      // in both integrators, since a bounce never finds a delta light.
      float uPunctual = rand01(rng);
      if (depth + 1u < maxDepth) radiance += beta * filt * addPunctualLight(v, uPunctual);
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
#ifdef CAUSTICA_GGX
    else if (lobe >= kLobeConductor) {  // GGX lobes: rough metal, plastic, rough glass (microfacet.glsl)
      float eta = 1.0;
      vec3 sigmaBelow = sigma;
#ifdef CAUSTICA_GLASS
      if (lobe == kLobeRoughGlass) {
        float ior = glassIor(m, lambda, filt, rng);
        eta = front ? ior : 1.0 / ior;  // n beyond the surface / n on the ray's side
#ifdef CAUSTICA_VOLUME
        sigmaBelow = (front && (m.tex.z & kMatHasVolume) != 0u) ? m.absorption.rgb : vec3(0.0);
#endif
      }
#endif
      Vertex v = makeVertex(makeBsdf(m, lobe, base.rgb, metalRough.y, eta), p, pError, ng, ns, dir, sigma, sigmaBelow);
#ifdef CAUSTICA_MIS
      if (depth + 1u < maxDepth) radiance += beta * filt * sampleEmitterLight(v, rng, gShadowRays);
#endif
#if defined(CAUSTICA_ENV) && defined(CAUSTICA_MIS)
      // The environment's next-event estimate through this lobe (both sides for rough glass), matching
      // the MIS weight escaped rays get after this vertex (environment_light.glsl).
      vec2 uEnv = rand2(rng);
      if (depth + 1u < maxDepth)
        radiance += beta * filt * addEnvironmentLight(v, uEnv);
#endif
#ifdef CAUSTICA_PUNCTUAL
      float uPunctual = rand01(rng);
      if (depth + 1u < maxDepth) radiance += beta * filt * addPunctualLight(v, uPunctual);
#endif
      BsdfSample bs;
      float uPart = rand01(rng);
      if (!bsdfSample(v.bsdf, v.wo, vec3(uPart, rand2(rng)), bs)) break;
      newDir = vertexToWorld(v, bs.wi);
      if (bs.transmitted ? dot(newDir, ng) >= 0.0 : dot(newDir, ng) <= 0.0) break;  // through the true surface: lost
      beta *= bs.weight;
      prevPdf = bs.pdf;
      prevDelta = false;
      if (bs.transmitted) {
        etaScale *= eta * eta;
        sigma = sigmaBelow;
      }
    }
#endif
#ifdef CAUSTICA_GLASS
    else {
      float ior = glassIor(m, lambda, filt, rng);
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
    // (inside glass that factor is not an energy loss and must not end paths; pbrt-v4 does the same),
    // times the dispersion filter: after a dispersive event the path carries filt (3 in one channel,
    // or the hero wavelength's sensitivity / pdf), and ignoring it ended those paths up to 3x too
    // often (cornell-dispersion 64x64: 1.3-2.1x the efficiency; docs/benchmarks.md).
    if (depth >= 3u) {
      float q = min(maxComponent(beta * filt) * etaScale, 1.0);
      if (rand01(rng) >= q) break;
      beta /= q;
    }
    dir = newDir;
    org = offsetRayOrigin(p, pError, dot(dir, ng) > 0.0 ? ng : -ng);
    prevP = p;
    prevN = ns;
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
