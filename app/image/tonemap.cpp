// tonemap.cpp — exposure, tone curves (clamp, ACES filmic fit by Narkowicz 2015) and sRGB encoding.
#include "image/tonemap.h"

#include <cmath>

#include "util/error.h"

namespace caustica {

ToneCurve parseToneCurve(const std::string& name) {
  if (name == "clamp") return ToneCurve::Clamp;
  if (name == "aces") return ToneCurve::Aces;
  throw Error("unknown tone curve '" + name + "' (expected clamp or aces)");
}

const char* toneCurveName(ToneCurve curve) { return curve == ToneCurve::Clamp ? "clamp" : "aces"; }

glm::vec3 tonemapCurve(const glm::vec3& x, ToneCurve curve) {
  if (curve == ToneCurve::Aces)
    return glm::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
  return glm::clamp(x, 0.0f, 1.0f);
}

glm::vec3 linearToSrgb(const glm::vec3& c) {
  glm::vec3 out;
  for (int i = 0; i < 3; ++i)
    out[i] = c[i] <= 0.0031308f ? c[i] * 12.92f : 1.055f * std::pow(c[i], 1.0f / 2.4f) - 0.055f;
  return out;
}

std::vector<std::uint8_t> tonemapImage(const std::vector<float>& rgb, const ToneMapSettings& settings) {
  std::vector<std::uint8_t> out(rgb.size());
  float scale = std::exp2(settings.exposureStops);
  for (size_t i = 0; i + 2 < rgb.size(); i += 3) {
    glm::vec3 c(rgb[i], rgb[i + 1], rgb[i + 2]);
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(c[k]) || c[k] < 0.0f) c[k] = 0.0f;
    glm::vec3 s = linearToSrgb(tonemapCurve(c * scale, settings.curve));
    for (int k = 0; k < 3; ++k) out[i + k] = static_cast<std::uint8_t>(std::lround(glm::clamp(s[k], 0.0f, 1.0f) * 255.0f));
  }
  return out;
}

}  // namespace caustica
