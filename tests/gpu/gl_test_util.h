// gl_test_util.h — helpers shared by the GPU tests: render a scene file or an in-memory scene and
// get the linear image back, and per-region statistics.
#pragma once
#include <doctest/doctest.h>
#include "scene/assets.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "image/image_io.h"
#include "gpu/renderer.h"
#include "scene/scene.h"
#include "util/math_constants.h"
#include "gpu/shader_library.h"

namespace caustica::test {

extern std::string gGlDescription;

inline std::string sourcePath(const std::string& rel) { return sourceDir() + "/" + rel; }

struct RenderResult {
  Image image;
  RenderStats stats;
  std::vector<std::string> defines;  // the shader variant that rendered it
};

// The embedded shaders, one library for every GL test (it holds no GL state: sources and expansion only).
inline ShaderLibrary& testShaderLibrary() {
  static ShaderLibrary library;
  return library;
}

inline RenderResult renderScene(const Scene& scene, const Camera& camera, RenderSettings settings, int spp,
                                int sppPerPass = 8) {
  Renderer r(testShaderLibrary(), scene, camera, settings);
  while (r.samplesPerPixel() < spp) r.renderPass(std::min(sppPerPass, spp - r.samplesPerPixel()));
  return {r.image(), r.stats(), r.shaderDefines()};
}

// A quad as two triangles with flat normals; a, b, c, d counter-clockwise seen from its front.
inline void addQuad(Scene& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t material) {
  glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  for (auto tri : {std::array<glm::vec3, 3>{a, b, c}, std::array<glm::vec3, 3>{a, c, d}}) {
    Triangle t{};
    for (int i = 0; i < 3; ++i) {
      t.p[i] = tri[i];
      t.setNormal(i, n);
    }
    t.material = material;
    s.triangles.push_back(t);
  }
}

// A UV sphere of 2 * segments^2 triangles with smooth (radial) normals, outward fronts.
inline void addSphere(Scene& s, glm::vec3 center, float radius, int segments, std::uint32_t material) {
  auto point = [&](int i, int j) {
    float theta = kPi * i / segments, phi = 2 * kPi * j / (2 * segments);
    return glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
  };
  for (int i = 0; i < segments; ++i)
    for (int j = 0; j < 2 * segments; ++j) {
      glm::vec3 q[4] = {point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)};
      for (auto idx : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
        Triangle t{};
        for (int k = 0; k < 3; ++k) {
          t.setNormal(k, q[idx[k]]);
          t.p[k] = center + radius * q[idx[k]];
        }
        if (glm::length(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0])) == 0.0f) continue;  // pole slivers
        t.material = material;
        s.triangles.push_back(t);
      }
    }
}

// A relative tolerance: |x - value| <= rel |value| + abs (doctest::Approx's epsilon is relative to
// 1 + |value|, which is far too loose for small values).
struct Rel {
  double value, rel, abs;
  Rel(double v, double r, double a = 0.0) : value(v), rel(r), abs(a) {}
};
inline bool operator==(double x, const Rel& r) { return std::abs(x - r.value) <= r.rel * std::abs(r.value) + r.abs; }
inline doctest::String toString(const Rel& r) {
  std::ostringstream s;
  s << r.value << " (within " << 100.0 * r.rel << " %)";
  return doctest::String(s.str().c_str());
}

inline Camera sceneCamera(const Scene& s) { return s.cameras.empty() ? autoCamera(s.bounds) : s.cameras[0]; }

inline double meanOf(const Image& img, int channel = -1) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < img.rgb.size(); ++i)
    if (channel < 0 || static_cast<int>(i % 3) == channel) {
      sum += img.rgb[i];
      ++n;
    }
  return sum / static_cast<double>(n);
}

// Whether the shader variant `defines` holds `name` (the whole entry, value included).
inline bool hasDefine(const std::vector<std::string>& defines, const std::string& name) {
  return std::find(defines.begin(), defines.end(), name) != defines.end();
}

// Floats that differ between two arrays, bit for bit (0: equal; different sizes count every value).
inline std::size_t differing(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return a.size() + b.size();
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) n += std::memcmp(&a[i], &b[i], sizeof(float)) != 0;
  return n;
}

}  // namespace caustica::test
