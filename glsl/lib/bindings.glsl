// bindings.glsl — GLSL declarations of every buffer and image the path tracer reads or writes.
// Struct layouts come from glsl/shared/gpu_layout.h (shared with C++); this file only binds them.
#include "../shared/gpu_layout.h"

// Every scene array is read through a buffer texture over its buffer (texelFetch is a vector gather on
// llvmpipe; an SSBO load there is a loop over the lanes, 1.0-1.3x slower overall: docs/architecture.md,
// "Writing shaders for llvmpipe"): the BVH and the triangle positions for traversal,
layout(binding = CAUSTICA_TEXUNIT_BVH_NODES) uniform usamplerBuffer bvhNodeTexels;  // 4 texels per BvhNode
layout(binding = CAUSTICA_TEXUNIT_TRI_GEOM) uniform usamplerBuffer triGeomTexels;   // 3 texels per TriGeom
layout(binding = CAUSTICA_TEXUNIT_BVH_WIDE) uniform usamplerBuffer bvhWideTexels;   // 7 texels per BvhWideNode
// the TriShade words (SSBOs only when split over several storage blocks),
#ifdef CAUSTICA_TRISHADE_PARTS  // split over several storage blocks (split_buffers.glsl)
layout(std430, binding = CAUSTICA_BINDING_TRISHADE) readonly buffer TriShadeBuffer { uint triShadeWords[]; };
#else
layout(binding = CAUSTICA_TEXUNIT_TRI_SHADE) uniform usamplerBuffer triShadeTexels;  // rgb32ui: 3 words per texel
#endif
// the materials, and the texture block (TexInfo records of kTexInfoWords words first, then the RGBA8
// texels; TexInfo.offset counts from word 0) as words and as records; the light-tree nodes: light_tree.glsl.
layout(binding = CAUSTICA_TEXUNIT_MATERIALS) uniform usamplerBuffer materialTexels;  // kMaterialTexels per Material
layout(binding = CAUSTICA_TEXUNIT_TEXELS) uniform usamplerBuffer texelWords;         // r32ui: one word per texel
layout(binding = CAUSTICA_TEXUNIT_TEX_INFO) uniform usamplerBuffer texInfoTexels;    // 3 texels per TexInfo
layout(std430, binding = CAUSTICA_BINDING_COUNTERS) buffer CounterBuffer { Counters counters; };

layout(std140, binding = CAUSTICA_BINDING_FRAME) uniform FrameBlock { FrameParams frame; };
// The layer texels of a Material are read only where a layer or a factor texture may be used.
#if defined(CAUSTICA_CLEARCOAT) || defined(CAUSTICA_SHEEN) || defined(CAUSTICA_FACTOR_TEXTURES)
#define CAUSTICA_MATERIAL_LAYERS
#endif

// Material record i (gpu_layout.h), kMaterialTexels RGBA32UI texels (the last five: CAUSTICA_MATERIAL_LAYERS).
Material materialAt(uint i) {
  int b = int(kMaterialTexels * i);
  Material m;
  m.baseColor = uintBitsToFloat(texelFetch(materialTexels, b));
  m.emission = uintBitsToFloat(texelFetch(materialTexels, b + 1));
  m.params = uintBitsToFloat(texelFetch(materialTexels, b + 2));
  m.absorption = uintBitsToFloat(texelFetch(materialTexels, b + 3));
  m.tex = texelFetch(materialTexels, b + 4);
  m.specular = uintBitsToFloat(texelFetch(materialTexels, b + 5));
  m.tex2 = texelFetch(materialTexels, b + 6);
#ifdef CAUSTICA_MATERIAL_LAYERS
  m.coat = uintBitsToFloat(texelFetch(materialTexels, b + 7));
  m.sheen = uintBitsToFloat(texelFetch(materialTexels, b + 8));
  m.tex3 = texelFetch(materialTexels, b + 9);
  m.tex4 = texelFetch(materialTexels, b + 10);
  m.specularBase = uintBitsToFloat(texelFetch(materialTexels, b + 11));
#else
  m.coat = vec4(0.0);
  m.sheen = vec4(0.0);
  m.tex3 = uvec4(kInvalidIndex);
  m.tex4 = uvec4(kInvalidIndex);
  m.specularBase = vec4(0.0);
#endif
  return m;
}

#include "split_buffers.glsl"  // triGeomAt(i), texInfoAt(i), triShadeWord(i) (split only)
#include "tri_shade.glsl"      // triNormals, triUvs: the TriShade words decoded
