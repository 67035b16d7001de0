// rng.glsl — random numbers: one stream per (pixel, global sample index, seed), so an image does not
// depend on how samples are split into dispatches. The three 32-bit keys go through pcg4d
// (Jarzynski & Olano 2020), a bijection of uvec4, into a 128-bit xoshiro128+ state (Blackman &
// Vigna): distinct paths start from distinct states, so no two paths share a stream, however many
// pixels and samples (a 32-bit seed repeats past 2^32 paths). Twins in app/shading/rng.cpp.

uvec4 pcg4d(uvec4 v) {
  v = v * 1664525u + 1013904223u;
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  v ^= v >> 16u;
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  return v;
}

uvec4 rngSeed(uint pixel, uint sampleIndex, uint seed) {
  uvec4 s = pcg4d(uvec4(pixel, sampleIndex, seed, 0x9E3779B9u));
  if (s == uvec4(0u)) s.x = 1u;  // xoshiro's one forbidden state (one key in 2^128 maps to it)
  return s;
}

uint rotl32(uint x, uint k) { return (x << k) | (x >> (32u - k)); }

// Uniform float in [0, 1): the top 24 bits of xoshiro128+ (its best bits).
float rand01(inout uvec4 s) {
  uint result = s.x + s.w;
  uint t = s.y << 9u;
  s.z ^= s.x;
  s.w ^= s.y;
  s.y ^= s.z;
  s.x ^= s.w;
  s.z ^= t;
  s.w = rotl32(s.w, 11u);
  return float(result >> 8u) * (1.0 / 16777216.0);
}

vec2 rand2(inout uvec4 s) { return vec2(rand01(s), rand01(s)); }
