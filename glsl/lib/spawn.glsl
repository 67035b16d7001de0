// spawn.glsl — where a new ray starts: hit points carry a conservative bound on their rounding error
// (world space, scene units), and origins move just past that bound along the normal, so a ray
// never re-hits the surface it leaves at any scale or distance from the origin (pbrt-v4's
// OffsetRayOrigin). Twins of app/accel/spawn.cpp.

// gamma(n) = n u / (1 - n u), u = 2^-24: bound on the relative error of n chained float operations.
float gammaBound(int n) {
  const float u = 5.9604644775390625e-8;
  return float(n) * u / (1.0 - float(n) * u);
}

// Absolute error bound, per axis, of the point b0 p0 + b1 p1 + b2 p2 computed in float.
vec3 hitPointError(float b0, float b1, float b2, vec3 p0, vec3 p1, vec3 p2) {
  return gammaBound(7) * (abs(b0 * p0) + abs(b1 * p1) + abs(b2 * p2));
}

// The next float above (below) v; +-0 steps to the smallest subnormal of that direction.
float nextFloatUp(float v) {
  if (isinf(v) && v > 0.0) return v;
  if (v == 0.0) return intBitsToFloat(1);
  int bits = floatBitsToInt(v);
  return intBitsToFloat(v > 0.0 ? bits + 1 : bits - 1);
}
float nextFloatDown(float v) {
  if (isinf(v) && v < 0.0) return v;
  if (v == 0.0) return -intBitsToFloat(1);
  int bits = floatBitsToInt(v);
  return intBitsToFloat(v > 0.0 ? bits - 1 : bits + 1);
}

// Moves p (error bound pError) along the unit normal n, which points to the side the new ray
// leaves into, just past the error box, then one more float step away, so that the origin lies
// strictly on that side of the true surface.
vec3 offsetRayOrigin(vec3 p, vec3 pError, vec3 n) {
  float d = dot(abs(n), pError);
  vec3 offset = d * n;
  precise vec3 po = p + offset;
  for (int i = 0; i < 3; ++i) {
    if (offset[i] > 0.0) po[i] = nextFloatUp(po[i]);
    else if (offset[i] < 0.0) po[i] = nextFloatDown(po[i]);
  }
  return po;
}
