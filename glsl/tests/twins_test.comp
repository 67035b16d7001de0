// twins_test.comp — GPU test entry: runs one GLSL library function (chosen by a uniform) on a batch of
// input records, so that tests/gpu/twins_gpu_test.cpp can compare it with its C++ twin (app/shading/sampling.h).
// One invocation per record; #version is injected by the host. Compiled as it is, and with CAUSTICA_GUIDING
// for caster guiding's twins (guide cells from a third buffer).
#include "../shared/gpu_layout.h"
#include "../lib/rng.glsl"
#include "../lib/spawn.glsl"
#include "../lib/sampling.glsl"
#include "../lib/spectral.glsl"
#include "../lib/microfacet.glsl"
#include "../lib/materials.glsl"
#include "../lib/casters.glsl"
#include "../lib/punctual.glsl"  // without CAUSTICA_PUNCTUAL: spotFalloff only (no UBO)
#include "../lib/oct_normal.glsl"
#include "../lib/texture_wrap.glsl"
#include "../lib/denoise.glsl"

layout(local_size_x = 64) in;

// bindings.glsl is not included, so SSBO bindings 0 and 1 are free (GL 4.3 guarantees only 0-7).
// Per record kInWords uvec4: uint arguments as they are, float arguments as their bits.
layout(std430, binding = 0) readonly buffer InBuffer { uvec4 inRec[]; };
// Per record kOutWords uvec4: results as uint, float results as their bits, bools as 0 or 1.
layout(std430, binding = 1) writeonly buffer OutBuffer { uvec4 outRec[]; };

layout(location = 0) uniform uint recordCount;
layout(location = 1) uniform uint function;  // one of the constants below (enum Fn in the test)

const uint kInWords = 4u;
const uint kOutWords = 35u;

const uint kPcg4d = 0u;
const uint kRngSeed = 1u;
const uint kRand01 = 2u;
const uint kLuminance = 3u;
const uint kOrthonormalBasis = 4u;
const uint kSampleCosineHemisphere = 5u;
const uint kSampleTriangleUniform = 6u;
const uint kPowerHeuristic = 7u;
const uint kFresnelDielectric = 8u;
const uint kRefractDir = 9u;
const uint kOffsetRayOrigin = 10u;
const uint kSampleDielectric = 11u;
const uint kCauchyIor = 12u;
const uint kChannelSensitivity = 13u;
const uint kInCone = 14u;
const uint kCasterCone = 15u;
const uint kSampleUniformCone = 16u;
const uint kCasterFacesLights = 17u;
const uint kPrepareCasters = 18u;
const uint kDiffuseDirectionPdf = 19u;
const uint kSampleDiffuseDirection = 20u;
const uint kHitPointError = 21u;
const uint kGgx = 22u;
const uint kGgxSampleVisibleNormal = 23u;
const uint kBsdfEvalPdf = 24u;
const uint kBsdfSample = 25u;
const uint kSpotFalloff = 26u;
const uint kOctDecode = 27u;
const uint kWrapCoord = 28u;
const uint kLayers = 29u;
const uint kDenoiseTapWeight = 30u;
const uint kGuideLobe = 31u;  // with CAUSTICA_GUIDING only
const uint kVmf = 32u;        // with CAUSTICA_GUIDING only

#ifdef CAUSTICA_GUIDING
// Per record kGuideClasses * CAUSTICA_MAX_CASTERS guide cells: what casterGuideCell(caster, cls, p)
// returns at [kGuideClasses * caster + cls] (the record's p is ignored).
layout(std430, binding = 2) readonly buffer GuideCellBuffer { uvec4 guideCellRec[]; };
uint gRecord = 0u;  // the record this invocation runs
uvec4 casterGuideCell(uint caster, uint cls, vec3 p) {
  return guideCellRec[(gRecord * uint(CAUSTICA_MAX_CASTERS) + caster) * kGuideClasses + cls];
}
#endif

