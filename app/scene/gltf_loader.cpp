// gltf_loader.cpp — loads a glTF 2.0 file (.gltf or .glb) into caustica::Scene after the material
// contract in docs/materials.md. Every index, byte range and JSON type is checked before use: bad
// input ends in caustica::Error("FILE: what is wrong"), never in a crash, hang or silent default.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <new>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include <glm/glm.hpp>

#include "util/error.h"
#include "util/file_io.h"
#include "util/math_constants.h"
#include "scene/gltf_internal.h"
#include "scene/scene.h"

namespace caustica {
namespace gltf {

std::string oneLine(const std::string& text) {
  std::string out;
  bool pendingSeparator = false;
  for (char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\n' || c == '\r') {
      pendingSeparator = !out.empty();
      continue;
    }
    if (pendingSeparator) {
      while (!out.empty() && (out.back() == ' ' || out.back() == '.')) out.pop_back();
      out += "; ";
      pendingSeparator = false;
    }
    out += (c < 0x20 || c >= 0x7f) ? '?' : ch;
  }
  while (!out.empty() && (out.back() == ' ' || out.back() == ';')) out.pop_back();
  if (out.size() > kMaxMessage) out = out.substr(0, kMaxMessage) + "...";
  return out;
}

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string mib(std::uint64_t bytes) {
  if (bytes < (1u << 20)) return str(bytes) + " bytes";
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << double(bytes) / double(1u << 20);
  std::string text = s.str();
  if (text.size() > 2 && text.compare(text.size() - 2, 2, ".0") == 0) text.resize(text.size() - 2);
  return text + " MiB";
}

bool insideFolder(const FileAccess& access, const std::filesystem::path& file) {
  if (access.allowOutside) return true;
  std::error_code ec;
  const std::filesystem::path resolved = std::filesystem::weakly_canonical(file, ec);
  if (ec) return false;
  // Component by component, so that /a/bc is not taken to lie inside /a/b.
  auto r = resolved.begin();
  for (auto f = access.folder.begin(); f != access.folder.end(); ++f, ++r)
    if (r == resolved.end() || *f != *r) return false;
  return true;
}

bool referenceAllowed(const FileAccess& access, const std::string& reference) {
  if (access.allowOutside) return true;
  const std::filesystem::path ref(reference);
  if (ref.has_root_path()) return false;  // absolute
  const std::filesystem::path normal = ref.lexically_normal();
  if (!normal.empty() && *normal.begin() == "..") return false;  // climbs out of the folder
  return insideFolder(access, std::filesystem::path(access.baseDir) / ref);  // symlinks
}

namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// ---- file reading --------------------------------------------------------------------------------
// File access for tinygltf (external buffers and images): regular files only, read with the same
// checks as the scene file itself (tinygltf's default reader trusts the size a directory reports).
// `user` is the FileAccess: a file outside the scene's folder does not exist for tinygltf (the JSON
// check has already refused such references by name; this also covers tinygltf's fallback of
// looking in the current directory).
bool fsFileExists(const std::string& path, void* user) {
  if (!insideFolder(*static_cast<const FileAccess*>(user), path)) return false;
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

// tinygltf joins the folder and the URI as text: an absolute URI (allowed by --allow-outside-paths)
// arrives as "FOLDER//abs/path", which the system would read as FOLDER/abs/path.
std::string fsExpandFilePath(const std::string& path, void* user) {
  const FileAccess& access = *static_cast<const FileAccess*>(user);
  const std::string joined = access.baseDir + "//";
  if (!access.baseDir.empty() && access.baseDir != "/" && path.rfind(joined, 0) == 0)
    return path.substr(access.baseDir.size() + 1);
  return path;
}

bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  if (!insideFolder(*static_cast<const FileAccess*>(user), path)) {
    if (err) *err += "'" + oneLine(path) + "' leads outside the scene's folder\n";
    return false;
  }
  try {
    *out = readFileBytes(path);
    return true;
  } catch (const std::exception& e) {
    if (err) *err += std::string(e.what()) + "\n";
    return false;
  }
}

bool fsWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err += "writing files is disabled\n";
  return false;
}

