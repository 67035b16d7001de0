// trace_instanced_test.comp — GPU test entry: traces rays with traceInstanced (closest and any hit) so
// tests/gpu/traverse_gpu_test.cpp can compare them with the C++ twin in app/accel/tlas.cpp.
#include "../lib/bindings.glsl"
#include "../lib/spawn.glsl"
#include "../lib/intersect.glsl"
#include "../lib/traverse.glsl"
#include "../lib/traverse_instanced.glsl"

layout(local_size_x = 64) in;

// As trace_test.comp; hits[i].w = tri, and instances[i] = the scene instance hit.
layout(std430, binding = 8) readonly buffer RayBuffer { vec4 rays[]; };
layout(std430, binding = 9) writeonly buffer HitBuffer { uvec4 hits[]; };
layout(std430, binding = 10) writeonly buffer OccludedBuffer { uvec2 occluded[]; };

layout(location = 0) uniform uint rayCount;
layout(location = 1) uniform uint recordBase;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= rayCount) return;
  vec4 o = rays[2u * i];
  vec3 d = rays[2u * i + 1u].xyz;
  Hit hit;
  uint inst;
  traceInstanced(o.xyz, d, o.w, recordBase, false, hit, inst);
  hits[i] = uvec4(floatBitsToUint(hit.t), floatBitsToUint(hit.u), floatBitsToUint(hit.v), hit.tri);
  Hit any;
  uint anyInst;
  occluded[i] = uvec2(inst, traceInstanced(o.xyz, d, o.w, recordBase, true, any, anyInst) ? 1u : 0u);
}
