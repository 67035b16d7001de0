// lights.glsl — next-event estimation: emissive triangles chosen in proportion to power through an
// alias table (Emitter[] in gpu_layout.h), then a uniform point on the chosen triangle.

struct LightSample {
  vec3 p;        // world-space point on the emitter
  vec3 pError;   // bound on p's rounding error, per axis (spawn.glsl)
  vec3 n;        // unit geometric normal of the emitter's front face
  vec3 le;       // emitted radiance at p (towards the front; both ways if double-sided)
  float pdfArea; // probability density per unit area (selection and position)
  bool twoSided;
  uint material;  // the emitter's material index
};

// Selection probability per unit area of emitter triangle material m: power weight / total, divided
// by area. Matches the host's weight luminance(emission) * area * sides exactly.
float lightPdfArea(Material m) {
  float sides = (m.tex.z & kMatDoubleSided) != 0u ? 2.0 : 1.0;
  return luminance(m.emission.rgb) * sides / frame.lights.x;
}

bool sampleLight(float uSlot, float uAlias, vec2 uTri, out LightSample ls) {
  uint count = frame.options.z;
  if (count == 0u) return false;
  uint slot = min(uint(uSlot * float(count)), count - 1u);
  Emitter e = emitters[slot];
  uint tri = uAlias < e.prob ? e.tri : emitters[e.alias].tri;
  TriGeom g = triGeom[tri];
  vec2 b = sampleTriangleUniform(uTri);
  ls.p = (1.0 - b.x - b.y) * g.v0.xyz + b.x * g.v1.xyz + b.y * g.v2.xyz;
  ls.pError = hitPointError(1.0 - b.x - b.y, b.x, b.y, g.v0.xyz, g.v1.xyz, g.v2.xyz);
  vec3 c = cross(g.v1.xyz - g.v0.xyz, g.v2.xyz - g.v0.xyz);
  float len = length(c);
  if (!(len > 0.0)) return false;
  ls.n = c / len;
  ls.material = floatBitsToUint(g.v0.w);
  Material m = materials[ls.material];
  vec2 uv = vec2(0.0);
#ifdef CAUSTICA_TEXTURES
  TriShade s = triShade[tri];
  uv = (1.0 - b.x - b.y) * vec2(s.n0.w, s.vt.x) + b.x * vec2(s.n1.w, s.vt.y) + b.y * vec2(s.n2.w, s.vt.z);
#endif
  ls.le = materialEmission(m, uv);
  ls.pdfArea = lightPdfArea(m);
  ls.twoSided = (m.tex.z & kMatDoubleSided) != 0u;
  return ls.pdfArea > 0.0;
}
