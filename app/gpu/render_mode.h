// render_mode.h — the render modes (docs/render-modes.md), one row each in render_mode.cpp: the name
// --mode takes, the entry shader that makes the image, how many samples a dispatch traces, what the
// mode needs from the scene and what it shows. The Renderer, the commands and the tests read the
// rows rather than asking which mode they are in. No GL.
#pragma once
#include <string>
#include <vector>

namespace caustica {

// How the image is made: the path tracer, a Whitted ray tracer (compute shader, point lights, mirrors
// and glass, no global illumination) or the OpenGL raster pipeline.
enum class RenderMode { Path, Whitted, Raster };

// How a mode's samples per pixel are made.
enum class SampleRule {
  Regeneration,    // K samples per pixel in one dispatch (path regeneration), K within llvmpipe's loop
                   // cap for the depth cap (Renderer::samplesPerDispatch)
  OnePerDispatch,  // one sample per pixel per dispatch
  OneFrame,        // one deterministic frame per restart: further samples add nothing
};

struct RenderModeSpec {
  RenderMode mode;
  const char* name;         // what --mode takes and settings and checkpoints print
  const char* help;         // its part of --mode's help
  // Compute entry shader in glsl/ (Renderer::program compiles it with the shader-feature table's
  // defines), or nullptr: the raster pipeline draws the mode (RasterRenderer, glsl/raster/).
  const char* entryShader;
  SampleRule samples;
  // The path tracer's estimator options apply (--integrator, --dispersion, --caster-probability,
  // --all-features): the shader-feature table's integrator rows compile in (shader_features.h).
  bool pathTracer;
  bool tracksCoverage;   // --background transparent gives the image an alpha channel (coverage.glsl)
  bool seesEnvironment;  // the environment lights it (else only emitters and punctual lights do)
  bool instancedScenes;  // traces instanced scenes' two-level BVH; else they are flattened on the host first
};

// Every mode, in --mode's order (the viewer's M key cycles through them in this order).
const std::vector<RenderModeSpec>& renderModes();
const RenderModeSpec& renderModeSpec(RenderMode m);
RenderMode parseRenderMode(const std::string& name);  // a row's name; throws Error naming the others otherwise
const char* renderModeName(RenderMode m);
// "path, whitted or raster": the names of the modes `keep` accepts, for help and error texts.
std::string renderModeNames(bool (*keep)(const RenderModeSpec&) = nullptr);
std::string renderModeHelp();  // --mode's help text, from the rows' help
// The mode after `m` in renderModes() order, skipping modes that cannot draw an instanced scene when
// `instancedScene` (the viewer's M key).
RenderMode nextRenderMode(RenderMode m, bool instancedScene);

}  // namespace caustica
