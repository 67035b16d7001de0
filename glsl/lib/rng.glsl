// rng.glsl — PCG random numbers (O'Neill; hash form from Jarzynski & Olano 2020). One stream per
// (pixel, global sample index, seed), so an image does not depend on how samples are split into dispatches.

uint pcgHash(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

uint rngSeed(uint pixel, uint sampleIndex, uint seed) {
  return pcgHash(pixel ^ pcgHash(sampleIndex ^ pcgHash(seed)));
}

// Uniform float in [0, 1): 24 random bits.
float rand01(inout uint state) {
  state = state * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  word = (word >> 22u) ^ word;
  return float(word >> 8u) * (1.0 / 16777216.0);
}

vec2 rand2(inout uint state) { return vec2(rand01(state), rand01(state)); }
