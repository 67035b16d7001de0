// cmd_compare.cpp — `caustica compare`: the same scene by the rasterizer, the Whitted ray tracer and
// the path tracer, side by side with each one's render time and the paper's table of effects.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "cli/cli_common.h"
#include "cli/commands.h"
#include "cli/compare_figure.h"
#include "image/image_io.h"
#include "platform/context.h"
#include "util/error.h"

namespace caustica::cli {

int cmdCompare(const std::vector<std::string>& args) {
  std::vector<OptionSpec> specs = {
      {"--output", "-o", "FILE", "the figure, .png (default compare.png)"},
      {"--spp", "", "N", "path tracer samples per pixel (default 64)"},
      {"--whitted-spp", "", "N", "Whitted jittered samples per pixel, for anti-aliasing (default 4)"},
      {"--save-panels", "", "PREFIX", "also write each mode's linear image as PREFIX-MODE.exr"},
      {"--exposure", "", "STOPS", "exposure in stops (default 0)"},
      {"--tonemap", "", "CURVE", "tone curve: aces (default) or clamp"},
  };
  for (auto& s : sceneOptionSpecs()) {
    if (s.name == "--mode") continue;  // compare renders every mode
    if (s.name == "--size") s.help = "size of each panel in pixels (default 384; H follows the camera's aspect)";
    specs.push_back(s);
  }
  Options opts("caustica compare [SCENE] [options]",
               "Renders SCENE three ways (docs/render-modes.md) - the OpenGL rasterizer (Blinn-Phong, shadow\n"
               "maps, planar mirrors, blended glass), the Whitted ray tracer (sharp shadows, mirrors, refraction,\n"
               "no global illumination) and the path tracer - and writes them side by side, each with its\n"
               "render time, beside the table of effects each one shows.",
               specs);
  if (!opts.parse(args)) return 0;
  const bool quiet = opts.has("--quiet");
  const std::string out = opts.get("--output", "compare.png");
  if (fileExtension(out) != ".png") throw Error(out + ": the compare figure is a .png file");
  const int spp = opts.getInt("--spp", 64, 1, 1 << 24);
  const int whittedSpp = opts.getInt("--whitted-spp", 4, 1, 4096);
  const std::string panelsPrefix = opts.get("--save-panels", "");
  Backend backend = parseBackend(opts.get("--backend", "auto"));
  checkWritableFile(out, "output");

  LoadedScene ls = loadSceneForCli(opts, !quiet, 384);
  for (const RenderModeSpec& m : renderModes()) flattenForMode(ls.scene, m.mode, opts, quiet);  // one scene for every mode
  RenderSettings settings = ls.settings.render;
  const ToneMapSettings& tone = ls.settings.tone;
  std::string glInfo;
  auto context = createHeadlessContext(backend, &glInfo);
  note(quiet, "OpenGL (" + context->backendName() + "): " + glInfo);
  ShaderLibrary library = shaderLibraryFrom(opts);
  settings.mode = RenderMode::Raster;
  Renderer renderer(library, ls.scene, ls.camera, settings);

  std::vector<ComparePanel> panels;
  // The paper's order, from the fewest effects to all of them (compare_figure.cpp's table has a column each).
  for (RenderMode mode : {RenderMode::Raster, RenderMode::Whitted, RenderMode::Path}) {
    const RenderModeSpec& spec = renderModeSpec(mode);
    settings.mode = mode;
    renderer.apply(settings);  // compiles the mode's shaders (not timed)
    // Drivers compile at the first dispatch or draw (llvmpipe: about a second): one row first, so
    // the time is the render's alone.
    renderer.renderRows(0, 1, 1);
    renderer.reset();
    const int n = spec.samples == SampleRule::OneFrame ? 1 : spec.pathTracer ? spp : whittedSpp;
    auto t0 = std::chrono::steady_clock::now();
    renderWithProgress(renderer, n, renderModeName(mode), quiet);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ComparePanel p;
    p.label = renderModeName(mode);
    char detail[96];
    if (spec.samples == SampleRule::OneFrame)
      std::snprintf(detail, sizeof detail, "1 frame, %.1f ms", seconds * 1000.0);
    else
      std::snprintf(detail, sizeof detail, "%d spp, %.2f s", n, seconds);
    p.detail = detail;
    p.image = renderer.image();
    note(quiet, p.label + ": " + p.detail);
    if (!panelsPrefix.empty()) writeImage(panelsPrefix + "-" + p.label + ".exr", p.image);
    panels.push_back(std::move(p));
  }
  std::string name = std::filesystem::path(ls.scene.path).stem().string();
  // "vendor | renderer | version": the renderer names the GPU (or llvmpipe).
  std::string gpuName = glInfo;
  size_t bar = gpuName.find(" | ");
  if (bar != std::string::npos) gpuName = gpuName.substr(bar + 3);
  gpuName = gpuName.substr(0, gpuName.find(" | "));
  char title[200];
  std::snprintf(title, sizeof title, "%s, %dx%d, on %s", name.c_str(), settings.width, settings.height,
                gpuName.substr(0, 60).c_str());
  Canvas figure = composeCompareFigure(panels, tone, title);
  writePng(out, figure.width, figure.height, figure.rgb);
  note(quiet, "wrote " + std::filesystem::absolute(out).string());
  return 0;
}

}  // namespace caustica::cli
