// environment_textures.h — the environment light's GPU side: its map and CDFs as two rgba32f
// textures read with texelFetch (no SSBO slot is free) and its parameter UBO (gpu_layout.h).
#pragma once
#include "accel/gpu_scene.h"
#include "gpu/gl_limits.h"
#include "gpu/gl_objects.h"

namespace caustica {

class EnvironmentTextures {
 public:
  EnvironmentTextures() = default;
  // Uploads `scene`'s environment (a 1x1 black placeholder when there is none). Throws Error if
  // the map exceeds the GPU's texture size.
  void upload(const GpuScene& scene, const GlLimits& limits, const std::string& sceneName);
  // Binds the textures to CAUSTICA_TEXUNIT_ENV_* and the UBO to CAUSTICA_BINDING_ENVIRONMENT.
  void bind() const;

 private:
  GlTexture map_, marginal_;
  GlBuffer ubo_;
};

}  // namespace caustica
