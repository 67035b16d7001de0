// environment.cpp — environment maps (.hdr through stb_image, .exr through OpenEXR), uniform skies,
// and the text of --env / --background.
#include "scene/environment.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include <stb_image.h>

#include "image/image_io.h"
#include "scene/assets.h"
#include "util/error.h"

namespace caustica {

namespace {
std::string number(float x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", x);
  return b;
}
std::string colorText(const glm::vec3& c) {
  if (c.r == c.g && c.g == c.b) return number(c.r);
  return "(" + number(c.r) + ", " + number(c.g) + ", " + number(c.b) + ")";
}
}  // namespace

bool Environment::emits() const {
  if (kind == Kind::None) return false;
  for (float v : rgb)
    if (v > 0.0f) return true;
  return false;
}

std::string Environment::describe() const {
  if (kind == Kind::None) return "none";
  std::string s;
  if (kind == Kind::Uniform) s = "uniform radiance " + colorText(uniform);
  else s = source + " " + std::to_string(width) + "x" + std::to_string(height) + ", strength " + number(strength) +
           ", rotation " + number(rotationDegrees) + " deg";
  if (isDefault) s += " (default: the scene has no emitters and no --env)";
  return s;
}

std::string Background::describe() const {
  switch (kind) {
    case Kind::Environment: return "env";
    case Kind::Color: return "colour " + colorText(color);
    case Kind::Transparent: return "transparent";
  }
  return "";
}

Environment uniformEnvironment(const glm::vec3& radiance, float strength) {
  Environment e;
  e.kind = Environment::Kind::Uniform;
  e.source = "uniform";
  e.strength = strength;
  e.uniform = radiance * strength;
  // A one-column map whose rows importance-sample sin(theta): nearly uniform over the sphere, and
  // every lookup returns exactly `uniform`.
  e.width = 1;
  e.height = kUniformRows;
  e.rgb.resize(static_cast<size_t>(kUniformRows) * 3);
  for (int y = 0; y < kUniformRows; ++y)
    for (int c = 0; c < 3; ++c) e.rgb[static_cast<size_t>(y) * 3 + c] = e.uniform[c];
  return e;
}

Environment loadEnvironmentMap(const std::string& path, float strength, float rotationDegrees) {
  std::string ext = fileExtension(path);
  Environment e;
  e.kind = Environment::Kind::Map;
  e.source = path;
  e.strength = strength;
  e.rotationDegrees = rotationDegrees;
  if (ext == ".hdr") {
    if (!stbi_is_hdr(path.c_str())) {
      FILE* f = std::fopen(path.c_str(), "rb");
      if (!f) throw Error(path + ": cannot open the environment map");
      std::fclose(f);
      throw Error(path + ": not a Radiance .hdr file (no '#?RADIANCE' or '#?RGBE' header)");
    }
    int w = 0, h = 0, n = 0;
    float* data = stbi_loadf(path.c_str(), &w, &h, &n, 3);
    if (!data) throw Error(path + ": cannot read the environment map (" + stbi_failure_reason() + ")");
    e.width = w;
    e.height = h;
    e.rgb.assign(data, data + static_cast<size_t>(w) * h * 3);
    stbi_image_free(data);
  } else if (ext == ".exr") {
    Image img = readImage(path);
    e.width = img.width;
    e.height = img.height;
    e.rgb = std::move(img.rgb);
  } else {
    throw Error(path + ": environment maps must be .hdr (Radiance) or .exr (OpenEXR), not '" + ext + "'");
  }
  if (e.width < 1 || e.height < 1) throw Error(path + ": the environment map is empty");
  for (float& v : e.rgb) {
    if (!std::isfinite(v)) throw Error(path + ": the environment map holds NaN or infinite values");
    v = v > 0.0f ? v * strength : 0.0f;
    if (!std::isfinite(v)) throw Error(path + ": --env-strength makes the map's radiance overflow");
  }
  return e;
}

bool parseColor(const std::string& text, glm::vec3& out) {
  std::vector<float> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    float x = std::strtof(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(x) || x < 0.0f) return false;
    v.push_back(x);
  }
  if (!text.empty() && text.back() == ',') return false;
  if (v.size() == 1) out = glm::vec3(v[0]);
  else if (v.size() == 3) out = glm::vec3(v[0], v[1], v[2]);
  else return false;
  return true;
}

std::string resolveEnvironmentPath(const std::string& nameOrPath) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(nameOrPath, ec) || nameOrPath.find('/') != std::string::npos) return nameOrPath;
  const fs::path dir = fs::path(assetSceneDir()).parent_path() / "env";
  for (const char* ext : {"", ".hdr", ".exr"}) {
    fs::path p = dir / (nameOrPath + ext);
    if (fs::is_regular_file(p, ec)) return p.string();
  }
  return nameOrPath;
}

Environment parseEnvironment(const std::string& text, float strength, float rotationDegrees) {
  if (!std::isfinite(strength) || strength < 0.0f)
    throw Error("option --env-strength needs a non-negative number, got " + number(strength));
  if (!std::isfinite(rotationDegrees)) throw Error("option --env-rotation needs a finite number of degrees");
  if (text == "none") return Environment{};
  glm::vec3 c;
  if (parseColor(text, c)) {
    Environment e = uniformEnvironment(c, strength);
    e.rotationDegrees = rotationDegrees;
    return e;
  }
  std::string path = resolveEnvironmentPath(text);
  std::string ext = fileExtension(path);
  if (ext != ".hdr" && ext != ".exr")
    throw Error("option --env needs none, a radiance (0.8 or R,G,B, non-negative) or a .hdr/.exr file, got '" +
                text + "'");
  return loadEnvironmentMap(path, strength, rotationDegrees);
}

Background parseBackground(const std::string& text) {
  Background b;
  if (text == "env") return b;
  if (text == "transparent") {
    b.kind = Background::Kind::Transparent;
    return b;
  }
  if (!parseColor(text, b.color))
    throw Error("option --background needs env, transparent or a colour (0.2 or R,G,B, non-negative), got '" + text +
                "'");
  b.kind = Background::Kind::Color;
  return b;
}

}  // namespace caustica
