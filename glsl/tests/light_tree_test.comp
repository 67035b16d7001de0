// light_tree_test.comp — GPU test entry: runs lightImportance, sampleLightTree and lightTreePdf
// (glsl/lib/light_tree.glsl) on a batch of query records, so that tests/gpu/light_tree_gpu_test.cpp can
// compare them with their C++ twins (app/accel/light_tree.h). One invocation per record.
#include "../shared/gpu_layout.h"

layout(local_size_x = 64) in;

// bindings.glsl is not included: the tree is read through its usual buffer texture (light_tree.glsl),
// queries and results are SSBOs 0 and 1.
#include "../lib/light_tree.glsl"

// Per record: [0] xyz p, w u (float bits); [1] xyz n, w: leaf to query (uint); [2] x: node for lightImportance.
layout(std430, binding = 0) readonly buffer InBuffer { uvec4 inRec[]; };
// Per record: x: sampled (0/1), y: tri, z: pmf bits, w: lightTreePdf(leaf) bits; then x: lightImportance bits.
layout(std430, binding = 1) writeonly buffer OutBuffer { uvec4 outRec[]; };

layout(location = 0) uniform uint recordCount;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= recordCount) return;
  vec4 a = uintBitsToFloat(inRec[3u * i]);
  uvec4 b = inRec[3u * i + 1u];
  uvec4 c = inRec[3u * i + 2u];
  vec3 n = uintBitsToFloat(b.xyz);
  uint tri;
  float pmf;
  bool ok = sampleLightTree(a.xyz, n, a.w, tri, pmf);
  float pdf = lightTreePdf(a.xyz, n, b.w);
  outRec[2u * i] = uvec4(ok ? 1u : 0u, tri, floatBitsToUint(pmf), floatBitsToUint(pdf));
  outRec[2u * i + 1u] = uvec4(floatBitsToUint(lightImportance(lightNodeAt(c.x), a.xyz, n)), 0u, 0u, 0u);
}
