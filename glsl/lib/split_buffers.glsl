// split_buffers.glsl — reads of the big scene arrays (BVH nodes, TriGeom, TriShade words) that also work
// when one storage block cannot hold an array (GL_MAX_SHADER_STORAGE_BLOCK_SIZE): the host
// (app/gpu/scene_buffers.*) then splits it into CAUSTICA_<ARRAY>_PARTS parts of CAUSTICA_<ARRAY>_PART
// elements each and binds part k > 0 at CAUSTICA_<ARRAY>_BINDING<k>. Without those defines (the usual
// case) each accessor reads its one block. Included by bindings.glsl.

#ifdef CAUSTICA_NODES_PARTS
layout(std430, binding = CAUSTICA_NODES_BINDING1) readonly buffer NodeBuffer1 { BvhNode nodes1[]; };
#if CAUSTICA_NODES_PARTS > 2
layout(std430, binding = CAUSTICA_NODES_BINDING2) readonly buffer NodeBuffer2 { BvhNode nodes2[]; };
#endif
#if CAUSTICA_NODES_PARTS > 3
layout(std430, binding = CAUSTICA_NODES_BINDING3) readonly buffer NodeBuffer3 { BvhNode nodes3[]; };
#endif
BvhNode bvhNode(uint i) {
  uint part = i / uint(CAUSTICA_NODES_PART);
  uint j = i - part * uint(CAUSTICA_NODES_PART);
  if (part == 0u) return nodes[j];
#if CAUSTICA_NODES_PARTS > 2
  if (part == 2u) return nodes2[j];
#endif
#if CAUSTICA_NODES_PARTS > 3
  if (part == 3u) return nodes3[j];
#endif
  return nodes1[j];
}
#else
BvhNode bvhNode(uint i) { return nodes[i]; }
#endif

#ifdef CAUSTICA_TRIGEOM_PARTS
layout(std430, binding = CAUSTICA_TRIGEOM_BINDING1) readonly buffer TriGeomBuffer1 { TriGeom triGeom1[]; };
#if CAUSTICA_TRIGEOM_PARTS > 2
layout(std430, binding = CAUSTICA_TRIGEOM_BINDING2) readonly buffer TriGeomBuffer2 { TriGeom triGeom2[]; };
#endif
#if CAUSTICA_TRIGEOM_PARTS > 3
layout(std430, binding = CAUSTICA_TRIGEOM_BINDING3) readonly buffer TriGeomBuffer3 { TriGeom triGeom3[]; };
#endif
TriGeom triGeomAt(uint i) {
  uint part = i / uint(CAUSTICA_TRIGEOM_PART);
  uint j = i - part * uint(CAUSTICA_TRIGEOM_PART);
  if (part == 0u) return triGeom[j];
#if CAUSTICA_TRIGEOM_PARTS > 2
  if (part == 2u) return triGeom2[j];
#endif
#if CAUSTICA_TRIGEOM_PARTS > 3
  if (part == 3u) return triGeom3[j];
#endif
  return triGeom1[j];
}
#else
TriGeom triGeomAt(uint i) { return triGeom[i]; }
#endif

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
#else
uint triShadeWord(uint i) { return triShadeWords[i]; }
#endif

// The TexInfo record of texture `index`, from the head of the texel block.
TexInfo texInfoAt(uint index) {
  uint b = index * kTexInfoWords;
  TexInfo t;
  t.offset = texels[b];
  t.width = texels[b + 1u];
  t.height = texels[b + 2u];
  t.flags = texels[b + 3u];
  t.uvRow0 = uintBitsToFloat(uvec4(texels[b + 4u], texels[b + 5u], texels[b + 6u], texels[b + 7u]));
  t.uvRow1 = uintBitsToFloat(uvec4(texels[b + 8u], texels[b + 9u], texels[b + 10u], texels[b + 11u]));
  return t;
}
