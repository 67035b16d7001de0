// assets.cpp — scene name resolution against the bundled assets folder.
#include "scene/assets.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>

#include "util/error.h"

namespace fs = std::filesystem;

namespace caustica {

namespace {
std::string executableDir() {
  std::error_code ec;
  fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : p.parent_path().string();
}
}  // namespace

std::string sourceDir() { return CAUSTICA_SOURCE_DIR; }

std::string assetSceneDir() {
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("CAUSTICA_ASSETS")) candidates.emplace_back(fs::path(env) / "scenes");
  std::string exe = executableDir();
  if (!exe.empty()) {
    candidates.emplace_back(fs::path(exe) / ".." / "assets" / "scenes");
    candidates.emplace_back(fs::path(exe) / ".." / "share" / "caustica" / "scenes");
  }
  candidates.emplace_back(fs::path(CAUSTICA_SOURCE_DIR) / "assets" / "scenes");
  for (const auto& c : candidates) {
    std::error_code ec;
    if (fs::is_directory(c, ec)) return fs::weakly_canonical(c, ec).string();
  }
  return (fs::path(CAUSTICA_SOURCE_DIR) / "assets" / "scenes").string();
}

std::vector<std::string> assetSceneNames() {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(assetSceneDir(), ec)) {
    if (e.path().extension() == ".gltf" || e.path().extension() == ".glb") names.push_back(e.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string resolveScenePath(const std::string& nameOrPath) {
  std::error_code ec;
  if (fs::is_regular_file(nameOrPath, ec)) return nameOrPath;
  bool bare = nameOrPath.find('/') == std::string::npos && fs::path(nameOrPath).extension().empty();
  if (bare) {
    for (const char* ext : {".gltf", ".glb"}) {
      fs::path p = fs::path(assetSceneDir()) / (nameOrPath + ext);
      if (fs::is_regular_file(p, ec)) return p.string();
    }
    std::string list;
    for (const auto& n : assetSceneNames()) list += (list.empty() ? "" : ", ") + n;
    throw Error(nameOrPath + ": no such scene file or bundled scene (bundled: " + list + ")");
  }
  if (fs::exists(nameOrPath, ec)) throw Error(nameOrPath + ": not a regular file");
  throw Error(nameOrPath + ": no such file");
}

}  // namespace caustica
