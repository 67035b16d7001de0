// environment_test.comp — GPU test entry: runs the environment-map functions of lib/environment.glsl
// on a batch of records, so tests/gpu/environment_gpu_test.cpp can compare them with their C++ twins
// (app/shading/environment_sampling.h). One invocation per record; #version is injected by the host.
#include "../shared/gpu_layout.h"
#include "../lib/sampling.glsl"
#include "../lib/environment.glsl"

layout(local_size_x = 64) in;

// Per record: in[0].xy uniform numbers for sampleEnvironment, in[1].xyz a unit direction (float bits).
layout(std430, binding = 0) readonly buffer InBuffer { uvec4 inRec[]; };
// Per record: out[0] sampled dir + ok, out[1] its le + pdf, out[2] environmentRadiance(in dir) +
// environmentPdf(in dir), out[3] envDirectionToUv(in dir) and envUvToDirection(in[0].xy).x, .y.
layout(std430, binding = 1) writeonly buffer OutBuffer { uvec4 outRec[]; };
layout(location = 0) uniform uint recordCount;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= recordCount) return;
  vec2 u = uintBitsToFloat(inRec[i * 2u].xy);
  vec3 d = uintBitsToFloat(inRec[i * 2u + 1u].xyz);
  vec3 dir, le;
  float pdf;
  bool ok = sampleEnvironment(u, dir, le, pdf);
  outRec[i * 4u] = uvec4(floatBitsToUint(dir), ok ? 1u : 0u);
  outRec[i * 4u + 1u] = floatBitsToUint(vec4(le, pdf));
  outRec[i * 4u + 2u] = floatBitsToUint(vec4(environmentRadiance(d), environmentPdf(d)));
  vec2 uv = envDirectionToUv(d, environment.rotation.x, environment.rotation.y);
  vec3 back = envUvToDirection(u, environment.rotation.x, environment.rotation.y);
  outRec[i * 4u + 3u] = floatBitsToUint(vec4(uv, back.x, back.y));
}
