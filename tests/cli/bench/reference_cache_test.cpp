// reference_cache_test.cpp — what names a cached reference: the reference's own settings, the cache
// key text and file stem (pinned to an entry written before the bench was split into files), the
// scene hash over external glTF files, and the default cache folder.
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "cli/bench/reference_cache.h"
#include "util/file_io.h"

using namespace caustica;
using namespace caustica::cli;

namespace fs = std::filesystem;

namespace {

void writeText(const fs::path& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

// Sets an environment variable for the life of the object (unset when `value` is null), then puts
// the old value back.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = std::string(old);
    if (value) setenv(name, value, 1);
    else unsetenv(name);
  }
  ~ScopedEnv() {
    if (old_) setenv(name_, old_->c_str(), 1);
    else unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

}  // namespace

TEST_CASE("a reference renders with mis, its own seed and the default caster probability") {
  RenderSettings measured;
  measured.width = 320;
  measured.height = 240;
  measured.seed = 7;
  measured.maxDepth = 12;
  measured.integrator = Integrator::Naive;
  measured.dispersion = DispersionMode::Rgb;
  measured.casterProbability = 0.2f;
  RenderSettings rs = referenceSettings(measured, DispersionMode::Spectral);
  CHECK(rs.width == 320);
  CHECK(rs.height == 240);
  CHECK(rs.maxDepth == 12);
  CHECK(rs.seed == kReferenceSeed);
  CHECK(rs.seed == 2654435770u);  // above any --seed (at most 2^31 - 1)
  CHECK(rs.integrator == Integrator::Mis);
  CHECK(rs.dispersion == DispersionMode::Spectral);
  CHECK(rs.casterProbability == RenderSettings{}.casterProbability);
  // Measured runs that differ only in seed, estimator or caster probability share the reference.
  measured.seed = 99;
  measured.integrator = Integrator::Mis;
  measured.casterProbability = 0.7f;
  CHECK(referenceSettings(measured, DispersionMode::Spectral) == rs);
}

TEST_CASE("the cache key text and stem match an entry cached before the bench was split") {
  // The key of cornell-glass, 16x16, 8 spp, rgb, as the bench wrote it to
  // cornell-glass-rgb-8c7fd390859f03fb.txt at commit a2fe5a3: the same inputs must name the same files.
  ReferenceKey key;
  key.sceneHash = 0x2d5f04bf79de0efaull;
  key.settings = referenceSettings(RenderSettings{}, DispersionMode::Rgb);
  key.settings.width = 16;
  key.settings.height = 16;
  key.settings.maxDepth = 32;  // the default when that entry was written
  key.spp = 8;
  key.cameraIndex = 0;
  key.camera.position = {0.0f, 1.0f, 3.7f};
  key.camera.forward = {0.0f, 0.0f, -1.0f};
  key.camera.up = {0.0f, 1.0f, 0.0f};
  key.camera.yfov = 0.6911f;
  key.shaderHash = 0xddffe20d5dd0ab53ull;
  const std::string text = referenceKeyText(key);
  CHECK(text ==
        "caustica-bench-reference-v1\n"
        "2d5f04bf79de0efa\n"
        "16x16\n"
        "8 spp\n"
        "seed 2654435770\n"
        "depth 32\n"
        "rgb\n"
        "mis\n"
        "casters 0.5\n"
        "camera 0 0 1 3.7 0 0 -1 0 1 0 0.6911\n"
        "ddffe20d5dd0ab53\n");
  CHECK(referenceCacheStem("cornell-glass", DispersionMode::Rgb, text) == "cornell-glass-rgb-8c7fd390859f03fb");

  // Every input is part of the key.
  ReferenceKey other = key;
  other.settings.dispersion = DispersionMode::Spectral;
  CHECK(referenceKeyText(other).find("\nspectral\n") != std::string::npos);
  CHECK(referenceCacheStem("cornell-glass", DispersionMode::Spectral, referenceKeyText(other)) ==
        "cornell-glass-spectral-" + hex64(fnv1a64(referenceKeyText(other))));
  other = key;
  other.spp = 16;
  CHECK(referenceKeyText(other) != text);
  other = key;
  other.cameraIndex = 1;
  CHECK(referenceKeyText(other) != text);
  other = key;
  other.camera.yfov = 0.7f;
  CHECK(referenceKeyText(other) != text);
  other = key;
  other.shaderHash ^= 1;
  CHECK(referenceKeyText(other) != text);
  other = key;
  other.settings.maxDepth = 8;
  CHECK(referenceKeyText(other) != text);
}

TEST_CASE("the scene hash covers the external files a .gltf names, not data: URIs or missing files") {
  fs::path dir = fs::temp_directory_path() / "caustica_reference_cache_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string gltf = R"({"buffers": [{"uri": "mesh.bin"}, {"uri": "data:application/octet-stream;base64,AAAA"}],
                                "images": [{"uri": "missing.png"}, {"uri": "tex.png"}]})";
  writeText(dir / "scene.gltf", gltf);
  writeText(dir / "mesh.bin", "0123");
  writeText(dir / "tex.png", "pixels");
  const std::string path = (dir / "scene.gltf").string();
  std::uint64_t expected = fnv1a64(gltf);
  expected = fnv1a64(std::string("0123"), fnv1a64(std::string("mesh.bin"), expected));
  expected = fnv1a64(std::string("pixels"), fnv1a64(std::string("tex.png"), expected));
  CHECK(hashSceneFiles(path) == expected);

  // A changed buffer changes the hash.
  writeText(dir / "mesh.bin", "0124");
  CHECK(hashSceneFiles(path) != expected);

  // A .glb (or any other file) is hashed by its bytes alone, as is a .gltf that is not JSON.
  writeText(dir / "scene.glb", gltf);
  CHECK(hashSceneFiles((dir / "scene.glb").string()) == fnv1a64(gltf));
  writeText(dir / "broken.gltf", "{ not json");
  CHECK(hashSceneFiles((dir / "broken.gltf").string()) == fnv1a64(std::string("{ not json")));
  fs::remove_all(dir);
}

TEST_CASE("the default cache folder follows XDG_CACHE_HOME, then HOME") {
  {
    ScopedEnv xdg("XDG_CACHE_HOME", "/xdg/cache");
    ScopedEnv home("HOME", "/home/someone");
    CHECK(defaultReferenceCacheDir() == "/xdg/cache/caustica/references");
  }
  {
    ScopedEnv xdg("XDG_CACHE_HOME", "");  // set but empty: ignored
    ScopedEnv home("HOME", "/home/someone");
    CHECK(defaultReferenceCacheDir() == "/home/someone/.cache/caustica/references");
  }
  {
    ScopedEnv xdg("XDG_CACHE_HOME", nullptr);
    ScopedEnv home("HOME", nullptr);
    CHECK(defaultReferenceCacheDir() == "bench-out/cache");
  }
}
