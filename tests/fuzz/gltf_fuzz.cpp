// gltf_fuzz.cpp — libFuzzer target for the glTF loader (scripts/fuzz-gltf builds and runs it; see
// docs/fuzzing.md). Each input is written as a file into a private temporary folder and loaded with
// caustica::loadScene. caustica::Error is the expected end of a bad file; anything else (another
// exception, a signal, a sanitizer report, a leak, a hang) is left to crash and libFuzzer saves it.
//
// The file's extension, a rule scripts/fuzz-gltf repeats when it names a saved input:
//   .glb when the bytes start with "glTF", else .gltf; the other one when the size is a multiple
//   of 8, so the loader's extension/content mismatch paths are fuzzed too.
// The bytes are written unchanged, so a saved input is itself a scene file that `caustica info`
// reproduces once it has that extension.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>

#include "scene/scene.h"
#include "util/error.h"

namespace {

std::string g_dir;  // private folder: external buffers and images named by an input resolve in it

void removeDir() {
  std::error_code ec;
  if (!g_dir.empty()) std::filesystem::remove_all(g_dir, ec);
}

const char* extensionFor(const std::uint8_t* data, std::size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const bool swap = size % 8 == 0;
  return glb != swap ? ".glb" : ".gltf";
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::error_code ec;
  std::filesystem::path base = std::filesystem::temp_directory_path(ec);
  if (ec) base = "/tmp";
  std::string pattern = (base / "caustica-fuzz-XXXXXX").string();
  if (!mkdtemp(pattern.data())) {
    std::perror("gltf_fuzz: mkdtemp");
    std::abort();
  }
  g_dir = pattern;
  std::atexit(removeDir);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = g_dir + "/input" + extensionFor(data, size);
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f || (size > 0 && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
    std::perror(("gltf_fuzz: " + path).c_str());
    std::abort();
  }
  try {
    const caustica::Scene scene = caustica::loadScene(path);
    // A loaded scene keeps the loader's promises (scene.h): triangles, and every index valid.
    if (scene.materials.empty() || scene.triangles.empty()) std::abort();
    for (const caustica::Triangle& t : scene.triangles)
      if (t.material >= scene.materials.size()) std::abort();
    const auto texture = [&](int i) { return i >= -1 && i < int(scene.textures.size()); };
    for (const caustica::Material& m : scene.materials)
      if (!texture(m.baseColorTexture) || !texture(m.emissiveTexture)) std::abort();
  } catch (const caustica::Error&) {
    // a clean rejection: what the loader must do with every bad file
  }
  // Removed after each run, so that no input can read the one before it as an external file.
  std::remove(path.c_str());
  return 0;
}
