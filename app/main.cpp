// main.cpp — the caustica command line: render / info / view / bench / compare / merge subcommands.
// Setup errors are exceptions, caught here once and printed as one line with a non-zero exit.
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "util/error.h"

namespace {

const char* kUsage =
    "usage: caustica <command> [options]\n"
    "\n"
    "caustica is a progressive path tracer on OpenGL 4.3 compute shaders: caustics, soft shadows and\n"
    "colour bleeding from eye rays that bounce until they reach emitters of any shape.\n"
    "\n"
    "commands:\n"
    "  render [SCENE]   render a glTF scene headless to .png, .exr or .pfm\n"
    "  view [SCENE]     interactive progressive preview in a window\n"
    "  info SCENE       print what a scene holds and what the renderer will need for it\n"
    "  bench [SCENE..]  measure run time against error for each estimator\n"
    "  compare [SCENE]  raster, Whitted and path tracing side by side with the table of effects\n"
    "  merge PART...    add the partials of a render's shards (render --shard K/N) into its image\n"
    "\n"
    "SCENE is a .gltf/.glb file or the name of a bundled scene (default: cornell-glass).\n"
    "'caustica <command> --help' describes each command's options.\n";

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::cout << kUsage;
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "--version") {
    std::cout << "caustica 0.1.0\n";
    return 0;
  }
  std::string command = args[0];
  args.erase(args.begin());
  try {
    if (command == "render") return caustica::cli::cmdRender(args);
    if (command == "info") return caustica::cli::cmdInfo(args);
    if (command == "view") return caustica::cli::cmdView(args);
    if (command == "bench") return caustica::cli::cmdBench(args);
    if (command == "compare") return caustica::cli::cmdCompare(args);
    if (command == "merge") return caustica::cli::cmdMerge(args);
    std::cerr << "caustica: unknown command '" << command << "' (commands: render, view, info, bench, compare, merge; see --help)\n";
    return 2;
  } catch (const caustica::Error& e) {
    std::string msg = e.what();
    std::cerr << "caustica " << command << ": error: " << msg << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "caustica " << command << ": internal error: " << e.what() << "\n";
    return 3;
  }
}
