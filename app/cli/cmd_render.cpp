// cmd_render.cpp — `caustica render`: headless progressive render of a scene to an image file.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli/cli_common.h"
#include "cli/commands.h"
#include "util/error.h"
#include "image/image_io.h"
#include "platform/context.h"

namespace caustica::cli {

int cmdRender(const std::vector<std::string>& args) {
  std::vector<OptionSpec> specs = {
      {"--output", "-o", "FILE", "output image: .png (tone-mapped sRGB), .exr or .pfm (linear) (default caustica.png)"},
      {"--spp", "", "N", "samples per pixel (default 64)"},
      {"--exposure", "", "STOPS", "PNG exposure in stops (default 0)"},
      {"--tonemap", "", "CURVE", "PNG tone curve: aces (default) or clamp"},
  };
  for (auto& s : sceneOptionSpecs()) specs.push_back(s);
  Options opts("caustica render [SCENE] [options]",
               "Renders SCENE (a .gltf/.glb file or a bundled scene name; default cornell-glass) headless and\n"
               "writes the mean radiance of each pixel. Linear outputs are not tone-mapped or clamped.",
               specs);
  if (!opts.parse(args)) return 0;
  bool quiet = opts.has("--quiet");
  std::string out = opts.get("--output", "caustica.png");
  checkImageExtension(out);  // fail before any work
  int spp = opts.getInt("--spp", 64, 1, 1 << 24);
  ToneMapSettings tone;
  tone.exposureStops = static_cast<float>(opts.getDouble("--exposure", 0.0));
  tone.curve = parseToneCurve(opts.get("--tonemap", "aces"));
  Backend backend = parseBackend(opts.get("--backend", "auto"));

  LoadedScene ls = loadSceneForCli(opts, !quiet);
  RenderSettings settings = renderSettingsFrom(opts, ls.camera, 512);
  std::string glInfo;
  auto context = createHeadlessContext(backend, &glInfo);
  note(quiet, "OpenGL (" + context->backendName() + "): " + glInfo);
  ShaderLibrary library = shaderLibraryFrom(opts);
  Renderer renderer(library, ls.scene, ls.camera, settings);
  note(quiet, ls.scene.path + ": " + std::to_string(ls.scene.triangles.size()) + " triangles, " +
                  std::to_string(renderer.gpuScene().emitters.size()) + " emissive, features: " +
                  renderer.gpuScene().features.describe() + "; " + std::to_string(settings.width) + "x" +
                  std::to_string(settings.height) + ", " + std::to_string(spp) + " spp, " +
                  integratorName(settings.integrator));

  auto start = std::chrono::steady_clock::now();
  renderWithProgress(renderer, spp, "", quiet);
  double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const RenderStats& st = renderer.stats();
  char line[256];
  std::snprintf(line, sizeof line, "%.2f s, %.3g samples/s, %.3g rays/s, non-finite samples: %llu", total,
                double(st.primaryRays) / total, double(st.rays()) / total, static_cast<unsigned long long>(st.nonFinite));
  note(quiet, line);
  writeImage(out, renderer.image(), tone);
  note(quiet, "wrote " + std::filesystem::absolute(out).string());
  return 0;
}

}  // namespace caustica::cli
