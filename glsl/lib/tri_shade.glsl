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

// Words 3k .. 3k + 2 of the TriShade array: one RGB32UI texel of the buffer texture (a vector gather on
// llvmpipe, where an SSBO load is a loop over the SIMD lanes), or three words of the storage blocks when
// the array is split over several (split_buffers.glsl).
uvec3 triShadeTriple(uint k) {
#ifdef CAUSTICA_TRISHADE_PARTS
  return uvec3(triShadeWord(3u * k), triShadeWord(3u * k + 1u), triShadeWord(3u * k + 2u));
#else
  return texelFetch(triShadeTexels, int(k)).xyz;
#endif
}

// Vertex normals of triangle `tri` (TriGeom order), world space, unit or (0,0,0) where the mesh has none.
void triNormals(uint tri, out vec3 n0, out vec3 n1, out vec3 n2) {
  uvec3 w = triShadeTriple(tri * (kShadeStride / 3u));
  n0 = octDecode(w.x);
  n1 = octDecode(w.y);
  n2 = octDecode(w.z);
}

// Vertex texcoords of triangle `tri` (the material's UV set); (0,0) in scenes without textures.
void triUvs(uint tri, out vec2 t0, out vec2 t1, out vec2 t2) {
#ifdef CAUSTICA_TRISHADE_TEXCOORDS
  uint k = tri * (kShadeStride / 3u) + 1u;  // words 3..8: u0 v0 u1 | v1 u2 v2
  uvec3 a = triShadeTriple(k), b = triShadeTriple(k + 1u);
  t0 = uintBitsToFloat(a.xy);
  t1 = uintBitsToFloat(uvec2(a.z, b.x));
  t2 = uintBitsToFloat(b.yz);
#else
  t0 = t1 = t2 = vec2(0.0);
#endif
}