// Checks the GLB container layout strictly (tinygltf trusts the BIN chunk length a little too far)
// and returns the JSON chunk's text.
std::string glbJson(const std::string& path, const std::vector<unsigned char>& bytes) {
  const auto fail = [&](const std::string& what) { throw Error(path + ": invalid GLB: " + what); };
  if (bytes.size() < 20) fail("the file is " + str(bytes.size()) + " bytes, too short for a GLB header");
  if (std::memcmp(bytes.data(), "glTF", 4) != 0) fail("bad magic (the file does not start with \"glTF\")");
  const std::uint32_t version = readU32(&bytes[4]);
  if (version != 2) fail("container version " + str(version) + " (only 2 is supported)");
  const std::uint64_t length = readU32(&bytes[8]);
  if (length > bytes.size())
    fail("the header says " + str(length) + " bytes but the file has " + str(bytes.size()) + " (truncated?)");
  const std::uint64_t jsonLength = readU32(&bytes[12]);
  if (readU32(&bytes[16]) != 0x4E4F534Au) fail("the first chunk is not JSON");
  if (jsonLength == 0 || 20 + jsonLength > length) fail("the JSON chunk overruns the file");
  const std::uint64_t binAt = 20 + jsonLength;
  if (binAt + 8 <= length) {
    const std::uint64_t binLength = readU32(&bytes[binAt]);
    if (binAt + 8 + binLength > length)
      fail("the BIN chunk (" + str(binLength) + " bytes) overruns the file (" + str(length - binAt - 8) +
           " bytes left)");
  } else if (binAt != length) {
    fail("there are " + str(length - binAt) + " stray bytes after the JSON chunk");
  }
  return std::string(reinterpret_cast<const char*>(&bytes[20]), jsonLength);
}

// The GLB `bytes` (checked by glbJson) with its JSON chunk replaced by `json`, the BIN chunk kept.
std::vector<unsigned char> glbWithJson(const std::vector<unsigned char>& bytes, const std::string& json) {
  const std::uint64_t length = readU32(&bytes[8]), binAt = 20 + std::uint64_t(readU32(&bytes[12]));
  std::string padded = json;
  while (padded.size() % 4 != 0) padded += ' ';
  const std::uint64_t total = 20 + padded.size() + (length - binAt);
  unsigned char header[20];
  std::memcpy(header, bytes.data(), 8);  // magic and version
  const auto put32 = [&](std::size_t at, std::uint64_t v) {
    for (int k = 0; k < 4; ++k) header[at + std::size_t(k)] = static_cast<unsigned char>(v >> (8 * k));
  };
  put32(8, total);
  put32(12, padded.size());
  put32(16, 0x4E4F534Au);
  std::vector<unsigned char> out(static_cast<std::size_t>(total));
  std::copy(header, header + 20, out.begin());
  std::copy(padded.begin(), padded.end(), out.begin() + 20);
  std::copy(bytes.begin() + std::ptrdiff_t(binAt), bytes.begin() + std::ptrdiff_t(length),
            out.begin() + 20 + std::ptrdiff_t(padded.size()));
  return out;
}

}  // namespace
}  // namespace gltf

Scene loadScene(const std::string& path) { return loadScene(path, LoadOptions{}); }

Scene loadScene(const std::string& path, const LoadOptions& options) { return loadScene(path, options, ScenePose{}); }

Scene loadScene(const std::string& path, const LoadOptions& options, const ScenePose& pose) {
  return SceneFile(path, options).sceneAt(pose);
}

// The parsed document: what SceneBuilder reads for every pose.
struct SceneFile::Document {
  std::string path;
  LoadOptions options;
  tinygltf::Model model;
  gltf::ImageLog imageLog;
  std::vector<std::string> warnings;  // the file's own (GLB in .gltf, tinygltf's), copied into each Scene
};

SceneFile::~SceneFile() = default;
SceneFile::SceneFile(SceneFile&&) noexcept = default;
SceneFile& SceneFile::operator=(SceneFile&&) noexcept = default;
const std::string& SceneFile::path() const { return doc_->path; }

