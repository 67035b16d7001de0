// bindings.glsl — GLSL declarations of every buffer and image the path tracer reads or writes.
// Struct layouts come from glsl/shared/gpu_layout.h (shared with C++); this file only binds them.
#include "../shared/gpu_layout.h"

// The BVH and the triangle positions for traversal come through buffer textures over the same buffers
// (texelFetch is a vector gather on llvmpipe; an SSBO load there is a loop over the lanes).
layout(binding = CAUSTICA_TEXUNIT_BVH_NODES) uniform usamplerBuffer bvhNodeTexels;  // 4 texels per BvhNode
layout(binding = CAUSTICA_TEXUNIT_TRI_GEOM) uniform usamplerBuffer triGeomTexels;   // 3 texels per TriGeom
layout(binding = CAUSTICA_TEXUNIT_BVH_WIDE) uniform usamplerBuffer bvhWideTexels;   // 7 texels per BvhWideNode
layout(std430, binding = CAUSTICA_BINDING_TRISHADE) readonly buffer TriShadeBuffer { uint triShadeWords[]; };
layout(std430, binding = CAUSTICA_BINDING_MATERIALS) readonly buffer MaterialBuffer { Material materials[]; };
layout(std430, binding = CAUSTICA_BINDING_EMITTERS) readonly buffer EmitterBuffer { LightNode lightNodes[]; };
// TexInfo records (kTexInfoWords words each) first, then the texels (TexInfo.offset counts from word 0).
layout(std430, binding = CAUSTICA_BINDING_TEXELS) readonly buffer TexelBuffer { uint texels[]; };
layout(std430, binding = CAUSTICA_BINDING_COUNTERS) buffer CounterBuffer { Counters counters; };

layout(std140, binding = CAUSTICA_BINDING_FRAME) uniform FrameBlock { FrameParams frame; };
#include "split_buffers.glsl"  // triGeomAt(i) (buffer texture), triShadeWord(i) (split when large)
#include "tri_shade.glsl"      // triNormals, triUvs: the TriShade words decoded
