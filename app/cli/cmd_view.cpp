// cmd_view.cpp — `caustica view`: its options, read into a ViewConfig for the interactive viewer
// (cli/view/viewer.h), which shows the same Renderer as `render` refining in a GLFW window.
#include <string>
#include <vector>

#include "cli/cli_common.h"
#include "cli/commands.h"
#include "cli/view/input.h"
#include "cli/view/viewer.h"
#include "image/image_io.h"
#include "util/error.h"

namespace caustica::cli {

int cmdView(const std::vector<std::string>& args) {
  std::vector<OptionSpec> specs = {
      {"--frames", "", "N", "scripted run: render N frames, complete the sample pass in flight, write --screenshot, exit"},
      {"--screenshot", "", "FILE", "image written at exit, as shown (denoised unless --no-denoise): .png (tone-mapped), .exr or .pfm (linear)"},
      {"--budget-ms", "", "MS", "path-tracing GPU time per frame in milliseconds (default 30)"},
      {"--spp", "", "N", "stop refining at N samples per pixel (default: never)"},
      {"--target-error", "", "E", "stop refining (and using the GPU) once the estimated relMSE is at most E; key G toggles"},
      {"--exposure", "", "STOPS", "display exposure in stops (default 0)"},
      {"--tonemap", "", "CURVE", "display tone curve: aces (default) or clamp"},
      {"--no-vsync", "", "", "do not wait for the display's vertical blank"},
      {"--no-preview", "", "", "always render at full resolution, also while the camera moves"},
      {"--spin", "", "DEG", "orbit the camera DEG degrees per frame (demos, preview benchmarks)"},
      {"--no-denoise", "", "", "show the raw image, not the denoised one (key N toggles; docs/denoising.md)"},
  };
  for (OptionSpec s : sceneOptionSpecs()) {
    if (s.name == "--backend") continue;  // a window brings its own context
    if (s.name == "--size") s.help = "render resolution (default: follows the window, which opens 960 wide)";
    specs.push_back(s);
  }
  Options opts("caustica view [SCENE] [options]",
               std::string("Opens a window showing SCENE (a .gltf/.glb file or a bundled scene name; default\n"
                           "cornell-glass) refining progressively: the same renderer as 'caustica render'.\n\n") +
                   kViewerControls,
               specs);
  if (!opts.parse(args)) return 0;
#ifdef CAUSTICA_HAVE_GLFW
  ViewConfig config;
  config.quiet = opts.has("--quiet");
  config.frameLimit = opts.getInt("--frames", 0, 1, 1 << 30);
  config.screenshotPath = opts.get("--screenshot", "");
  if (!config.screenshotPath.empty()) checkImageExtension(config.screenshotPath);  // fail before any work
  config.budgetMs = opts.getDouble("--budget-ms", 30.0);
  if (config.budgetMs < 1.0 || config.budgetMs > 10000.0) throw Error("option --budget-ms needs 1 to 10000 milliseconds");
  config.maxSpp = opts.getInt("--spp", 0, 1, 1 << 24);
  config.targetError = opts.getDouble("--target-error", 0.0);
  if (opts.has("--target-error") && !(config.targetError > 0.0 && config.targetError < 1e30))
    throw Error("option --target-error needs a relMSE above 0 (e.g. 0.01)");
  config.vsync = !opts.has("--no-vsync");
  config.preview = !opts.has("--no-preview");
  config.spinRadians = opts.getDouble("--spin", 0.0) * 3.14159265358979 / 180.0;
  config.fixedSize = opts.has("--size");
  config.denoise = !opts.has("--no-denoise");
  Viewer viewer(opts, config);
  return viewer.run();
#else
  throw Error("this caustica was built without the viewer (CAUSTICA_VIEWER=OFF); use 'caustica render' for headless images");
#endif
}

}  // namespace caustica::cli
