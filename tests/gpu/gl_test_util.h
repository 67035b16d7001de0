// gl_test_util.h — helpers shared by the GPU tests: render a scene file or an in-memory scene (built
// with scene_builder.h) and get the linear image back, and per-region statistics.
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
#include "gpu/gl_objects.h"
#include "gpu/renderer.h"
#include "scene/scene.h"
#include "util/math_constants.h"
#include "gpu/shader_library.h"
#include "scene_builder.h"

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

// A test entry shader of glsl/tests ("tests/NAME.comp") with feature defines, compiled with its log mapped
// to the library's files.
inline GlProgram compileTestShader(const std::string& path, const std::vector<std::string>& defines = {}) {
  ExpandedShader src = testShaderLibrary().expand(path, defines);
  return GlProgram::compileCompute(src.source, [&](const std::string& log) { return src.mapLog(log); }, path);
}

// Settings of a small test render: w x h pixels, the integrator and the seed; all else the defaults.
inline RenderSettings smallSettings(int w, int h, Integrator integrator = Integrator::Mis, std::uint32_t seed = 1) {
  RenderSettings s;
  s.width = w;
  s.height = h;
  s.integrator = integrator;
  s.seed = seed;
  return s;
}

inline RenderResult renderScene(const Scene& scene, const Camera& camera, RenderSettings settings, int spp,
                                int sppPerPass = 8) {
  Renderer r(testShaderLibrary(), scene, camera, settings);
  while (r.samplesPerPixel() < spp) r.renderPass(std::min(sppPerPass, spp - r.samplesPerPixel()));
  return {r.image(), r.stats(), r.shaderDefines()};
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

// Grey means ((r + g + b) / 3) of the whole image and of its four quadrants: top left, top right,
// bottom left, bottom right.
inline std::array<double, 5> quadrantMeans(const Image& img) {
  const int w = img.width, h = img.height;
  std::array<double, 5> reg{};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double grey = (img.at(x, y, 0) + img.at(x, y, 1) + img.at(x, y, 2)) / 3.0;
      reg[0] += grey / (w * h);
      reg[1 + (y >= h / 2 ? 2 : 0) + (x >= w / 2 ? 1 : 0)] += grey / (w * h / 4.0);
    }
  return reg;
}

// Whether the shader variant `defines` holds `name` (the whole entry, value included).
inline bool hasDefine(const std::vector<std::string>& defines, const std::string& name) {
  return std::find(defines.begin(), defines.end(), name) != defines.end();
}

// Float bits to uints and back (memcpy: glm's vector floatBitsToUint casts through a reference, which
// GCC's aliasing rules break).
template <class To, class From>
To sameBits(const From& v) {
  static_assert(sizeof(To) == sizeof(From));
  To out;
  std::memcpy(&out, &v, sizeof out);
  return out;
}

// Floats that differ between two arrays, bit for bit (0: equal; different sizes count every value).
inline std::size_t differing(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return a.size() + b.size();
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) n += std::memcmp(&a[i], &b[i], sizeof(float)) != 0;
  return n;
}

}  // namespace caustica::test
