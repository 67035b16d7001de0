// tri_shade.glsl — a triangle's shading attributes from the TriShade words (layout in gpu_layout.h):
// octahedral vertex normals and, where the scene has them, texcoords, vertex colours and tangents.
// Needs bindings.glsl.
#include "oct_normal.glsl"

// CAUSTICA_TRISHADE_TEXCOORDS, _COLORS, _TANGENTS (TriShadeLayout, app/accel/gpu_scene.h): the blocks
// the words hold, which the host stores exactly when the scene has textures, COLOR_0 or TANGENT
// (CAUSTICA_TEXTURES and CAUSTICA_VERTEX_COLORS alone may come from --all-features).
#ifdef CAUSTICA_TRISHADE_TEXCOORDS
const uint kShadeTexcoordWords = kTriShadeTexcoordWords;
#else
const uint kShadeTexcoordWords = 0u;
#endif
#ifdef CAUSTICA_TRISHADE_COLORS
const uint kShadeColorWords = kTriShadeColorWords;
#else
const uint kShadeColorWords = 0u;
#endif
#ifdef CAUSTICA_TRISHADE_TANGENTS
const uint kShadeTangentWords = kTriShadeTangentWords;
#else
const uint kShadeTangentWords = 0u;
#endif
const uint kShadeColorOffset = kTriShadeWords + kShadeTexcoordWords;
const uint kShadeTangentOffset = kShadeColorOffset + kShadeColorWords;
const uint kShadeStride = kShadeTangentOffset + kShadeTangentWords;

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

// Vertex colours (COLOR_0, linear RGBA) of triangle `tri`; white in scenes without them.
void triColors(uint tri, out vec4 c0, out vec4 c1, out vec4 c2) {
#ifdef CAUSTICA_TRISHADE_COLORS
  uint k = tri * (kShadeStride / 3u) + kShadeColorOffset / 3u;  // rg0 ba0 rg1 | ba1 rg2 ba2
  uvec3 a = triShadeTriple(k), b = triShadeTriple(k + 1u);
  c0 = vec4(unpackHalf2x16(a.x), unpackHalf2x16(a.y));
  c1 = vec4(unpackHalf2x16(a.z), unpackHalf2x16(b.x));
  c2 = vec4(unpackHalf2x16(b.y), unpackHalf2x16(b.z));
#else
  c0 = c1 = c2 = vec4(1.0);
#endif
}

// Vertex tangents of triangle `tri` (xyz unit, w the bitangent's sign; vec4(0): none).
void triTangents(uint tri, out vec4 t0, out vec4 t1, out vec4 t2) {
#ifdef CAUSTICA_TRISHADE_TANGENTS
  uvec3 w = triShadeTriple(tri * (kShadeStride / 3u) + kShadeTangentOffset / 3u);
  t0 = tangentDecode(w.x);
  t1 = tangentDecode(w.y);
  t2 = tangentDecode(w.z);
#else
  t0 = t1 = t2 = vec4(0.0);
#endif
}
