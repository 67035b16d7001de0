// trace_test.comp — GPU test entry: traces a batch of rays with traceClosest and traceOccluded so a
// host test can compare them with the C++ twins. One invocation per ray; #version is injected by the host.
#include "../lib/bindings.glsl"
#include "../lib/spawn.glsl"
#include "../lib/intersect.glsl"
#include "../lib/traverse.glsl"

layout(local_size_x = 64) in;

// Per ray two vec4: [2i] = origin.xyz (world space), tmax; [2i + 1] = direction.xyz, unused.
layout(std430, binding = 8) readonly buffer RayBuffer { vec4 rays[]; };
// Per ray (t, u, v, tri): t, u, v as float bits, tri as uint (kInvalidIndex and t = tmax on a miss).
// Same bytes as vec4(t, u, v, uintBitsToFloat(tri)), but declared uvec4 so the tri bits are stored
// exactly (GLSL leaves uintBitsToFloat of a NaN pattern such as kInvalidIndex unspecified).
layout(std430, binding = 9) writeonly buffer HitBuffer { uvec4 hits[]; };
// Per ray: 1 if traceOccluded(origin, dir, tmax), else 0.
layout(std430, binding = 10) writeonly buffer OccludedBuffer { uint occluded[]; };

layout(location = 0) uniform uint rayCount;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= rayCount) return;
  vec4 o = rays[2u * i];
  vec3 d = rays[2u * i + 1u].xyz;
  Hit hit;
  traceClosest(o.xyz, d, o.w, hit);
  hits[i] = uvec4(floatBitsToUint(hit.t), floatBitsToUint(hit.u), floatBitsToUint(hit.v), hit.tri);
  occluded[i] = traceOccluded(o.xyz, d, o.w) ? 1u : 0u;
}
