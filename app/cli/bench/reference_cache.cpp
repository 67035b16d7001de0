// reference_cache.cpp — finding, rendering and caching the bench's references: the key text, scene
// hashing, the two-halves render and atomic writes of the cached halves.
#include "cli/bench/reference_cache.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "util/error.h"
#include "util/file_io.h"

namespace caustica::cli {

namespace fs = std::filesystem;

RenderSettings referenceSettings(const RenderSettings& measured, DispersionMode mode) {
  RenderSettings rs = measured;
  rs.seed = kReferenceSeed;  // independent of the measured runs, whatever their --seed
  rs.integrator = Integrator::Mis;
  rs.dispersion = mode;
  // The reference is one estimate of the image whatever the measured runs use: always mis with the
  // default caster probability, so --caster-probability runs (ablations) share the cached reference.
  rs.casterProbability = RenderSettings{}.casterProbability;
  rs.guideProbability = RenderSettings{}.guideProbability;
  rs.manifold = ManifoldMode::Off;  // and without manifold NEE: one estimator's reference for all
  return rs;
}

std::string referenceKeyText(const ReferenceKey& key) {
  const RenderSettings& rs = key.settings;
  const Camera& camera = key.camera;
  std::ostringstream text;
  text << kReferenceCacheVersion << '\n' << hex64(key.sceneHash) << '\n' << rs.width << 'x' << rs.height << '\n'
       << key.spp << " spp\nseed " << rs.seed << "\ndepth " << rs.maxDepth << '\n'
       << dispersionModeName(rs.dispersion) << '\n' << integratorName(rs.integrator) << "\ncasters "
       << rs.casterProbability << "\ncamera " << key.cameraIndex << ' ' << camera.position.x << ' '
       << camera.position.y << ' ' << camera.position.z << ' ' << camera.forward.x << ' ' << camera.forward.y << ' '
       << camera.forward.z << ' ' << camera.up.x << ' ' << camera.up.y << ' ' << camera.up.z << ' ' << camera.yfov
       << (camera.orthographic() ? " orthographic " + std::to_string(camera.orthoHeight) : std::string()) << '\n'
       << hex64(key.shaderHash) << '\n';
  return text.str();
}

std::string referenceCacheStem(const std::string& sceneName, DispersionMode mode, const std::string& keyText) {
  return sceneName + "-" + dispersionModeName(mode) + "-" + hex64(fnv1a64(keyText));
}

std::uint64_t hashSceneFiles(const std::string& path) {
  std::string bytes = readFileText(path);
  std::uint64_t h = fnv1a64(bytes);
  if (fileExtension(path) != ".gltf") return h;
  try {
    nlohmann::json j = nlohmann::json::parse(bytes);
    for (const char* key : {"buffers", "images"}) {
      if (!j.contains(key) || !j[key].is_array()) continue;
      for (const auto& item : j[key]) {
        if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
        std::string uri = item["uri"].get<std::string>();
        if (uri.rfind("data:", 0) == 0) continue;
        fs::path p = fs::path(path).parent_path() / uri;
        std::error_code ec;
        if (fs::is_regular_file(p, ec)) h = fnv1a64(readFileText(p.string()), fnv1a64(uri, h));
      }
    }
  } catch (const nlohmann::json::exception&) {
    // The loader accepted the file; anything it could not name is covered by the file's own bytes.
  }
  return h;
}

std::string defaultReferenceCacheDir() {
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x)
    return (fs::path(x) / "caustica" / "references").string();
  if (const char* h = std::getenv("HOME"); h && *h) return (fs::path(h) / ".cache" / "caustica" / "references").string();
  return "bench-out/cache";
}

void writeImageAtomic(const std::string& path, const Image& image) {
  writeFileAtomically(path, ".tmp.exr", [&](const std::string& tmp) { writeImage(tmp, image); });
}

