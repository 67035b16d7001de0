// reference_cache.h — the image a bench run is measured against: --reference FILE, else two independent
// halves from the reference cache, else rendered now in two halves (mis, its own seed) and cached.
// The cache key and file names are pure functions (no OpenGL); existing caches depend on their text.
#pragma once
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>

#include "cli/bench/bench_metrics.h"
#include "cli/cli_common.h"
#include "gpu/render_settings.h"
#include "image/image_io.h"
#include "scene/scene.h"

namespace caustica::cli {

// First line of every cache key: bump it to invalidate every cached reference.
constexpr const char* kReferenceCacheVersion = "caustica-bench-reference-v1";
// Seed of rendered references: above the largest --seed (2^31 - 1), so never a measured run's seed,
// and fixed, so runs with other seeds reuse the cached reference.
constexpr std::uint32_t kReferenceSeed = 0x9E3779BAu;

struct Reference {
  Image image;                        // the mean of the two halves, or the user's file
  std::optional<Image> halfA, halfB;  // independent halves, for the noise estimate
  std::string source;                 // file or cache entry it came from
  int spp = 0;                        // samples per pixel of a rendered reference; 0 if given as a file
  double noise = std::nan(""), noiseCaustic = std::nan("");  // its own relMSE (whole image, caustic region)
};

// The settings a reference renders with, for measured runs with `measured`: the same size and depth,
// dispersion mode `mode`, always mis with seed kReferenceSeed and the default caster probability, so
// runs with another seed, estimator or --caster-probability (ablations) share the cached reference.
RenderSettings referenceSettings(const RenderSettings& measured, DispersionMode mode);

// Everything a rendered reference depends on.
struct ReferenceKey {
  std::uint64_t sceneHash = 0;   // hashSceneFiles of the scene file
  RenderSettings settings;       // referenceSettings(...)
  int spp = 0;                   // samples per pixel, both halves together
  int cameraIndex = 0;           // --camera
  Camera camera;                 // the camera it was rendered from
  std::uint64_t shaderHash = 0;  // FNV-1a 64 of the expanded pathtrace.comp of the reference's variant
};
// The key as text (one item a line, starting with kReferenceCacheVersion); it is stored as the cache
// entry's .txt and its hash names the entry, so its layout must not change without a version bump.
std::string referenceKeyText(const ReferenceKey& key);
// "SCENE-MODE-HASH" with HASH = hex64(fnv1a64(keyText)): the entry is STEM-a.exr, STEM-b.exr, STEM.txt.
std::string referenceCacheStem(const std::string& sceneName, DispersionMode mode, const std::string& keyText);
// FNV-1a 64 of the scene file's bytes, chained for a .gltf with the URI and bytes of each external
// buffer and image it names that exists (data: URIs are part of the file already).
std::uint64_t hashSceneFiles(const std::string& path);
// $XDG_CACHE_HOME/caustica/references, else $HOME/.cache/caustica/references, else bench-out/cache.
std::string defaultReferenceCacheDir();
// Writes to a temporary name and renames, so that an interrupted run leaves no half file behind.
void writeImageAtomic(const std::string& path, const Image& image);

// --reference FILE: the image as given (its own noise unknown); throws Error unless it is
// width x height pixels.
Reference givenReference(const std::string& file, int width, int height, bool quiet);

// One reference to find or render: a scene in one dispersion mode.
struct ReferenceRequest {
  std::string scenePath, sceneName;   // the scene file and its name (the file's stem)
  int cameraIndex = 0;                // --camera
  RenderSettings measured;            // the measured runs' settings (LoadedScene::settings.render, cli/image_settings.h)
  DispersionMode mode = DispersionMode::Rgb;
  std::optional<PixelRect> caustic;   // for the caustic-region noise estimate
  int spp = 0;                        // samples per pixel, even: two halves of spp / 2
};

class ReferenceCache {
 public:
  // `dir`: the cache folder (created when a reference is stored); `refresh`: render even when cached;
  // `glRenderer` is written into each entry's .txt.
  ReferenceCache(std::string dir, bool refresh, std::string glRenderer, bool quiet);

  // The cached reference for `request`, else renders it with a renderer of its own and caches it.
  // Applies referenceSettings to `renderer` (the renderer of the measured runs) for the shader
  // variant, which is part of the key: the caller applies its own settings again afterwards.
  Reference get(const ShaderLibrary& library, const LoadedScene& loaded, const ReferenceRequest& request,
                Renderer& renderer) const;

 private:
  // Renders spp / 2 samples per pixel, keeps that image as half A, renders to spp and derives half B.
  void render(const ShaderLibrary& library, const LoadedScene& loaded, const RenderSettings& rs,
              const ReferenceRequest& request, Reference& ref) const;

  std::string dir_, glRenderer_;
  bool refresh_ = false, quiet_ = false;
};

}  // namespace caustica::cli
