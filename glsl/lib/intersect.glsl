// intersect.glsl — watertight ray–triangle test and ray–box slab test (world space; t in units of |dir|).
// Twins of intersectTriangle() in app/accel/intersect.cpp and intersectAabb() in app/accel/ray_box.h; keep them in step.
// Needs gammaBound() from spawn.glsl.

// Cyclic permutation that moves axis kz to z (keeps handedness; both faces are accepted anyway).
vec3 permuteToKz(vec3 a, int kz) {
  return kz == 0 ? a.yzx : (kz == 1 ? a.zxy : a);
}

// The ray-only part of the watertight test (Woop, Benthin, Wald 2013): which axis becomes z, and the
// shear that maps the direction onto +z. Computed once per ray by the traversal.
struct RayShear {
  int kz;    // axis of the largest |dir| component, permuted to z
  float sx;  // -d.x / d.z of the permuted direction
  float sy;  // -d.y / d.z
  float sz;  // 1 / d.z (0 for a zero direction: nothing hits)
};

RayShear makeRayShear(vec3 dir) {
  vec3 ad = abs(dir);
  int kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  vec3 d = permuteToKz(dir, kz);
  RayShear s;
  s.kz = kz;
  s.sz = d.z == 0.0 ? 0.0 : 1.0 / d.z;
  s.sx = -d.x * s.sz;
  s.sy = -d.y * s.sz;
  return s;
}

// max and min as selects, for the error bound's operands and the edge functions' signs: GLSL max/min
// compile on llvmpipe to vmaxps/vminps plus a NaN test and a masked move (its NaN-safe max); the
// select is one vmaxps. In every lane whose result decides anything (0 < t < tmax: the edge
// functions, det and the ray-space coordinates are finite numbers) no operand is NaN, so the values
// are max's and min's (up to the sign of a zero, which only meets comparisons with 0 here). `precise`
// keeps NIR from folding the select back into fmax/fmin (as bvhMax in traverse.glsl).
float triMax(float a, float b) {
  precise float m = mix(b, a, a > b);
  return m;
}
float triMin(float a, float b) {
  precise float m = mix(b, a, a < b);
  return m;
}

