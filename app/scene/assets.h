// assets.h — finds scene files: a path as given, or a bare name ("cornell-glass") looked up in the
// bundled assets/scenes folder.
#pragma once
#include <string>
#include <vector>

namespace caustica {

// The folder holding the bundled scenes: $CAUSTICA_ASSETS, else next to the executable
// (../assets/scenes, ../share/caustica/scenes), else the source tree it was built from.
std::string assetSceneDir();
// The source tree this binary was built from (the one file compiled with CAUSTICA_SOURCE_DIR, so that
// no other object depends on where the tree lies: ccache can share objects between checkouts).
std::string sourceDir();
// Names of the bundled scenes (file names without .gltf), sorted.
std::vector<std::string> assetSceneNames();
// Resolves a scene argument; throws Error listing the bundled names if nothing matches.
std::string resolveScenePath(const std::string& nameOrPath);

constexpr const char* kDefaultScene = "cornell-glass";

}  // namespace caustica
