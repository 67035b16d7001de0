// modes_twins_test.comp — GPU test entry: pointLightIntensity and phongBrdf (lib/point_lights.glsl) on
// a batch of records, compared with their C++ twins (app/shading/phong.h) by tests/gpu/modes_test.cpp.
#include "../shared/gpu_layout.h"
#include "../lib/point_lights.glsl"

layout(local_size_x = 64) in;

// Per record 8 vec4: light position, intensity, axis; (w, roughness); (base, 0); (n, 0); (wv, 0); light cone.
layout(std430, binding = 0) readonly buffer InBuffer { vec4 inRec[]; };
// Per record 2 vec4: (pointLightIntensity(light, w), 0), (phongBrdf(base, roughness, n, w, wv), 0).
layout(std430, binding = 1) writeonly buffer OutBuffer { vec4 outRec[]; };
layout(location = 0) uniform uint recordCount;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= recordCount) return;
  PointLight l;
  l.position = inRec[i * 8u];
  l.intensity = inRec[i * 8u + 1u];
  l.axis = inRec[i * 8u + 2u];
  l.cone = inRec[i * 8u + 7u];
  vec4 w = inRec[i * 8u + 3u];
  outRec[i * 2u] = vec4(pointLightIntensity(l, w.xyz), 0.0);
  outRec[i * 2u + 1u] = vec4(phongBrdf(inRec[i * 8u + 4u].xyz, w.w, inRec[i * 8u + 5u].xyz, w.xyz, inRec[i * 8u + 6u].xyz), 0.0);
}
