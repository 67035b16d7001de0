// surface.glsl — the surface a closest hit found, as the path tracer and the Whitted tracer shade it:
// point and its error bound, geometric and shading normals on the side the ray came from, texcoords
// and material (world space). Needs bindings.glsl, spawn.glsl, traverse.glsl (instances.glsl), materials.glsl.

struct Surface {
  vec3 p;        // hit point
  vec3 pError;   // bound on p's rounding error, per axis (spawn.glsl)
  vec3 ngFront;  // unit geometric normal of the front (counter-clockwise) face
  bool front;    // the ray arrived on the front face
  vec3 ng;       // unit geometric normal on the side the ray came from
  vec3 ns;       // unit shading normal (interpolated, normal-mapped) on that side
#ifdef CAUSTICA_CLEARCOAT
  vec3 nc;       // unit normal of the clear coat on that side: interpolated, with the coat's own normal map
#endif
  vec2 uv;       // texcoords
  vec4 color;    // vertex colour (COLOR_0, linear RGBA; white without CAUSTICA_VERTEX_COLORS)
  Material m;
  float t;       // distance along the (unit) ray
  uint tri;      // the hit's triangle (TriGeom order; instanced: the stored object-space one)
#ifdef CAUSTICA_INSTANCED
  TriGeom g;         // the triangle in world space (instanceTriangle)
  InstanceXform xf;  // its instance
#endif
};

// The triangle a closest hit found, as its shading reads it: positions (TriGeom, world space), vertex
// normals (unit or 0) and texcoords, in corner order (instanced: hit.u, hit.v follow a mirrored instance).
struct HitTriangle {
  TriGeom g;
  vec3 n0, n1, n2;
  vec2 t0, t1, t2;
#ifdef CAUSTICA_INSTANCED
  InstanceXform xf;  // its instance
#endif
};

HitTriangle hitTriangle(inout Hit hit) {
  HitTriangle h;
#ifdef CAUSTICA_INSTANCED
  h.xf = instanceXform(hit.inst);
  instanceHitTriangle(hit, h.xf, h.g, h.n0, h.n1, h.n2, h.t0, h.t1, h.t2);  // instances.glsl: world space
#else
  h.g = triGeomAt(hit.tri);
  triNormals(hit.tri, h.n0, h.n1, h.n2);  // tri_shade.glsl
  triUvs(hit.tri, h.t0, h.t1, h.t2);
#endif
  return h;
}

// The surface at closest hit `hit` on triangle h (hitTriangle) of a ray along unit direction dir;
// false for a triangle of zero area (no normal: the ray is lost). normalMapped: apply the material's
// normal map (CAUSTICA_TEXTURES); a constant at each call site, folded away where it is false.
bool surfaceOn(Hit hit, HitTriangle h, vec3 dir, bool normalMapped, out Surface sf) {
  TriGeom g = h.g;
#ifdef CAUSTICA_INSTANCED
  sf.g = g;
  sf.xf = h.xf;
#endif
  sf.t = hit.t;
  sf.tri = hit.tri;
  float b0 = 1.0 - hit.u - hit.v;
  sf.p = b0 * g.v0.xyz + hit.u * g.v1.xyz + hit.v * g.v2.xyz;
  sf.pError = hitPointError(b0, hit.u, hit.v, g.v0.xyz, g.v1.xyz, g.v2.xyz);  // spawn.glsl
#ifdef CAUSTICA_INSTANCED
  sf.pError += instancePointError(g, h.xf);
#endif
  vec3 cr = cross(g.v1.xyz - g.v0.xyz, g.v2.xyz - g.v0.xyz);
  float crLen = length(cr);
  if (!(crLen > 0.0)) return false;
  sf.ngFront = cr / crLen;
  sf.front = dot(dir, sf.ngFront) < 0.0;
  sf.ng = sf.front ? sf.ngFront : -sf.ngFront;
  vec3 nsRaw = b0 * h.n0 + hit.u * h.n1 + hit.v * h.n2;
  float nsLen = length(nsRaw);
  vec3 ns = nsLen > 1.0e-12 ? nsRaw / nsLen : sf.ngFront;
  if (dot(ns, sf.ngFront) < 0.0) ns = -ns;
  sf.uv = b0 * h.t0 + hit.u * h.t1 + hit.v * h.t2;
  sf.color = vec4(1.0);  // exactly white where the scene has no colours (also under --all-features)
#if defined(CAUSTICA_VERTEX_COLORS) && defined(CAUSTICA_TRISHADE_COLORS)
  vec4 sc0, sc1, sc2;
#ifdef CAUSTICA_INSTANCED
  instanceColors(hit.tri, h.xf, sc0, sc1, sc2);
#else
  triColors(hit.tri, sc0, sc1, sc2);
#endif
  sf.color = b0 * sc0 + hit.u * sc1 + hit.v * sc2;
#endif
  sf.m = materialAt(floatBitsToUint(g.v0.w));
#ifdef CAUSTICA_TEXTURES
  vec4 tangent = vec4(0.0);  // none: a normal map takes the triangle's dp/du
#ifdef CAUSTICA_TRISHADE_TANGENTS
  if (normalMapped) {
    vec4 tt0, tt1, tt2;
#ifdef CAUSTICA_INSTANCED
    instanceTangents(hit.tri, h.xf, tt0, tt1, tt2);
#else
    triTangents(hit.tri, tt0, tt1, tt2);
#endif
    // The file's TANGENT where every corner has one (w: the first corner's sign).
    if (tt0.w != 0.0 && tt1.w != 0.0 && tt2.w != 0.0) tangent = vec4(b0 * tt0.xyz + hit.u * tt1.xyz + hit.v * tt2.xyz, tt0.w);
  }
#endif
#endif
#ifdef CAUSTICA_CLEARCOAT
  vec3 nc = ns;  // KHR_materials_clearcoat: the base's normal map does not apply to the coat
#ifdef CAUSTICA_TEXTURES
  if (normalMapped)
    nc = applyNormalMapTexture(sf.m.tex3.z, sf.m.coat.z, nc, sf.uv, g.v0.xyz, g.v1.xyz, g.v2.xyz, h.t0, h.t1, h.t2,
                               tangent);
#endif
  sf.nc = sf.front ? nc : -nc;
#endif
#ifdef CAUSTICA_TEXTURES
  if (normalMapped) ns = applyNormalMap(sf.m, ns, sf.uv, g.v0.xyz, g.v1.xyz, g.v2.xyz, h.t0, h.t1, h.t2, tangent);
#endif
  sf.ns = sf.front ? ns : -ns;
  return true;
}

// The surface at closest hit `hit` of a ray along unit direction dir (surfaceOn of its hitTriangle).
bool surfaceAt(Hit hit, vec3 dir, bool normalMapped, out Surface sf) {
  HitTriangle h = hitTriangle(hit);
  return surfaceOn(hit, h, dir, normalMapped, sf);
}

// Whether the surface emits towards the ray (the front face, or both faces when double-sided).
bool surfaceEmits(Surface sf) { return isEmissive(sf.m) && (sf.front || (sf.m.tex.z & kMatDoubleSided) != 0u); }

// Absorption coefficient (per scene unit) of the medium a ray refracted at sf travels in: the
// material's volume when it enters one through its front face, else none (it leaves it).
vec3 mediumBeyond(Surface sf) {
  return (sf.front && (sf.m.tex.z & kMatHasVolume) != 0u) ? sf.m.absorption.rgb : vec3(0.0);
}
