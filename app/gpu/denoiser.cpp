// denoiser.cpp — the denoiser's GL side: its two programs, intermediate images and dispatches.
#include "gpu/denoiser.h"

#include <utility>

#include "util/error.h"

namespace caustica {

namespace {

GlProgram compileStage(const ShaderLibrary& library, const char* define) {
  ExpandedShader src = library.expand("denoise.comp", {define});
  return GlProgram::compileCompute(src.source, [&](const std::string& log) { return src.mapLog(log); }, "denoise.comp");
}

}  // namespace

const std::array<const char*, 3>& denoiseStageDefines() {
  static const std::array<const char*, 3> stages = {"CAUSTICA_DENOISE_PREPARE", "CAUSTICA_DENOISE_PASS",
                                                    "CAUSTICA_DENOISE_RESIDUAL"};
  return stages;
}

Denoiser::Denoiser(const ShaderLibrary& library)
    : prepare_(compileStage(library, denoiseStageDefines()[0])),
      pass_(compileStage(library, denoiseStageDefines()[1])),
      residual_(compileStage(library, denoiseStageDefines()[2])) {}

const GlTexture& Denoiser::run(const GlTexture& accum, const GlTexture& albedo, const GlTexture& normal,
                               const DenoiseSettings& settings) {
  if (settings.iterations < 1) throw Error("internal: the denoiser needs at least one pass");
  const int w = accum.width(), h = accum.height();
  if (output_.width() != w || output_.height() != h) {
    for (GlTexture* t : {&ping_, &pong_, &guide_, &centre_, &output_, &residualA_, &residualB_})
      *t = GlTexture::create2D(w, h, GL_RGBA32F);
  }
  const GLuint groupsX = GLuint((w + CAUSTICA_WORKGROUP_X - 1) / CAUSTICA_WORKGROUP_X);
  const GLuint groupsY = GLuint((h + CAUSTICA_WORKGROUP_Y - 1) / CAUSTICA_WORKGROUP_Y);
  // Uniform locations as glsl/denoise.comp declares them, each set only in the stage that has it.
  accum.bindImage(CAUSTICA_DENOISE_IMAGE_ACCUM, GL_READ_ONLY);
  guide_.bindImage(CAUSTICA_DENOISE_IMAGE_GUIDE, GL_READ_WRITE);
  centre_.bindImage(CAUSTICA_DENOISE_IMAGE_CENTRE, GL_READ_WRITE);

  prepare_.use();
  glUniform1f(3, settings.sigmaDepth);
  glUniform1f(4, settings.albedoFloor);
  albedo.bindImage(CAUSTICA_DENOISE_IMAGE_ALBEDO, GL_READ_ONLY);
  normal.bindImage(CAUSTICA_DENOISE_IMAGE_NORMAL, GL_READ_ONLY);
  ping_.bindImage(CAUSTICA_DENOISE_IMAGE_PONG, GL_WRITE_ONLY);
  glDispatchCompute(groupsX, groupsY, 1);
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);

  pass_.use();
  glUniform1f(2, settings.sigmaLuminance);
  glUniform1f(3, settings.sigmaDepth);
  GlTexture* in = &ping_;
  GlTexture* out = &pong_;
  const bool spread = settings.residualPasses > 0;
  (spread ? residualA_ : output_).bindImage(CAUSTICA_DENOISE_IMAGE_OUTPUT, GL_WRITE_ONLY);
  for (int pass = 0; pass < settings.iterations; ++pass) {
    in->bindImage(CAUSTICA_DENOISE_IMAGE_PING, GL_READ_ONLY);
    out->bindImage(CAUSTICA_DENOISE_IMAGE_PONG, GL_WRITE_ONLY);
    glUniform1i(0, 1 << pass);
    glUniform1i(1, pass + 1 < settings.iterations ? 0 : spread ? 2 : 1);
    glDispatchCompute(groupsX, groupsY, 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    std::swap(in, out);
  }
  if (spread) {  // `in` holds the filtered illumination
    residual_.use();
    glUniform1f(3, settings.sigmaDepth);
    glUniform1f(5, settings.sigmaResidual);
    glUniform1f(6, settings.residualBound);
    albedo.bindImage(CAUSTICA_DENOISE_IMAGE_MOMENTS, GL_READ_ONLY);
    in->bindImage(CAUSTICA_DENOISE_IMAGE_FILTERED, GL_READ_ONLY);
    output_.bindImage(CAUSTICA_DENOISE_IMAGE_OUTPUT, GL_WRITE_ONLY);
    GlTexture* rin = &residualA_;
    GlTexture* rout = &residualB_;
    for (int pass = 0; pass < settings.residualPasses; ++pass) {
      rin->bindImage(CAUSTICA_DENOISE_IMAGE_PING, GL_READ_ONLY);
      rout->bindImage(CAUSTICA_DENOISE_IMAGE_PONG, GL_WRITE_ONLY);
      glUniform1i(0, 1 << pass);
      glUniform1i(1, pass + 1 == settings.residualPasses ? 1 : 0);
      glDispatchCompute(groupsX, groupsY, 1);
      glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
      std::swap(rin, rout);
    }
  }
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
  glFinish();
  checkGlError("denoising");
  return output_;
}

}  // namespace caustica
