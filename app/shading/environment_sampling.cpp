// environment_sampling.cpp — C++ twin of glsl/lib/environment.glsl; see environment_sampling.h.
#include "shading/environment_sampling.h"

#include <algorithm>
#include <cmath>

#include "shading/sampling.h"
#include "util/error.h"
#include "util/math_constants.h"

namespace caustica {

namespace {
// Smallest i in [0, n) with cdf[i] > u (n - 1 if none): the interval of a piecewise-constant
// distribution that u falls in. Same loop as the GLSL (findInterval over a texture row).
int findInterval(const float* cdf, int n, float u) {
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    int mid = (lo + hi) / 2;
    if (cdf[mid] > u) hi = mid;
    else lo = mid + 1;
  }
  return lo;
}
constexpr float kTwoPi = 6.28318530717958647692f;
constexpr float kInvTwoPi = 0.15915494309189533577f;
}  // namespace

EnvironmentDistribution buildEnvironmentDistribution(const Environment& env) {
  EnvironmentDistribution d;
  const int w = env.width, h = env.height;
  if (w < 1 || h < 1 || env.rgb.size() != static_cast<size_t>(w) * h * 3)
    throw Error("internal: environment map without texels");
  if (w > 16384 || h > 16384)
    throw Error(env.source + ": the environment map is " + std::to_string(w) + "x" + std::to_string(h) +
                "; at most 16384 texels a side are supported");
  d.width = w;
  d.height = h;
  d.rgb = env.rgb;
  d.conditionalCdf.resize(static_cast<size_t>(w) * h);
  d.marginalCdf.resize(static_cast<size_t>(h));
  const double rad = static_cast<double>(env.rotationDegrees) * kPiD / 180.0;
  d.cosRotation = static_cast<float>(std::cos(rad));
  d.sinRotation = static_cast<float>(std::sin(rad));
  std::vector<double> rowSum(static_cast<size_t>(h), 0.0);
  double total = 0.0;
  for (int y = 0; y < h; ++y) {
    const double sinTheta = std::sin(kPiD * (y + 0.5) / h);
    double sum = 0.0;
    std::vector<double> cum(static_cast<size_t>(w));
    for (int x = 0; x < w; ++x) {
      const float* t = &env.rgb[(static_cast<size_t>(y) * w + x) * 3];
      sum += std::max(0.0, static_cast<double>(luminance(glm::vec3(t[0], t[1], t[2])))) * sinTheta;
      cum[static_cast<size_t>(x)] = sum;
    }
    for (int x = 0; x < w; ++x)  // a black row: uniform (never chosen: its marginal weight is 0)
      d.conditionalCdf[static_cast<size_t>(y) * w + x] =
          x == w - 1 ? 1.0f : static_cast<float>(sum > 0.0 ? cum[static_cast<size_t>(x)] / sum : (x + 1.0) / w);
    rowSum[static_cast<size_t>(y)] = sum;
    total += sum;
  }
  double cum = 0.0;
  for (int y = 0; y < h; ++y) {
    cum += rowSum[static_cast<size_t>(y)];
    d.marginalCdf[static_cast<size_t>(y)] =
        y == h - 1 ? 1.0f : static_cast<float>(total > 0.0 ? cum / total : (y + 1.0) / h);
  }
  return d;
}

glm::vec2 envDirectionToUv(const glm::vec3& d, float cosRot, float sinRot) {
  // Into the map's frame: rotate by -rotation about +Y.
  float x = cosRot * d.x - sinRot * d.z;
  float z = sinRot * d.x + cosRot * d.z;
  float u = 0.5f + std::atan2(z, x) * kInvTwoPi;
  // v = acos(d.y) / pi, as atan2: accurate everywhere (llvmpipe's acos is off by up to 1e-4 rad).
  float v = std::atan2(std::sqrt(x * x + z * z), d.y) * kInvPi;
  return {u, v};
}

glm::vec3 envUvToDirection(const glm::vec2& uv, float cosRot, float sinRot) {
  float phi = (uv.x - 0.5f) * kTwoPi;
  float theta = uv.y * kPi;
  float s = std::sin(theta);
  float x = s * std::cos(phi), y = std::cos(theta), z = s * std::sin(phi);
  return {cosRot * x + sinRot * z, y, -sinRot * x + cosRot * z};
}

namespace {
void texelOf(const EnvironmentDistribution& e, const glm::vec2& uv, int& x, int& y) {
  x = std::clamp(static_cast<int>(uv.x * static_cast<float>(e.width)), 0, e.width - 1);
  y = std::clamp(static_cast<int>(uv.y * static_cast<float>(e.height)), 0, e.height - 1);
}
float cdfStep(const float* cdf, int i) { return i > 0 ? cdf[i] - cdf[i - 1] : cdf[0]; }
}  // namespace

glm::vec3 environmentRadiance(const EnvironmentDistribution& e, const glm::vec3& d) {
  int x, y;
  texelOf(e, envDirectionToUv(d, e.cosRotation, e.sinRotation), x, y);
  const float* t = &e.rgb[(static_cast<size_t>(y) * e.width + x) * 3];
  return {t[0], t[1], t[2]};
}

float environmentPdf(const EnvironmentDistribution& e, const glm::vec3& d) {
  int x, y;
  texelOf(e, envDirectionToUv(d, e.cosRotation, e.sinRotation), x, y);
  float sinTheta = std::sqrt(std::max(0.0f, 1.0f - d.y * d.y));
  if (!(sinTheta > 0.0f)) return 0.0f;
  float pdfUv = cdfStep(e.marginalCdf.data(), y) * cdfStep(&e.conditionalCdf[static_cast<size_t>(y) * e.width], x) *
                static_cast<float>(e.width) * static_cast<float>(e.height);
  return pdfUv / (2.0f * kPi * kPi * sinTheta);
}

bool sampleEnvironment(const EnvironmentDistribution& e, const glm::vec2& u, glm::vec3& dir, glm::vec3& le, float& pdf) {
  int y = findInterval(e.marginalCdf.data(), e.height, u.y);
  float m0 = y > 0 ? e.marginalCdf[y - 1] : 0.0f;
  float rowProb = e.marginalCdf[y] - m0;
  const float* row = &e.conditionalCdf[static_cast<size_t>(y) * e.width];
  int x = findInterval(row, e.width, u.x);
  float c0 = x > 0 ? row[x - 1] : 0.0f;
  float colProb = row[x] - c0;
  // Where u fell inside the chosen interval, reused as the offset inside the texel.
  float dv = std::clamp((u.y - m0) / rowProb, 0.0f, 0.99999994f);
  float du = std::clamp((u.x - c0) / colProb, 0.0f, 0.99999994f);
  glm::vec2 uv((static_cast<float>(x) + du) / static_cast<float>(e.width),
               (static_cast<float>(y) + dv) / static_cast<float>(e.height));
  dir = envUvToDirection(uv, e.cosRotation, e.sinRotation);
  float sinTheta = std::sqrt(std::max(0.0f, 1.0f - dir.y * dir.y));
  const float* t = &e.rgb[(static_cast<size_t>(y) * e.width + x) * 3];
  le = glm::vec3(t[0], t[1], t[2]);
  pdf = rowProb * colProb * static_cast<float>(e.width) * static_cast<float>(e.height) / (2.0f * kPi * kPi * sinTheta);
  return sinTheta > 0.0f && rowProb > 0.0f && colProb > 0.0f;
}

}  // namespace caustica
