// caustic_cells.glsl — the caustic cell table (CausticCell in gpu_layout.h): for each caster, the cells
// (cubes of kCellPerRadius times its radius) that its caustic photons reached (caustic_photons.comp),
// with their count and the direction they came from. Manifold NEE joins light through a caster only
// from its cells and starts its Newton steps from the cell's direction (path_manifold.glsl); caster
// guiding's table (the same layout, keyed also by photon class) gives its lobes (casters.glsl). A hash
// table of buckets of 4 keys; a key lives in one of two buckets, so a lookup reads two buckets and one
// slot, without a loop. Needs rng.glsl (pcg4d) and casters.glsl (the CasterParams block).

// The integer coordinates of the cell of caster `caster` holding p (cubes of kCellPerRadius times its
// radius), offset by `centreCell` cells so that they count from 0; false outside [0, 2 centreCell) (no key).
bool casterCellCoords(uint caster, vec3 p, vec3 centreCell, out uvec3 u) {
  vec4 sphere = casters.sphere[caster];
  vec3 c = floor((p - sphere.xyz) / (kCellPerRadius * sphere.w)) + centreCell;
  u = uvec3(max(c, vec3(0.0)));
  return !(any(lessThan(c, vec3(0.0))) || any(greaterThanEqual(c, 2.0 * centreCell)));
}

// The key of the cell of caster `caster` holding p: 3 bits of caster, 10 + 9 + 10 bits of the cell's
// coordinates about the caster's centre (x, z within +-512 cells, y within +-256); 0 (no key) outside.
uint casterCellKey(uint caster, vec3 p) {
  uvec3 u;
  if (!casterCellCoords(caster, p, vec3(512.0, 256.0, 512.0), u)) return 0u;
  return caster << 29 | u.x << 19 | u.y << 10 | u.z;
}

// The key of the guide table's cell holding p for caster `caster` and photon class `cls` (0: the
// caster's own chain, 1: any other; caustic_photons.comp): 3 bits of caster, 1 of class, 10 + 8 + 10 bits
// of the cell's coordinates about the caster's centre (x, z within +-512 cells, y within +-128); 0 outside.
uint guideCellKey(uint caster, uint cls, vec3 p) {
  uvec3 u;
  if (!casterCellCoords(caster, p, vec3(512.0, 128.0, 512.0), u)) return 0u;
  return caster << 29 | cls << 28 | u.x << 18 | u.y << 10 | u.z;
}

// The key's two buckets, before the table's bucket mask.
uvec2 cellBuckets(uint key) {
  uvec4 h = pcg4d(uvec4(key, 0x2545f491u, 0x9e3779b9u, key ^ 0x85ebca6bu));
  return uvec2(h.x, h.y);
}

#ifndef CAUSTICA_PHOTON_PASS
// The slot of `key` in a table (its keys, 4 per bucket, under bucket mask `mask`), -1 where absent.
int cellSlot(usamplerBuffer keys, uint mask, uint key) {
  uvec2 b = cellBuckets(key) & mask;
  uvec4 k1 = texelFetch(keys, int(b.x)), k2 = texelFetch(keys, int(b.y));
  bvec4 m1 = equal(k1, uvec4(key)), m2 = equal(k2, uvec4(key));
  int slot = -1;
  for (int j = 3; j >= 0; --j) {  // unrolled: straight-line selects
    if (m2[j]) slot = int(4u * b.y) + j;
  }
  for (int j = 3; j >= 0; --j) {
    if (m1[j]) slot = int(4u * b.x) + j;
  }
  return slot;
}

#ifdef CAUSTICA_MANIFOLD
layout(binding = CAUSTICA_TEXUNIT_CELL_KEYS) uniform usamplerBuffer cellKeys;  // 4 keys per bucket
layout(binding = CAUSTICA_TEXUNIT_CELLS) uniform usamplerBuffer cellSlots;     // CausticCell per slot

// What the photons of caster `caster` brought to the cell at p: count (x) and summed direction (yzw,
// int bits); 0 where none came or there is no table.
uvec4 casterCell(uint caster, vec3 p) {
  uint key = casterCellKey(caster, p);
  if (key == 0u || casters.count.z == 0u) return uvec4(0u);
  int slot = cellSlot(cellKeys, casters.count.z, key);
  return slot < 0 ? uvec4(0u) : texelFetch(cellSlots, slot);
}
#endif

#ifdef CAUSTICA_GUIDING
layout(binding = CAUSTICA_TEXUNIT_GUIDE_KEYS) uniform usamplerBuffer guideKeys;
layout(binding = CAUSTICA_TEXUNIT_GUIDE_CELLS) uniform usamplerBuffer guideSlots;

// casterCell of the caster guide table: the photons of class cls whose last smooth event was on caster
// `caster`.
uvec4 casterGuideCell(uint caster, uint cls, vec3 p) {
  uint key = guideCellKey(caster, cls, p);
  if (key == 0u || casters.guide.x == 0u) return uvec4(0u);
  int slot = cellSlot(guideKeys, casters.guide.x, key);
  return slot < 0 ? uvec4(0u) : texelFetch(guideSlots, slot);
}
#endif
#endif