SceneFile::SceneFile(const std::string& path, const LoadOptions& options) : doc_(std::make_unique<Document>()) {
  using namespace gltf;  // the loader's internals (gltf_internal.h)
  doc_->path = path;
  doc_->options = options;
  const std::string ext = lowerExtension(path);
  if (ext != ".gltf" && ext != ".glb")
    throw Error(path + ": unsupported file extension '" + oneLine(ext) + "' (supported: .gltf, .glb)");
  const std::vector<unsigned char> bytes = readFileBytes(path);
  if (bytes.empty()) throw Error(path + ": the file is empty");

  // glTF-Binary is recognised by its magic, whatever the extension says.
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  if (binary != (ext == ".glb")) {
    if (ext == ".glb") glbJson(path, bytes);  // reports the bad header
    doc_->warnings.push_back(path + ": binary glTF content in a .gltf file; loaded as GLB");
  }
  const std::string jsonText =
      binary ? glbJson(path, bytes) : std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size());

  FileAccess access;
  access.baseDir = std::filesystem::path(path).parent_path().string();
  access.allowOutside = options.allowOutsidePaths;
  {
    std::error_code ec;
    access.folder = std::filesystem::canonical(access.baseDir.empty() ? "." : access.baseDir, ec);
    if (ec) throw Error(path + ": cannot resolve the scene's folder (" + oneLine(ec.message()) + ")");
  }
  const JsonFacts facts = checkJson(path, jsonText, access, binary, options);
  // Compressed geometry that tinygltf cannot load as it stands: a rewritten document.
  std::vector<unsigned char> rewrittenGlb;
  const std::string loadJson = facts.needsRewrite() ? tinygltfJson(jsonText, facts) : jsonText;
  if (binary && facts.needsRewrite()) rewrittenGlb = glbWithJson(bytes, loadJson);

  tinygltf::Model& model = doc_->model;
  ImageLog& imageLog = doc_->imageLog;
  imageLog.budget = options.maxTextureBytes;
  try {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(decodeImage, &imageLog);
    loader.SetFsCallbacks({fsFileExists, fsExpandFilePath, fsReadWholeFile, fsWriteWholeFile, &access});
    std::string err, warn;
    const std::vector<unsigned char>& glb = rewrittenGlb.empty() ? bytes : rewrittenGlb;
    const bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, glb.data(),
                                                         static_cast<unsigned int>(glb.size()), access.baseDir)
                           : loader.LoadASCIIFromString(&model, &err, &warn, loadJson.data(),
                                                        static_cast<unsigned int>(loadJson.size()), access.baseDir);
    if (!imageLog.overBudget.empty()) throw Error(path + ": " + imageLog.overBudget);
    if (!ok) throw Error(path + ": " + (err.empty() ? std::string("tinygltf could not load the file") : oneLine(err)));
    if (!warn.empty()) doc_->warnings.push_back(path + ": " + oneLine(warn));
    // Compressed geometry, once per file: the Draco primitives' indices back, meshopt views decoded.
    restoreDracoIndices(model, facts);
    decodeMeshoptViews(path, model, facts.fallbackBuffers, options);
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw Error(path + ": out of memory while decoding the file");
  } catch (const std::exception& e) {
    throw Error(path + ": " + oneLine(e.what()));
  }
}

Scene SceneFile::sceneAt(const ScenePose& pose) const {
  using namespace gltf;
  const std::string& path = doc_->path;
  Scene scene;
  scene.path = path;
  scene.warnings = doc_->warnings;
  try {
    SceneBuilder(path, doc_->model, doc_->imageLog, doc_->options, pose, scene).build();
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw Error(path + ": out of memory while building the scene");
  } catch (const std::exception& e) {
    throw Error(path + ": " + oneLine(e.what()));
  }
  return scene;
}

Camera autoCamera(const Bounds& bounds) {
  Camera cam;
  cam.name = "automatic";
  cam.yfov = float(40.0 * kPiD / 180.0);
  cam.aspect = 0.0f;
  cam.forward = glm::vec3(0.0f, 0.0f, -1.0f);
  cam.up = glm::vec3(0.0f, 1.0f, 0.0f);
  if (bounds.empty()) {
    cam.position = glm::vec3(0.0f, 0.0f, 1.0f);
    return cam;
  }
  // Fit the bounding sphere: at distance r / sin(yfov / 2) it touches the top and bottom of the view.
  const glm::dvec3 lo(bounds.min), hi(bounds.max);
  const glm::dvec3 centre = 0.5 * (lo + hi);
  double radius = 0.5 * glm::length(hi - lo);
  if (!std::isfinite(radius) || !std::isfinite(centre.x) || !std::isfinite(centre.y) || !std::isfinite(centre.z)) {
    cam.position = glm::vec3(0.0f, 0.0f, 1.0f);
    return cam;
  }
  if (!(radius > 0.0)) radius = 1.0;  // a single point: any distance frames it
  const double distance = radius / std::sin(0.5 * double(cam.yfov));
  cam.position = glm::vec3(centre + glm::dvec3(0.0, 0.0, distance));
  return cam;
}

}  // namespace caustica