// The Bsdf of records for kBsdfEvalPdf and kBsdfSample: a[0].w = alpha, a[1].w = eta,
// a[2] = (color, lobe), a[3].xy = (f0 grey, f90).
Bsdf recordBsdf(vec4 a[kInWords]) {
  Bsdf b;
  b.lobe = uint(a[2].w);
  b.color = a[2].xyz;
  b.alpha = a[0].w;
  b.eta = a[1].w;
  b.f0 = vec3(a[3].x);
  b.f90 = a[3].y;
  return b;
}

uvec4 bits(vec4 v) { return floatBitsToUint(v); }
uvec4 bits(vec3 v, float w) { return floatBitsToUint(vec4(v, w)); }
uint bit(bool b) { return b ? 1u : 0u; }

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= recordCount) return;
#ifdef CAUSTICA_GUIDING
  gRecord = i;
#endif
  uvec4 raw[kInWords];
  vec4 a[kInWords];
  for (uint k = 0u; k < kInWords; ++k) {
    raw[k] = inRec[i * kInWords + k];
    a[k] = uintBitsToFloat(raw[k]);
  }
  uvec4 o[kOutWords];
  for (uint k = 0u; k < kOutWords; ++k) o[k] = uvec4(0u);

  if (function == kPcg4d) {
    o[0] = pcg4d(raw[0]);
  } else if (function == kRngSeed) {
    o[0] = rngSeed(raw[0].x, raw[0].y, raw[0].z);
  } else if (function == kRand01) {  // three draws from state raw[0], then the state
    uvec4 state = raw[0];
    o[0].x = floatBitsToUint(rand01(state));
    o[0].y = floatBitsToUint(rand01(state));
    o[0].z = floatBitsToUint(rand01(state));
    o[1] = state;
  } else if (function == kLuminance) {
    o[0].x = floatBitsToUint(luminance(a[0].xyz));
  } else if (function == kOrthonormalBasis) {
    vec3 t, b;
    orthonormalBasis(a[0].xyz, t, b);
    o[0] = bits(t, 0.0);
    o[1] = bits(b, 0.0);
  } else if (function == kSampleCosineHemisphere) {
    o[0] = bits(sampleCosineHemisphere(a[0].xy), 0.0);
  } else if (function == kSampleTriangleUniform) {
    o[0] = bits(vec4(sampleTriangleUniform(a[0].xy), 0.0, 0.0));
  } else if (function == kPowerHeuristic) {
    o[0].x = floatBitsToUint(powerHeuristic(a[0].x, a[0].y));
  } else if (function == kFresnelDielectric) {
    o[0].x = floatBitsToUint(fresnelDielectric(a[0].x, a[0].y));
  } else if (function == kRefractDir) {  // a[0] = (d, eta), a[1].xyz = n
    vec3 t;
    bool ok = refractDir(a[0].xyz, a[1].xyz, a[0].w, t);
    o[0] = bits(t, 0.0);
    o[0].w = bit(ok);
  } else if (function == kOffsetRayOrigin) {  // a[0].xyz = p, a[1].xyz = n, a[2].xyz = pError
    o[0] = bits(offsetRayOrigin(a[0].xyz, a[2].xyz, a[1].xyz), 0.0);
  } else if (function == kHitPointError) {  // a[0].xyz = (b0, b1, b2), a[1..3].xyz = p0, p1, p2
    o[0] = bits(hitPointError(a[0].x, a[0].y, a[0].z, a[1].xyz, a[2].xyz, a[3].xyz), 0.0);
  } else if (function == kWrapCoord) {  // a[0].xy: (i, n) as int bits; floorMod, then clamp, repeat, mirror
    int i = int(floatBitsToUint(a[0].x)), n = int(floatBitsToUint(a[0].y));
    o[0] = uvec4(uint(floorMod(i, n)), uint(wrapCoord(i, n, false, false)), uint(wrapCoord(i, n, true, false)),
                 uint(wrapCoord(i, n, false, true)));
  } else if (function == kLayers) {  // a[0] = (h, alpha), a[1] = (cosO, cosI, roughness, cosCoat),
                                      // a[2] = (sheen colour, clearcoat), a[3] = (u, base albedo, base luminance)
    o[0] = bits(vec4(sheenD(a[0].xyz, a[0].w), sheenLambda(a[1].x, a[0].w), sheenVisibility(a[1].x, a[1].y, a[0].w),
                     sheenAlbedo(a[1].x, a[1].z)));
    LayerWeights w = layerWeights(a[2].w, a[1].w, a[2].xyz, a[1].z, a[1].x, a[3].w);
    o[1] = bits(vec4(coatFresnel(a[1].w), w.coat, w.sheen, sheenL(a[1].y, a[0].w)));
    o[2] = bits(sampleUniformHemisphere(a[3].xy), w.coatPick);
    o[3] = bits(layeredAlbedo(w, a[2].xyz, vec3(a[3].z)), 0.0);
  } else if (function == kOctDecode) {  // a[0].x: the word (uint)
    o[0] = bits(octDecode(floatBitsToUint(a[0].x)), 0.0);
  } else if (function == kSpotFalloff) {  // a[0].xyz = (cos theta, cos outer, cos inner)
    o[0].x = floatBitsToUint(spotFalloff(a[0].x, a[0].y, a[0].z));
  } else if (function == kSampleDielectric) {  // a[0] = (d, eta), a[1] = (n, u)
    vec3 wi;
    bool transmitted;
    float f = sampleDielectric(a[0].xyz, a[1].xyz, a[0].w, a[1].w, wi, transmitted);
    o[0] = bits(wi, f);
    o[1].x = bit(transmitted);
  } else if (function == kCauchyIor) {  // a[0].xyz = (iorD, abbe, lambda)
    o[0].x = floatBitsToUint(cauchyIor(a[0].x, a[0].y, a[0].z));
  } else if (function == kChannelSensitivity) {
    o[0] = bits(channelSensitivity(a[0].x), 0.0);
  } else if (function == kInCone) {  // a[0] = (w, 1 - cos), a[1].xyz = axis
    o[0].x = bit(inCone(a[0].xyz, a[1].xyz, a[0].w));
  } else if (function == kCasterCone) {  // a[0].xyz = p, a[1].xyz = n, a[2] = sphere
    vec3 axis;
    float omc;
    bool ok = casterCone(a[0].xyz, a[1].xyz, a[2], axis, omc);
    o[0] = bits(axis, omc);
    o[1].x = bit(ok);
  } else if (function == kSampleUniformCone) {  // a[0] = (axis, 1 - cos), a[1].xy = u
    o[0] = bits(sampleUniformCone(a[0].xyz, a[0].w, a[1].xy), 0.0);
  } else if (function == kCasterFacesLights) {  // a[0] = (p, margin), a[1] = (axis, 1 - cos), a[2] = lights
    o[0].x = bit(casterFacesLights(a[0].xyz, a[1].xyz, a[1].w, a[2], a[0].w));
  } else if (function == kPrepareCasters) {  // a[0] = (p, u), a[1].xyz = n; spheres and lights from the UBO
    prepareCasters(a[0].xyz, a[1].xyz, a[0].w);
    o[0].xy = uvec2(gCasterUsable, gCasterPick);
    for (uint k = 0u; k < uint(CAUSTICA_MAX_CASTERS); ++k) {
      if (k >= gCasterUsable) break;
      o[1u + k] = bits(gCasterAxis[k], gCasterOneMinusCos[k]);
      o[9u + k / 4u][k % 4u] = floatBitsToUint(gCasterInvSolidAngle[k]);
    }
#ifdef CAUSTICA_GUIDING  // the guide lobes: (axis, kappa) at 11 + j, norm and weight at 27 and 31 + j / 4
    for (uint j = 0u; j < kGuideClasses * uint(CAUSTICA_MAX_CASTERS); ++j) {
      if (j >= kGuideClasses * gCasterUsable) break;
      o[11u + j] = bits(gGuideAxis[j], gGuideKappa[j]);
      o[27u + j / 4u][j % 4u] = floatBitsToUint(gGuideNorm[j]);
      o[31u + j / 4u][j % 4u] = floatBitsToUint(gGuideWeight[j]);
    }
#endif
  } else if (function == kDiffuseDirectionPdf) {  // prepareCasters as above, a[2].xyz = w
    prepareCasters(a[0].xyz, a[1].xyz, a[0].w);
    o[0].x = floatBitsToUint(diffuseDirectionPdf(a[1].xyz, a[2].xyz));
  } else if (function == kSampleDiffuseDirection) {  // prepareCasters as above, a[1].w = uPick, a[3].xy = u
    prepareCasters(a[0].xyz, a[1].xyz, a[0].w);
    o[0] = bits(sampleDiffuseDirection(a[1].xyz, a[1].w, a[3].xy), 0.0);
#ifdef CAUSTICA_GUIDING
  } else if (function == kGuideLobe) {  // raw[0] = cell, a[1].xyz = n: (axis, kappa), ok
    vec3 axis;
    float kappa;
    bool ok = guideLobe(raw[0], a[1].xyz, axis, kappa);
    o[0] = bits(axis, kappa);
    o[1].x = bit(ok);
  } else if (function == kVmf) {  // a[0].xy = (kappa, u): vmfOneMinusCos, vmfNorm
    o[0].x = floatBitsToUint(vmfOneMinusCos(a[0].x, a[0].y));
    o[0].y = floatBitsToUint(vmfNorm(a[0].x));
#endif
  } else if (function == kGgx) {  // a[0] = (h, alpha), a[1].xyz = wi: D(h), Lambda(h), G1(h), G2(h, wi)
    o[0] = bits(vec4(ggxD(a[0].xyz, a[0].w), ggxLambda(a[0].xyz, a[0].w), ggxG1(a[0].xyz, a[0].w),
                     ggxG2(a[0].xyz, a[1].xyz, a[0].w)));
  } else if (function == kGgxSampleVisibleNormal) {  // a[0] = (wo, alpha), a[1].xy = u: h, its pdf
    vec3 h = ggxSampleVisibleNormal(a[0].xyz, a[0].w, a[1].xy);
    o[0] = bits(h, ggxVisibleNormalPdf(a[0].xyz, h, a[0].w));
  } else if (function == kBsdfEvalPdf) {  // a[0].xyz = wo, a[1].xyz = wi: f, pdf
    Bsdf b = recordBsdf(a);
    vec3 f;  // bsdfEvalPdf: bsdfEval and bsdfPdf in one body (the path tracer's vertexEvalPdf and bsdfSample call it)
    float pdf = bsdfEvalPdf(b, a[0].xyz, a[1].xyz, f);
    o[0] = bits(f, pdf);
  } else if (function == kDenoiseTapWeight) {  // a[0] = (np, zp), a[1] = (nq, zq), a[2] = (depthScale, lumDiff, lumScale, n),
                                                // a[3] = (m2, l, albedoP, albedoQ)
    o[0].x = floatBitsToUint(denoiseTapWeight(a[0].xyz, a[1].xyz, a[0].w, a[1].w, a[2].x, a[2].y, a[2].z));
    o[0].y = floatBitsToUint(denoiseNormalWeight(a[0].xyz, a[1].xyz));
    o[0].z = floatBitsToUint(denoiseMeanVariance(a[2].w, a[3].x, a[3].y));
    o[0].w = floatBitsToUint(denoiseLuminanceScale(2.0, a[3].x, a[3].y, a[3].z, a[3].w));
    vec4 g = denoiseGuide(a[0].xyz, a[3].z, a[0].w);
    o[1] = floatBitsToUint(vec4(denoiseGuideNormal(g), denoiseGuideAlbedo(g)));
  } else if (function == kBsdfSample) {  // a[0].xyz = wo, a[1].xyz = u: wi, pdf, weight, transmitted, ok
    BsdfSample bs;
    bool ok = bsdfSample(recordBsdf(a), a[0].xyz, a[1].xyz, bs);
    o[0] = bits(bs.wi, bs.pdf);
    o[1] = bits(bs.weight, 0.0);
    o[2].x = bit(bs.transmitted);
    o[2].y = bit(ok);
  }

  for (uint k = 0u; k < kOutWords; ++k) outRec[i * kOutWords + k] = o[k];
}
