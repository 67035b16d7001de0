// math_constants.h — the constants of the C++ side (the GLSL side has its own in glsl/lib/sampling.glsl).
#pragma once

namespace caustica {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;
constexpr double kPiD = 3.14159265358979323846;

}  // namespace caustica