Reference givenReference(const std::string& file, int width, int height, bool quiet) {
  Reference ref;
  ref.source = file;
  ref.image = readImage(ref.source);
  if (ref.image.width != width || ref.image.height != height)
    throw Error(ref.source + ": the reference is " + std::to_string(ref.image.width) + "x" +
                std::to_string(ref.image.height) + " but the bench renders " + std::to_string(width) + "x" +
                std::to_string(height) + " (use --size " + std::to_string(ref.image.width) + "x" +
                std::to_string(ref.image.height) + ")");
  note(quiet, "reference " + ref.source + " (given; its own noise is unknown)");
  return ref;
}

ReferenceCache::ReferenceCache(std::string dir, bool refresh, std::string glRenderer, bool quiet)
    : dir_(std::move(dir)), glRenderer_(std::move(glRenderer)), refresh_(refresh), quiet_(quiet) {}

Reference ReferenceCache::get(const ShaderLibrary& library, const LoadedScene& loaded,
                              const ReferenceRequest& request, Renderer& renderer) const {
  Reference ref;
  const RenderSettings rs = referenceSettings(request.measured, request.mode);
  renderer.apply(rs);  // for its shader variant, which is part of the cache key
  ReferenceKey key;
  key.sceneHash = hashSceneFiles(request.scenePath);
  key.settings = rs;
  key.spp = request.spp;
  key.cameraIndex = request.cameraIndex;
  key.camera = loaded.camera;
  key.shaderHash = fnv1a64(library.expand("pathtrace.comp", renderer.shaderDefines()).source);
  const std::string keyText = referenceKeyText(key);
  const std::string stem = referenceCacheStem(request.sceneName, request.mode, keyText);
  fs::path a = fs::path(dir_) / (stem + "-a.exr"), b = fs::path(dir_) / (stem + "-b.exr");
  std::error_code ec;
  if (!refresh_ && fs::is_regular_file(a, ec) && fs::is_regular_file(b, ec)) {
    ref.halfA = readImage(a.string());
    ref.halfB = readImage(b.string());
    ref.source = "cached " + (fs::path(dir_) / stem).string() + "-{a,b}.exr";
  } else {
    fs::create_directories(dir_, ec);
    if (ec) throw Error(dir_ + ": cannot create the reference cache folder (" + ec.message() + ")");
    render(library, loaded, rs, request, ref);
    writeImageAtomic(a.string(), *ref.halfA);
    writeImageAtomic(b.string(), *ref.halfB);
    std::ofstream meta(fs::path(dir_) / (stem + ".txt"));
    meta << keyText << "scene " << request.scenePath << "\nGL " << glRenderer_ << '\n';
    ref.source = "rendered, cached as " + (fs::path(dir_) / stem).string() + "-{a,b}.exr";
  }
  ref.spp = request.spp;
  ref.image = averageImages(*ref.halfA, *ref.halfB);
  ref.noise = referenceNoise(*ref.halfA, *ref.halfB);
  if (request.caustic) ref.noiseCaustic = referenceNoise(*ref.halfA, *ref.halfB, *request.caustic);
  note(quiet_, "reference " + std::string(dispersionModeName(request.mode)) + ", " + std::to_string(request.spp) +
                   " spp mis: " + ref.source + "; its own relMSE ~" + formatSci(ref.noise) +
                   (request.caustic ? ", caustic region ~" + formatSci(ref.noiseCaustic) : std::string()));
  return ref;
}

void ReferenceCache::render(const ShaderLibrary& library, const LoadedScene& loaded, const RenderSettings& rs,
                            const ReferenceRequest& request, Reference& ref) const {
  Renderer r(library, loaded.scene, loaded.camera, rs);
  const int half = request.spp / 2;
  const std::string label = "reference " + request.sceneName + " " + dispersionModeName(rs.dispersion) + ":";
  // The first half, then the second: the sample indices differ, so the halves are independent.
  renderWithProgress(r, half, label, quiet_);
  ref.halfA = r.image();
  renderWithProgress(r, request.spp, label, quiet_);
  // mean = (A + B) / 2, so B = 2 mean - A.
  Image mean = r.image();
  Image b = mean;
  for (size_t i = 0; i < b.rgb.size(); ++i) b.rgb[i] = 2.0f * mean.rgb[i] - ref.halfA->rgb[i];
  ref.halfB = std::move(b);
}

}  // namespace caustica::cli
