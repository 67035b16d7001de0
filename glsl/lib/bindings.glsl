// bindings.glsl — GLSL declarations of every buffer and image the path tracer reads or writes.
// Struct layouts come from glsl/shared/gpu_layout.h (shared with C++); this file only binds them.
#include "../shared/gpu_layout.h"

layout(std430, binding = CAUSTICA_BINDING_NODES) readonly buffer NodeBuffer { BvhNode nodes[]; };
layout(std430, binding = CAUSTICA_BINDING_TRIGEOM) readonly buffer TriGeomBuffer { TriGeom triGeom[]; };
layout(std430, binding = CAUSTICA_BINDING_TRISHADE) readonly buffer TriShadeBuffer { uint triShadeWords[]; };
layout(std430, binding = CAUSTICA_BINDING_MATERIALS) readonly buffer MaterialBuffer { Material materials[]; };
layout(std430, binding = CAUSTICA_BINDING_EMITTERS) readonly buffer EmitterBuffer { LightNode lightNodes[]; };
// TexInfo records (kTexInfoWords words each) first, then the texels (TexInfo.offset counts from word 0).
layout(std430, binding = CAUSTICA_BINDING_TEXELS) readonly buffer TexelBuffer { uint texels[]; };
layout(std430, binding = CAUSTICA_BINDING_COUNTERS) buffer CounterBuffer { Counters counters; };

layout(std140, binding = CAUSTICA_BINDING_FRAME) uniform FrameBlock { FrameParams frame; };
#include "split_buffers.glsl"  // bvhNode(i), triGeomAt(i), triShadeWord(i): the arrays above, split when large
#include "tri_shade.glsl"      // triNormals, triUvs: the TriShade words decoded