// Woop, Benthin, Wald 2013, in the form of pbrt-v4's IntersectTriangle: translate to the ray origin,
// permute the largest direction component to z, shear the ray onto +z, then 2D edge functions.
// Shared edges give exactly negated edge functions, so no ray slips between two triangles; `precise`
// forbids fused multiply-adds that would break that symmetry. Returns true when 0 < t < tmax; u and v
// are the barycentric weights of p1 and p2 (t, u, v are meaningful only then).
// Straight-line code (one boolean at the end, no early returns): llvmpipe runs every path of every
// lane anyway, and an early return becomes a flag and masks at each later statement. The decision is
// the C++ twin's, condition for condition.
// Zero-area triangles: this test does not look for them (the twin's cross product per test). They
// are packed as one point (appendTriGeom, packTriangleRange: p1 = p2 = p0 when cross(p1 - p0,
// p2 - p0) is exactly 0 in float), and a point has e0 = e1 = e2 = 0 exactly (a = b = c, products
// of the same two floats), so det == 0 rejects it for every ray; nothing else reads the vertices of
// a zero-area triangle (never hit, and zero emitter weight, so never light-sampled).
// Difference from the C++ twin: no double-precision recomputation when an edge function is exactly 0
// (such a ray counts as on the edge, so it may hit both neighbours; watertightness is unaffected).
bool intersectTriangleSheared(vec3 org, RayShear rs, vec3 p0, vec3 p1, vec3 p2, float tmax,
                              out float t, out float u, out float v) {
  float sx = rs.sx, sy = rs.sy, sz = rs.sz;
  int kz = rs.kz;

  vec3 a = permuteToKz(p0 - org, kz);
  vec3 b = permuteToKz(p1 - org, kz);
  vec3 c = permuteToKz(p2 - org, kz);
  precise float ax = a.x + sx * a.z;
  precise float ay = a.y + sy * a.z;
  precise float bx = b.x + sx * b.z;
  precise float by = b.y + sy * b.z;
  precise float cx = c.x + sx * c.z;
  precise float cy = c.y + sy * c.z;

  precise float e0 = bx * cy - by * cx;  // edge function opposite p0 (weight of p0)
  precise float e1 = cx * ay - cy * ax;  // opposite p1
  precise float e2 = ax * by - ay * bx;  // opposite p2
  // Some edge function < 0 and some > 0 (LLVM turns the twin's six comparisons into NaN-safe min/max;
  // with a NaN edge function det is NaN and t fails 0 < t below, so the decision is the twin's).
  bool mixedSigns = triMin(e0, triMin(e1, e2)) < 0.0 && triMax(e0, triMax(e1, e2)) > 0.0;
  float det = e0 + e1 + e2;  // 0: ray in the triangle's plane, or a zero-area triangle packed as a point

  float az = sz * a.z, bz = sz * b.z, cz = sz * c.z;
  float tScaled = e0 * az + e1 * bz + e2 * cz;
  float invDet = 1.0 / det;
  float tt = tScaled * invDet;
  // t must be conservatively positive: beyond the bound of its own rounding error (pbrt-v4), so a
  // ray spawned past a hit point's error box never re-hits the surface it leaves. Like pbrt-v4's,
  // this bound is right for unit-length directions only (it mixes units of t with world units):
  // every caller normalises (a short unnormalised shadow ray lost real occluders at 1e-4 scale).
  float maxZt = triMax(abs(az), triMax(abs(bz), abs(cz)));
  float maxXt = triMax(abs(ax), triMax(abs(bx), abs(cx)));
  float maxYt = triMax(abs(ay), triMax(abs(by), abs(cy)));
  float deltaZ = gammaBound(3) * maxZt;
  float deltaX = gammaBound(5) * (maxXt + maxZt);
  float deltaY = gammaBound(5) * (maxYt + maxZt);
  float deltaE = 2.0 * (gammaBound(2) * maxXt * maxYt + deltaY * maxXt + deltaX * maxYt);
  float maxE = triMax(abs(e0), triMax(abs(e1), abs(e2)));
  float deltaT = 3.0 * (gammaBound(3) * maxE * maxZt + deltaE * maxZt + deltaZ * maxE) * abs(invDet);
  t = tt;
  u = e1 * invDet;
  v = e2 * invDet;
  // The twin's rejections in its order: zero direction, mixed signs, det == 0, not 0 < t < tmax
  // (also NaN), t within its error bound.
  return !(sz == 0.0) && !mixedSigns && !(det == 0.0) && (tt > 0.0 && tt < tmax) && !(tt <= deltaT);
}

// The same test for a single ray (its shear computed here).
bool intersectTriangle(vec3 org, vec3 dir, vec3 p0, vec3 p1, vec3 p2, float tmax,
                       out float t, out float u, out float v) {
  return intersectTriangleSheared(org, makeRayShear(dir), p0, p1, p2, tmax, t, u, v);
}

// Slab test against [bmin, bmax]; invDir comes from safeInverse() (finite: no 0 * inf = NaN).
// tnear: entry distance clamped to >= 0. The exit distance is widened by 2^-20 (relative) to cover
// rounding, and an exit distance of exactly 0 (origin on a slab plane with a ~0 direction component)
// counts as "inside", so rays lying on a box face still visit it. Both are conservative.
bool intersectAabb(vec3 org, vec3 invDir, vec3 bmin, vec3 bmax, float tmax, out float tnear) {
  vec3 t0 = (bmin - org) * invDir;
  vec3 t1 = (bmax - org) * invDir;
  vec3 lo = min(t0, t1);
  vec3 hi = max(t0, t1);
  hi = mix(hi, vec3(3.0e38), equal(hi, vec3(0.0)));
  tnear = max(max(lo.x, lo.y), max(lo.z, 0.0));
  float tfar = min(min(hi.x, hi.y), min(hi.z, tmax)) * (1.0 + 1.0 / 1048576.0);
  return tnear <= tfar;
}

// Guarded reciprocal of a ray direction: |d| < 1e-20 becomes +-1e-20 (sign by d >= 0), so the
// result is finite and never 0 * inf = NaN in the slab test.
vec3 safeInverse(vec3 d) {
  vec3 g = mix(vec3(-1e-20), vec3(1e-20), greaterThanEqual(d, vec3(0.0)));
  return 1.0 / mix(d, g, lessThan(abs(d), vec3(1e-20)));
}
