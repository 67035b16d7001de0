// lights.glsl — next-event estimation: an emissive triangle chosen by its importance to the shading
// point through the light tree (light_tree.glsl), then a uniform point on the chosen triangle.
#include "light_tree.glsl"

struct LightSample {
  vec3 p;        // world-space point on the emitter
  vec3 pError;   // bound on p's rounding error, per axis (spawn.glsl)
  vec3 n;        // unit geometric normal of the emitter's front face
  vec3 le;       // emitted radiance at p (towards the front; both ways if double-sided)
  float pdfArea; // probability density per unit area (selection and position)
  bool twoSided;
  uint material;  // the emitter's material index
};

// Probability per unit area that sampleLight(p, n, ...) picks a point on emissive triangle `tri` (TriGeom
// order): the tree's choice probability from p (normal n) over the triangle's area. 0 for a triangle
// outside the tree. p, n: the shading point and normal that light sampling used there.
float lightPdfArea(uint tri, vec3 p, vec3 n) {
  TriGeom g = triGeomAt(tri);
  uint leaf = floatBitsToUint(g.v1.w);  // leaf index + 1; 0: not in the tree
  if (leaf == 0u) return 0.0;
  float area = 0.5 * length(cross(g.v1.xyz - g.v0.xyz, g.v2.xyz - g.v0.xyz));
  return area > 0.0 ? lightTreePdf(p, n, leaf - 1u) / area : 0.0;
}

#ifdef CAUSTICA_INSTANCED
// The same for a hit on world-space triangle g (instanceTriangle) of instance x: its emitter number
// (g.v1.w) leads through the instance's light-leaf table to its leaf.
float instanceLightPdfArea(TriGeom g, InstanceXform x, vec3 p, vec3 n) {
  uint k = floatBitsToUint(g.v1.w);  // emitter number within the mesh + 1; 0: not an emitter
  if (k == 0u) return 0.0;
  uint leaf = instanceLightLeaf(x, k - 1u);
  if (leaf == kInvalidIndex) return 0.0;
  float area = 0.5 * length(cross(g.v1.xyz - g.v0.xyz, g.v2.xyz - g.v0.xyz));
  return area > 0.0 ? lightTreePdf(p, n, leaf) / area : 0.0;
}
#endif

// A uniform point (uTri) on emissive triangle `tri` (TriGeom order; instanced: of instance
// gLightInstance), chosen with probability pmf, as seen from p.
bool sampleLightTriangle(vec3 p, uint tri, float pmf, vec2 uTri, out LightSample ls) {
#ifdef CAUSTICA_INSTANCED
  InstanceXform xf = instanceXform(gLightInstance);  // the leaf's instance: its world-space triangle
  TriGeom g = instanceTriangle(tri, xf);
#else
  TriGeom g = triGeomAt(tri);
#endif
  vec2 b = sampleTriangleUniform(uTri);
  ls.p = (1.0 - b.x - b.y) * g.v0.xyz + b.x * g.v1.xyz + b.y * g.v2.xyz;
  ls.pError = hitPointError(1.0 - b.x - b.y, b.x, b.y, g.v0.xyz, g.v1.xyz, g.v2.xyz);
#ifdef CAUSTICA_INSTANCED
  ls.pError += instancePointError(g, xf);
#endif
  vec3 c = cross(g.v1.xyz - g.v0.xyz, g.v2.xyz - g.v0.xyz);
  float len = length(c);
  if (!(len > 0.0)) return false;
  ls.n = c / len;
  ls.material = floatBitsToUint(g.v0.w);
  Material m = materialAt(ls.material);
  vec2 uv = vec2(0.0);
#ifdef CAUSTICA_TEXTURES
  vec2 t0, t1, t2;
#ifdef CAUSTICA_INSTANCED
  instanceUvs(tri, xf, t0, t1, t2);
#else
  triUvs(tri, t0, t1, t2);  // tri_shade.glsl
#endif
  uv = (1.0 - b.x - b.y) * t0 + b.x * t1 + b.y * t2;
#endif
  // As a path that hits it sees it: under its clear coat, and present with its opacity (path_scatter.glsl's
  // passThrough), so that both estimators weigh the same emission.
  ls.le = materialEmissionSeen(m, uv, dot(ls.n, normalize(p - ls.p)));
#ifdef CAUSTICA_OPACITY
  vec4 color = vec4(1.0);  // the vertex colour, whose alpha is part of the opacity (surface.glsl)
#if defined(CAUSTICA_VERTEX_COLORS) && defined(CAUSTICA_TRISHADE_COLORS)
  vec4 c0, c1, c2;
#ifdef CAUSTICA_INSTANCED
  instanceColors(tri, xf, c0, c1, c2);
#else
  triColors(tri, c0, c1, c2);
#endif
  color = (1.0 - b.x - b.y) * c0 + b.x * c1 + b.y * c2;
#endif
  ls.le *= materialBaseColor(m, uv, color).a;
#endif
  ls.pdfArea = pmf / (0.5 * len);
  ls.twoSided = (m.tex.z & kMatDoubleSided) != 0u;
  return ls.pdfArea > 0.0;
}

// Samples a point on an emitter for shading point p with unit normal n (world space): uSelect descends
// the light tree, uTri places the point uniformly on the chosen triangle.
bool sampleLight(vec3 p, vec3 n, float uSelect, vec2 uTri, out LightSample ls) {
  if (frame.options.z == 0u) return false;
  uint tri;
  float pmf;
  if (!sampleLightTree(p, n, uSelect, tri, pmf)) return false;
  return sampleLightTriangle(p, tri, pmf, uTri, ls);
}
