// tri_shade.glsl — a triangle's shading attributes from the TriShade words (layout in gpu_layout.h):
// octahedral vertex normals and, in textured scenes, texcoords; the emitter's light-tree leaf.
// Needs bindings.glsl.
#include "oct_normal.glsl"

// CAUSTICA_TRISHADE_TEXCOORDS (app/gpu/scene_buffers.cpp): the words hold texcoords, which the host
// stores exactly when the scene has textures (CAUSTICA_TEXTURES alone may come from --all-features).
#ifdef CAUSTICA_TRISHADE_TEXCOORDS
const uint kShadeStride = kTriShadeWordsTextured;
#else
const uint kShadeStride = kTriShadeWords;
#endif

// Vertex normals of triangle `tri` (TriGeom order), world space, unit or (0,0,0) where the mesh has none.
void triNormals(uint tri, out vec3 n0, out vec3 n1, out vec3 n2) {
  uint base = tri * kShadeStride;
  n0 = octDecode(triShadeWord(base));
  n1 = octDecode(triShadeWord(base + 1u));
  n2 = octDecode(triShadeWord(base + 2u));
}

// Vertex texcoords of triangle `tri` (the material's UV set); (0,0) in scenes without textures.
void triUvs(uint tri, out vec2 t0, out vec2 t1, out vec2 t2) {
#ifdef CAUSTICA_TRISHADE_TEXCOORDS
  uint base = tri * kShadeStride + 3u;
  t0 = uintBitsToFloat(uvec2(triShadeWord(base), triShadeWord(base + 1u)));
  t1 = uintBitsToFloat(uvec2(triShadeWord(base + 2u), triShadeWord(base + 3u)));
  t2 = uintBitsToFloat(uvec2(triShadeWord(base + 4u), triShadeWord(base + 5u)));
#else
  t0 = t1 = t2 = vec2(0.0);
#endif
}
