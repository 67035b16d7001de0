// environment_textures.cpp — uploads the environment map, its CDFs and parameters (see the header).
#include "gpu/environment_textures.h"

#include "util/error.h"

namespace caustica {

void EnvironmentTextures::upload(const GpuScene& scene, const GlLimits& limits, const std::string& sceneName) {
  const EnvironmentDistribution& e = scene.environment;
  const int w = e.width > 0 ? e.width : 1, h = e.height > 0 ? e.height : 1;
  if (w > limits.maxTextureSize || h > limits.maxTextureSize)
    throw Error(sceneName + ": the environment map is " + std::to_string(w) + "x" + std::to_string(h) +
                " but this GPU's textures hold at most " + std::to_string(limits.maxTextureSize) + " texels a side");
  std::vector<float> map(static_cast<size_t>(w) * h * 4, 0.0f), marginal(static_cast<size_t>(h) * 4, 0.0f);
  if (e.width > 0) {
    for (size_t i = 0; i < static_cast<size_t>(w) * h; ++i) {
      for (int c = 0; c < 3; ++c) map[i * 4 + c] = e.rgb[i * 3 + c];
      map[i * 4 + 3] = e.conditionalCdf[i];
    }
    for (int y = 0; y < h; ++y) marginal[static_cast<size_t>(y) * 4] = e.marginalCdf[static_cast<size_t>(y)];
  }
  map_ = GlTexture::create2D(w, h, GL_RGBA32F);
  map_.uploadRgba32f(map);
  marginal_ = GlTexture::create2D(h, 1, GL_RGBA32F);
  marginal_.uploadRgba32f(marginal);
  ubo_ = GlBuffer::create(sizeof(gpu::EnvironmentParams), &scene.environmentParams, GL_STATIC_DRAW);
  checkGlError("environment upload");
}

void EnvironmentTextures::bind() const {
  glActiveTexture(GL_TEXTURE0 + CAUSTICA_TEXUNIT_ENV_MAP);
  glBindTexture(GL_TEXTURE_2D, map_.id());
  glActiveTexture(GL_TEXTURE0 + CAUSTICA_TEXUNIT_ENV_MARGINAL);
  glBindTexture(GL_TEXTURE_2D, marginal_.id());
  glActiveTexture(GL_TEXTURE0);
  ubo_.bindBase(GL_UNIFORM_BUFFER, CAUSTICA_BINDING_ENVIRONMENT);
}

}  // namespace caustica
