// split_buffers.glsl — reads of the big per-triangle arrays that also work when one storage block cannot
// hold them (GL_MAX_SHADER_STORAGE_BLOCK_SIZE): TriGeom comes through its buffer texture (no block
// limit); the TriShade words, when the host (app/gpu/scene_buffers.*) splits them, come from
// CAUSTICA_TRISHADE_PARTS blocks of CAUSTICA_TRISHADE_PART words, part k > 0 bound at
// CAUSTICA_TRISHADE_BINDING<k>. Without those defines (the usual case) the words are read through
// their buffer texture instead (triShadeTriple, tri_shade.glsl). The BVH nodes are read through their own buffer texture (traverse.glsl). Included by bindings.glsl.

// TriGeom record i, read through the buffer texture the traversal uses (3 RGBA32UI texels; no SSBO, so
// no storage-block limit: GL_MAX_TEXTURE_BUFFER_SIZE texels, checked by app/gpu/bvh_textures.cpp).
TriGeom triGeomAt(uint i) {
  TriGeom t;
  t.v0 = uintBitsToFloat(texelFetch(triGeomTexels, int(3u * i)));
  t.v1 = uintBitsToFloat(texelFetch(triGeomTexels, int(3u * i + 1u)));
  t.v2 = uintBitsToFloat(texelFetch(triGeomTexels, int(3u * i + 2u)));
  return t;
}

#ifdef CAUSTICA_TRISHADE_PARTS
layout(std430, binding = CAUSTICA_TRISHADE_BINDING1) readonly buffer TriShadeBuffer1 { uint triShadeWords1[]; };
#if CAUSTICA_TRISHADE_PARTS > 2
layout(std430, binding = CAUSTICA_TRISHADE_BINDING2) readonly buffer TriShadeBuffer2 { uint triShadeWords2[]; };
#endif
#if CAUSTICA_TRISHADE_PARTS > 3
layout(std430, binding = CAUSTICA_TRISHADE_BINDING3) readonly buffer TriShadeBuffer3 { uint triShadeWords3[]; };
#endif
uint triShadeWord(uint i) {  // parts hold whole triangles (CAUSTICA_TRISHADE_PART is a multiple of the stride)
  uint part = i / uint(CAUSTICA_TRISHADE_PART);
  uint j = i - part * uint(CAUSTICA_TRISHADE_PART);
  if (part == 0u) return triShadeWords[j];
#if CAUSTICA_TRISHADE_PARTS > 2
  if (part == 2u) return triShadeWords2[j];
#endif
#if CAUSTICA_TRISHADE_PARTS > 3
  if (part == 3u) return triShadeWords3[j];
#endif
  return triShadeWords1[j];
}
#endif  // (unsplit, the words are read through a buffer texture: triShadeTriple in tri_shade.glsl)

// The TexInfo record of texture `index`, from the head of the texel block (3 RGBA32UI texels).
TexInfo texInfoAt(uint index) {
  int b = int(3u * index);
  uvec4 w = texelFetch(texInfoTexels, b);
  TexInfo t;
  t.offset = w.x;
  t.width = w.y;
  t.height = w.z;
  t.flags = w.w;
  t.uvRow0 = uintBitsToFloat(texelFetch(texInfoTexels, b + 1));
  t.uvRow1 = uintBitsToFloat(texelFetch(texInfoTexels, b + 2));
  return t;
}
