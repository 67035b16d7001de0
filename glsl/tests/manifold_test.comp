// manifold_test.comp — GPU test entry: manifold NEE's chain solve and its differential helpers
// (lib/manifold.glsl) on a batch of records, over a scene bound as the renderer binds it for a dispatch,
// so that tests/gpu/manifold_twins_gpu_test.cpp can compare them with their C++ twins
// (app/accel/manifold_chain.h, app/shading/manifold.h). The host passes the scene's feature defines.
#include "../lib/bindings.glsl"
#include "../lib/rng.glsl"
#include "../lib/sampling.glsl"
#include "../lib/spawn.glsl"
#include "../lib/intersect.glsl"
#include "../lib/traverse.glsl"
#include "../lib/textures.glsl"
#include "../lib/spectral.glsl"
#include "../lib/microfacet.glsl"
#include "../lib/materials.glsl"
#include "../lib/lights.glsl"
#include "../lib/casters.glsl"

layout(local_size_x = 64) in;

#include "../lib/surface.glsl"
#include "../lib/manifold.glsl"

// The scene's arrays are read through buffer textures, so SSBO bindings 0 and 1 are free here (as in
// caustic_photons.comp); the host binds them after the scene.
// Per record 7 vec4: (x, caster bits), (xOrg, lambda), (sigma, uLambda), (axis, 0), (y, 0), (nL, 0), (seed, 0, 0);
// the differential functions read their arguments from the same words (see main).
layout(std430, binding = 0) readonly buffer InBuffer { vec4 inRec[]; };
// Per record 8 vec4 (see main).
layout(std430, binding = 1) writeonly buffer OutBuffer { vec4 outRec[]; };

layout(location = 0) uniform uint recordCount;
layout(location = 1) uniform uint function;

const uint kInVec4 = 7u, kOutVec4 = 8u;
const uint kSolve = 0u;         // manifoldSolve
const uint kTraceChain = 1u;    // traceManifoldChain at ab = seed
const uint kTransferDiff = 2u;  // transferDiff(in0, in1, in2, in2.w, in3)
const uint kRefractDiff = 3u;   // refractDiff(in0, in1, in1.w, ., in2, in3, ., in4, in5, .)
const uint kReflectDiff = 4u;   // reflectDiff(in0, in1, in2, in3)
const uint kNormalDiff = 5u;    // normalDiffOn at triangle in0.w (bits), barycentrics in0.xy, ns in1;
                                // normalDerivative for dp in2

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= recordCount) return;
  uint b = i * kInVec4, o = i * kOutVec4;
  vec4 a[7];
  for (uint k = 0u; k < kInVec4; ++k) a[k] = inRec[b + k];
  for (uint k = 0u; k < kOutVec4; ++k) outRec[o + k] = vec4(0.0);
  if (function == kTransferDiff) {
    outRec[o] = vec4(transferDiff(a[0].xyz, a[1].xyz, a[2].xyz, a[2].w, a[3].xyz), 0.0);
    return;
  }
  if (function == kRefractDiff) {
    vec3 dOut, dDOut, dDOut2;
    bool ok = refractDiff(a[0].xyz, a[1].xyz, a[1].w, dOut, a[2].xyz, a[3].xyz, dDOut, a[4].xyz, a[5].xyz, dDOut2);
    outRec[o] = vec4(dOut, ok ? 1.0 : 0.0);
    outRec[o + 1u] = vec4(dDOut, 0.0);
    outRec[o + 2u] = vec4(dDOut2, 0.0);
    return;
  }
  if (function == kReflectDiff) {
    outRec[o] = vec4(reflectDiff(a[0].xyz, a[1].xyz, a[2].xyz, a[3].xyz), 0.0);
    return;
  }
  if (function == kNormalDiff) {
    Hit hit;
    hit.t = 1.0;
    hit.u = a[0].x;
    hit.v = a[0].y;
    hit.tri = floatBitsToUint(a[0].w);
#ifdef CAUSTICA_INSTANCED
    hit.inst = 0u;
#endif
    HitTriangle h = hitTriangle(hit);
    NormalDiff nd = normalDiffOn(hit, h, a[1].xyz);
    outRec[o] = vec4(nd.gu, nd.scale);
    outRec[o + 1u] = vec4(nd.gv, 0.0);
    outRec[o + 2u] = vec4(nd.dn1, 0.0);
    outRec[o + 3u] = vec4(nd.dn2, 0.0);
    outRec[o + 4u] = vec4(normalDerivative(nd, a[1].xyz, a[2].xyz), 0.0);
    return;
  }
  ManifoldQuery q;
  q.x = a[0].xyz;
  q.caster = floatBitsToUint(a[0].w);
  q.xOrg = a[1].xyz;
  q.lambda = a[1].w;
  q.sigma = a[2].xyz;
  q.uLambda = a[2].w;
  q.axis = a[3].xyz;
  q.y = a[4].xyz;
  q.nL = a[5].xyz;
  q.seed = a[6].xy;
  // Out: (ok or chain traced, converged, 0, 0), (w, areaPerSolidAngle), (throughput, eventProb), (ab, F),
  // (J[0], J[1]), (pLast, 0), (dLast, 0), (filt, lambda).
  ManifoldResult r;
  if (function == kSolve) {
    r = manifoldSolve(q, true);
    outRec[o] = vec4(r.ok ? 1.0 : 0.0, 0.0, 0.0, 0.0);
    outRec[o + 3u] = vec4(r.ab, 0.0, 0.0);
  } else {
    r = manifoldSolve(q, false);  // its initial values
    vec2 F;
    mat2 J;
    bool converged;
    bool traced = traceManifoldChain(q, q.seed, r, F, J, converged);
    outRec[o] = vec4(traced ? 1.0 : 0.0, converged ? 1.0 : 0.0, 0.0, 0.0);
    outRec[o + 3u] = vec4(r.ab, F);
    outRec[o + 4u] = vec4(J[0], J[1]);
  }
  outRec[o + 1u] = vec4(r.w, r.areaPerSolidAngle);
  outRec[o + 2u] = vec4(r.throughput, r.eventProb);
  outRec[o + 5u] = vec4(r.pLast, 0.0);
  outRec[o + 6u] = vec4(r.dLast, 0.0);
  outRec[o + 7u] = vec4(r.filt, r.lambda);
}
