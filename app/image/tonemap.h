// tonemap.h — display transform for 8-bit output: exposure, tone curve, sRGB encoding.
// Linear outputs (.exr, .pfm) never pass through here. Twin of glsl/tonemap.comp.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace caustica {

enum class ToneCurve { Clamp = 0, Aces = 1 };

struct ToneMapSettings {
  float exposureStops = 0.0f;  // radiance is scaled by 2^stops before the curve
  ToneCurve curve = ToneCurve::Aces;
};

ToneCurve parseToneCurve(const std::string& name);  // "clamp" | "aces"; throws Error otherwise
const char* toneCurveName(ToneCurve curve);
glm::vec3 tonemapCurve(const glm::vec3& x, ToneCurve curve);
glm::vec3 linearToSrgb(const glm::vec3& c);
// Linear RGB floats (w*h*3) to 8-bit sRGB RGB bytes.
std::vector<std::uint8_t> tonemapImage(const std::vector<float>& rgb, const ToneMapSettings& settings);

}  // namespace caustica
