// environment.h — the light at infinity: an equirectangular map of linear radiance (.hdr, .exr) or a
// uniform sky, and what camera rays that escape see (the background). Conventions in docs/lighting.md.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace caustica {

// Radiance arriving from every direction that leaves the scene. Directions are glTF world axes
// (+Y up). Map convention (Blender's world): for unit d in the map's frame, column
// u = 0.5 + atan2(d.z, d.x) / 2pi from the left, row v = acos(d.y) / pi from the top; the centre is +X.
struct Environment {
  enum class Kind { None, Uniform, Map };
  Kind kind = Kind::None;
  std::string source;          // file name, "uniform" or "default" (for messages and `info`)
  int width = 0, height = 0;   // texels of `rgb`; 1 x kUniformRows for a uniform sky
  std::vector<float> rgb;      // width * height * 3 linear radiance, strength applied, row 0 = top (v = 0)
  glm::vec3 uniform{0.0f};     // Uniform: the radiance (strength applied)
  float strength = 1.0f;       // multiplier already applied to rgb / uniform
  float rotationDegrees = 0.0f;  // the map turned about +Y, right-handed: +90 moves what was at +X to -Z
  bool isDefault = false;      // the neutral default a scene without lights gets (docs/lighting.md)

  // Whether any direction carries radiance (a black map or --env 0 lights nothing).
  bool emits() const;
  std::string describe() const;  // one line: "uniform (1, 1, 1)" or "sky.hdr 256x128, strength 2, rotation 30 deg"
};

// What camera rays that leave the scene see: the environment, a colour, or nothing (alpha 0).
struct Background {
  enum class Kind { Environment, Color, Transparent };
  Kind kind = Kind::Environment;
  glm::vec3 color{0.0f};  // Kind::Color: linear radiance
  std::string describe() const;
};

constexpr int kUniformRows = 32;       // rows of the 1-column map that stands for a uniform sky
constexpr float kDefaultEnvironmentRadiance = 1.0f;  // the neutral default: uniform radiance 1

// A uniform sky of radiance `radiance` (times `strength`).
Environment uniformEnvironment(const glm::vec3& radiance, float strength = 1.0f);
// Reads an equirectangular map of linear radiance: Radiance .hdr (RGBE) or OpenEXR .exr. Negative
// values are clamped to 0; NaN, Inf, empty or unreadable files throw Error naming the file.
Environment loadEnvironmentMap(const std::string& path, float strength = 1.0f, float rotationDegrees = 0.0f);
// A file name as given, or else a bundled map of that name (assets/env/NAME[.hdr|.exr]).
std::string resolveEnvironmentPath(const std::string& nameOrPath);
// Builds an environment from the text of --env: "none", a number "0.8", "R,G,B", or a file name.
Environment parseEnvironment(const std::string& text, float strength, float rotationDegrees);
// Parses --background: "env", "transparent" (radiance 0 and alpha 0 where camera rays leave the scene)
// or a colour ("0.2" or "R,G,B").
Background parseBackground(const std::string& text);
// Parses "x" or "r,g,b" of non-negative finite numbers; false if `text` is not one.
bool parseColor(const std::string& text, glm::vec3& out);

}  // namespace caustica
