// instances.glsl — instanced scenes (CAUSTICA_INSTANCED): the world-space triangle, normals and
// texcoords of a hit or a sampled emitter from the stored object-space ones and the instance's
// InstanceShade (gpu_layout.h), made as flattenInstances makes them, so shading is that of a flat scene.
// Included by traverse.glsl; needs bindings.glsl (bvhNodeTexels, triGeomAt, triNormals, triUvs).
#ifdef CAUSTICA_INSTANCED

struct InstanceXform {
  vec4 r0, r1, r2;     // object-to-world rows (world = Scene::origin-rebased, as the flat scene's)
  uint lightLeafBase;  // first entry of the instance in the light-leaf table
  bool mirrored;       // negative determinant: corners 1 and 2 swap (front faces stay counter-clockwise)
};

// InstanceShade of Scene::instances index `inst` (after the InstanceRecords in the node texture).
InstanceXform instanceXform(uint inst) {
  int base = int(4u * (CAUSTICA_INSTANCE_RECORD_BASE + CAUSTICA_INSTANCE_COUNT + inst));
  InstanceXform x;
  x.r0 = uintBitsToFloat(texelFetch(bvhNodeTexels, base));
  x.r1 = uintBitsToFloat(texelFetch(bvhNodeTexels, base + 1));
  x.r2 = uintBitsToFloat(texelFetch(bvhNodeTexels, base + 2));
  uvec4 w = texelFetch(bvhNodeTexels, base + 3);
  x.lightLeafBase = w.x;
  x.mirrored = (w.y & kInstanceMirrored) != 0u;
  return x;
}

vec3 instancePoint(InstanceXform x, vec3 p) {  // object space to world space
  return vec3(dot(x.r0.xyz, p) + x.r0.w, dot(x.r1.xyz, p) + x.r1.w, dot(x.r2.xyz, p) + x.r2.w);
}

// A unit object-space normal to world space: the inverse transpose of the 3x3 part (rows a, b, c),
// whose rows are cross(b, c), cross(c, a), cross(a, b) over the determinant; normalized. 0 stays 0.
vec3 instanceNormal(InstanceXform x, vec3 n) {
  vec3 a = x.r0.xyz, b = x.r1.xyz, c = x.r2.xyz;
  vec3 bc = cross(b, c);
  vec3 w = vec3(dot(bc, n), dot(cross(c, a), n), dot(cross(a, b), n));
  float len = length(w);
  if (!(len > 0.0)) return vec3(0.0);
  return (dot(a, bc) < 0.0 ? -w : w) / len;
}

// Stored triangle `tri` placed by x: world-space vertices, corners 1 and 2 swapped when mirrored (the
// w components stay where they are: material, emitter number).
TriGeom instanceTriangle(uint tri, InstanceXform x) {
  TriGeom o = triGeomAt(tri);
  vec3 p1 = instancePoint(x, o.v1.xyz), p2 = instancePoint(x, o.v2.xyz);
  TriGeom g;
  g.v0 = vec4(instancePoint(x, o.v0.xyz), o.v0.w);
  g.v1 = vec4(x.mirrored ? p2 : p1, o.v1.w);
  g.v2 = vec4(x.mirrored ? p1 : p2, o.v2.w);
  return g;
}

// Texcoords of stored triangle `tri` in the corner order of instanceTriangle.
void instanceUvs(uint tri, InstanceXform x, out vec2 t0, out vec2 t1, out vec2 t2) {
  vec2 a, b;
  triUvs(tri, t0, a, b);
  t1 = x.mirrored ? b : a;
  t2 = x.mirrored ? a : b;
}

// Vertex colours of stored triangle `tri` in the corner order of instanceTriangle.
void instanceColors(uint tri, InstanceXform x, out vec4 c0, out vec4 c1, out vec4 c2) {
  vec4 a, b;
  triColors(tri, c0, a, b);
  c1 = x.mirrored ? b : a;
  c2 = x.mirrored ? a : b;
}

// A stored tangent to world space: turned by the 3x3 part (a direction along the surface, not a
// normal), normalized; a mirroring instance flips the bitangent's sign, as flattenInstances does.
vec4 instanceTangent(InstanceXform x, vec4 t) {
  if (t.w == 0.0) return t;
  vec3 w = vec3(dot(x.r0.xyz, t.xyz), dot(x.r1.xyz, t.xyz), dot(x.r2.xyz, t.xyz));
  float len = length(w);
  if (!(len > 0.0)) return vec4(0.0);
  return vec4(w / len, x.mirrored ? -t.w : t.w);
}

// Vertex tangents of stored triangle `tri` in world space and the corner order of instanceTriangle.
void instanceTangents(uint tri, InstanceXform x, out vec4 t0, out vec4 t1, out vec4 t2) {
  vec4 a, b;
  triTangents(tri, t0, a, b);
  t0 = instanceTangent(x, t0);
  a = instanceTangent(x, a);
  b = instanceTangent(x, b);
  t1 = x.mirrored ? b : a;
  t2 = x.mirrored ? a : b;
}

// Everything a closest hit's shading reads, in world space: the triangle, its vertex normals (unit
// or 0) and texcoords in instanceTriangle's corner order; hit.u, hit.v (object corners 1, 2) follow.
void instanceHitTriangle(inout Hit hit, InstanceXform x, out TriGeom g, out vec3 n0, out vec3 n1, out vec3 n2,
                         out vec2 t0, out vec2 t1, out vec2 t2) {
  g = instanceTriangle(hit.tri, x);
  vec3 a, b, c;
  triNormals(hit.tri, a, b, c);
  n0 = instanceNormal(x, a);
  b = instanceNormal(x, b);
  c = instanceNormal(x, c);
  n1 = x.mirrored ? c : b;
  n2 = x.mirrored ? b : c;
  instanceUvs(hit.tri, x, t0, t1, t2);
  if (x.mirrored) {
    float u = hit.u;
    hit.u = hit.v;
    hit.v = u;
  }
}

// Bound on the extra rounding of world points made through the instance (object to world here, and
// the traversal's world to object), per axis, added to hitPointError: a few ulps of the magnitudes.
vec3 instancePointError(TriGeom g, InstanceXform x) {
  vec3 m = max(abs(g.v0.xyz), max(abs(g.v1.xyz), abs(g.v2.xyz))) + abs(vec3(x.r0.w, x.r1.w, x.r2.w));
  return 1.0e-6 * m;
}

// The light-tree leaf node of emitter number k (TriGeom.v1.w - 1) of instance x; kInvalidIndex: none.
uint instanceLightLeaf(InstanceXform x, uint k) {
  uint j = x.lightLeafBase + k;
  return texelFetch(bvhNodeTexels, int(CAUSTICA_LIGHT_LEAF_TABLE + j / 4u))[j % 4u];
}
#endif  // CAUSTICA_INSTANCED
