// texture_wrap.glsl — texel coordinates wrapped into a texture (glTF sampler wrap modes) without integer
// division. Twin: app/shading/texture_wrap.cpp (tests/gpu/twins_gpu_test.cpp, tests/shading/texture_wrap_test.cpp).

// i mod n in [0, n) (floored), without an integer division: SIMD hardware has none (llvmpipe divides
// lane by lane, 8 scalar divisions per call, which made cornell-textured 1.4x slower). For |i| <= 2^24
// and 0 < n <= 2^20, i and n are exact floats; a quotient within a few ulp (a GPU's fast division) puts
// the first remainder within a few periods of [0, n), the second step within one, and the corrections
// finish: the same result as ((i % n) + n) % n.
int floorMod(int i, int n) {
  float fn = float(n);
  int m = i - n * int(floor(float(i) / fn));
  m -= n * int(floor(float(m) / fn));
  m += m < 0 ? n : 0;
  m -= m >= n ? n : 0;
  return m;
}

// Texel index i wrapped into [0, n): mirrored repeat (taking precedence), repeat, or clamp to the edge.
int wrapCoord(int i, int n, bool repeat, bool mirror) {
  if (!repeat && !mirror) return clamp(i, 0, n - 1);
  int period = mirror ? 2 * n : n;
  int m = floorMod(i, period);
  return mirror && m >= n ? period - 1 - m : m;
}
