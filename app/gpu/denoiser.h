// denoiser.h — runs the à-trous denoiser (glsl/denoise.comp; docs/denoising.md) on the GPU over the
// renderer's accumulation and feature images. The filter's arithmetic and its C++ twin: image/denoise.h.
#pragma once
#include <array>

#include "gpu/gl_objects.h"
#include "gpu/shader_library.h"
#include "image/denoise.h"
#include "shared/gpu_layout.h"

namespace caustica {

// The defines that select glsl/denoise.comp's stages, each compiled as a program of its own: prepare
// (demodulate, variance, guide), one à-trous pass, one residual pass. Stage selectors, not features:
// the shader-feature table does not list them.
const std::array<const char*, 3>& denoiseStageDefines();

class Denoiser {
 public:
  // Compiles the three stages (needs a current GL 4.3 context).
  explicit Denoiser(const ShaderLibrary& library);
  // Filters the sums in `accum` (rgba32f: rgb radiance sum, a count) guided by the feature sums
  // (feature_buffers.glsl) and returns the output, rgba32f in the same convention (rgb = denoised mean
  // x count, a = count), valid until the next run. Waits for the GPU (glFinish) so callers can time it.
  const GlTexture& run(const GlTexture& accum, const GlTexture& albedo, const GlTexture& normal,
                       const DenoiseSettings& settings = {});

 private:
  GlProgram prepare_, pass_, residual_;
  GlTexture ping_, pong_, guide_, centre_, output_, residualA_, residualB_;  // at the size of the last run's images
};

}  // namespace caustica
