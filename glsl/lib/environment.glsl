// environment.glsl — the environment map: equirectangular lookup and importance sampling by a
// piecewise-constant 2-D distribution on luminance x sin(theta). Twin: app/shading/environment_sampling.h.
// Texture envMap (rgba32f, width x height): rgb radiance, a conditional CDF within the row;
// texture envMarginal (rgba32f, height x 1): r marginal CDF over rows. Row 0 = top of the map (v = 0).
// Directions are unit world-space vectors (glTF axes); pdfs are per steradian. Needs sampling.glsl.

layout(std140, binding = CAUSTICA_BINDING_ENVIRONMENT) uniform EnvironmentBlock { EnvironmentParams environment; };
layout(binding = CAUSTICA_TEXUNIT_ENV_MAP) uniform sampler2D envMap;
layout(binding = CAUSTICA_TEXUNIT_ENV_MARGINAL) uniform sampler2D envMarginal;

const float kEnvTwoPi = 6.28318530717958647692;
const float kEnvInvTwoPi = 0.15915494309189533577;

bool environmentPresent() { return environment.size.x > 0u; }

float envConditionalCdf(int x, int y) { return texelFetch(envMap, ivec2(x, y), 0).a; }
float envMarginalCdf(int y) { return texelFetch(envMarginal, ivec2(y, 0), 0).r; }

// Map coordinates (u, v) in [0,1]^2 of world direction d under the rotation (cos, sin) about +Y.
vec2 envDirectionToUv(vec3 d, float cosRot, float sinRot) {
  float x = cosRot * d.x - sinRot * d.z;
  float z = sinRot * d.x + cosRot * d.z;
  float u = 0.5 + atan(z, x) * kEnvInvTwoPi;
  // v = acos(d.y) / pi, as atan2: accurate everywhere (llvmpipe's acos is off by up to 1e-4 rad).
  float v = atan(sqrt(x * x + z * z), d.y) * INV_PI;
  return vec2(u, v);
}

// The world direction at map coordinates uv (inverse of envDirectionToUv).
vec3 envUvToDirection(vec2 uv, float cosRot, float sinRot) {
  float phi = (uv.x - 0.5) * kEnvTwoPi;
  float theta = uv.y * PI;
  float s = sin(theta);
  float x = s * cos(phi), y = cos(theta), z = s * sin(phi);
  return vec3(cosRot * x + sinRot * z, y, -sinRot * x + cosRot * z);
}

ivec2 envTexelOf(vec2 uv) {
  int w = int(environment.size.x), h = int(environment.size.y);
  return ivec2(clamp(int(uv.x * float(w)), 0, w - 1), clamp(int(uv.y * float(h)), 0, h - 1));
}

// Radiance seen looking in direction d (nearest texel, piecewise constant like the sampling density).
vec3 environmentRadiance(vec3 d) {
  ivec2 t = envTexelOf(envDirectionToUv(d, environment.rotation.x, environment.rotation.y));
  return texelFetch(envMap, t, 0).rgb;
}

// Solid-angle density of sampleEnvironment at direction d.
float environmentPdf(vec3 d) {
  ivec2 t = envTexelOf(envDirectionToUv(d, environment.rotation.x, environment.rotation.y));
  float sinTheta = sqrt(max(0.0, 1.0 - d.y * d.y));
  if (!(sinTheta > 0.0)) return 0.0;
  float rowProb = envMarginalCdf(t.y) - (t.y > 0 ? envMarginalCdf(t.y - 1) : 0.0);
  float colProb = envConditionalCdf(t.x, t.y) - (t.x > 0 ? envConditionalCdf(t.x - 1, t.y) : 0.0);
  float pdfUv = rowProb * colProb * float(environment.size.x) * float(environment.size.y);
  return pdfUv / (2.0 * PI * PI * sinTheta);
}

// Draws a direction from two uniform numbers in [0,1): dir, its radiance le and pdf (per sr).
// False (nothing drawn) only at a pole, where the density is undefined.
bool sampleEnvironment(vec2 u, out vec3 dir, out vec3 le, out float pdf) {
  int w = int(environment.size.x), h = int(environment.size.y);
  // Row: smallest y with marginal CDF > u.y (binary search; the same steps as the C++ twin). Bottom-tested
  // loops: llvmpipe runs a loop's whole body (masked) in the iteration whose test at the top ends it, so
  // `while (lo < hi)` cost one CDF fetch and step more than the search (docs/architecture.md, "Writing shaders
  // for llvmpipe").
  int lo = 0, hi = h - 1;
  if (lo < hi) do {
    int mid = (lo + hi) / 2;
    if (envMarginalCdf(mid) > u.y) hi = mid;
    else lo = mid + 1;
  } while (lo < hi);
  int y = lo;
  float m0 = y > 0 ? envMarginalCdf(y - 1) : 0.0;
  float rowProb = envMarginalCdf(y) - m0;
  lo = 0;
  hi = w - 1;
  if (lo < hi) do {
    int mid = (lo + hi) / 2;
    if (envConditionalCdf(mid, y) > u.x) hi = mid;
    else lo = mid + 1;
  } while (lo < hi);
  int x = lo;
  float c0 = x > 0 ? envConditionalCdf(x - 1, y) : 0.0;
  vec4 texel = texelFetch(envMap, ivec2(x, y), 0);
  float colProb = texel.a - c0;
  // Where u fell inside the chosen interval, reused as the offset inside the texel.
  float dv = clamp((u.y - m0) / rowProb, 0.0, 0.99999994);
  float du = clamp((u.x - c0) / colProb, 0.0, 0.99999994);
  vec2 uv = vec2((float(x) + du) / float(w), (float(y) + dv) / float(h));
  dir = envUvToDirection(uv, environment.rotation.x, environment.rotation.y);
  float sinTheta = sqrt(max(0.0, 1.0 - dir.y * dir.y));
  le = texel.rgb;
  pdf = rowProb * colProb * float(w) * float(h) / (2.0 * PI * PI * sinTheta);
  return sinTheta > 0.0 && rowProb > 0.0 && colProb > 0.0;
}
