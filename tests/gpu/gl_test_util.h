// gl_test_util.h — helpers shared by the GPU tests: render a scene file or an in-memory scene and
// get the linear image back, and per-region statistics.
#pragma once
#include <algorithm>
#include <string>
#include <vector>

#include "image/image_io.h"
#include "gpu/renderer.h"
#include "scene/scene.h"
#include "gpu/shader_library.h"

namespace caustica::test {

extern std::string gGlDescription;

inline std::string sourcePath(const std::string& rel) { return std::string(CAUSTICA_SOURCE_DIR) + "/" + rel; }

struct RenderResult {
  Image image;
  RenderStats stats;
  std::vector<std::string> defines;  // the shader variant that rendered it
};

inline RenderResult renderScene(const Scene& scene, const Camera& camera, RenderSettings settings, int spp,
                                int sppPerPass = 8) {
  static ShaderLibrary library;
  Renderer r(library, scene, camera, settings);
  while (r.samplesPerPixel() < spp) r.renderPass(std::min(sppPerPass, spp - r.samplesPerPixel()));
  return {r.image(), r.stats(), r.shaderDefines()};
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

}  // namespace caustica::test
