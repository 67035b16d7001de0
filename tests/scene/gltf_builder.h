// gltf_builder.h — what the loader tests share: small glTF documents built in memory with one embedded
// buffer (Gltf), a temporary folder (TempDir), and the loader's error for a file (loadError).
#pragma once
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "scene/assets.h"
#include "scene/scene.h"
#include "util/error.h"

namespace caustica::test {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr int kByte = 5121, kShort = 5123, kUint = 5125, kFloat = 5126;

inline std::string source(const std::string& relative) { return caustica::sourceDir() + "/" + relative; }

// A fresh directory under the system temp dir, removed at the end of the test.
struct TempDir {
  fs::path path;
  TempDir() {
    static int counter = 0;
    path = fs::temp_directory_path() /
           ("caustica_scene_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string write(const std::string& name, const std::string& bytes) const {
    const fs::path file = path / name;
    std::ofstream(file, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    return file.string();
  }
};

inline std::string base64(const std::string& in) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const std::uint32_t v = std::uint32_t(std::uint8_t(in[i])) << 16 | std::uint32_t(std::uint8_t(in[i + 1])) << 8 |
                            std::uint8_t(in[i + 2]);
    for (int k = 3; k >= 0; --k) out += table[(v >> (6 * k)) & 63];
  }
  if (i < in.size()) {
    std::uint32_t v = std::uint32_t(std::uint8_t(in[i])) << 16;
    if (i + 1 < in.size()) v |= std::uint32_t(std::uint8_t(in[i + 1])) << 8;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < in.size() ? table[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

// Builds small glTF documents with one embedded buffer.
struct Gltf {
  json doc = {{"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", json::array({{{"nodes", json::array()}}})}};
  std::string bin;

  template <class T>
  int accessor(const std::vector<T>& values, int componentType, const char* type, bool normalized = false) {
    while (bin.size() % 4) bin += '\0';
    doc["bufferViews"].push_back(
        {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", values.size() * sizeof(T)}});
    bin.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    const std::size_t components = std::string(type) == "SCALAR" ? 1 : std::size_t(type[3] - '0');
    json acc = {{"bufferView", doc["bufferViews"].size() - 1},
                {"componentType", componentType},
                {"count", values.size() / components},
                {"type", type}};
    if (normalized) acc["normalized"] = true;
    doc["accessors"].push_back(acc);
    return int(doc["accessors"].size() - 1);
  }
  // POSITION accessors carry min and max, as glTF requires (the loader's rebase reads them).
  int positions(const std::vector<float>& xyz) {
    const int index = accessor(xyz, kFloat, "VEC3");
    std::vector<float> lo(3, std::numeric_limits<float>::infinity()), hi(3, -std::numeric_limits<float>::infinity());
    for (std::size_t i = 0; i < xyz.size(); ++i) {
      lo[i % 3] = std::min(lo[i % 3], xyz[i]);
      hi[i % 3] = std::max(hi[i % 3], xyz[i]);
    }
    if (!xyz.empty()) {
      doc["accessors"][std::size_t(index)]["min"] = lo;
      doc["accessors"][std::size_t(index)]["max"] = hi;
    }
    return index;
  }

  int add(const char* array, const json& value) {
    doc[array].push_back(value);
    return int(doc[array].size() - 1);
  }
  int mesh(const json& primitive) { return add("meshes", {{"primitives", json::array({primitive})}}); }
  int root(const json& node) {
    const int index = add("nodes", node);
    doc["scenes"][0]["nodes"].push_back(index);
    return index;
  }
  int diffuse() { return add("materials", {{"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}}); }

  std::string text() {
    json d = doc;
    d["buffers"] = json::array(
        {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
    return d.dump();
  }
  caustica::Scene load(const TempDir& dir, const std::string& name = "scene.gltf") {
    return caustica::loadScene(dir.write(name, text()));
  }
};

// A unit right triangle in the z = 0 plane, counter-clockwise seen from +z, with normals +z.
inline const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};
inline const std::vector<float> kTriangleNormals = {0, 0, 1, 0, 0, 1, 0, 0, 1};

inline glm::vec3 geometricNormal(const caustica::Triangle& t) {
  return glm::normalize(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]));
}

inline bool near(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) { return glm::length(a - b) <= eps; }

// The error message for loading `path`, checking that only caustica::Error is thrown.
inline std::string loadError(const std::string& path) {
  try {
    caustica::loadScene(path);
  } catch (const caustica::Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    FAIL("non-caustica exception for ", path, ": ", e.what());
  }
  return "";
}

inline bool hasWarning(const caustica::Scene& s, const std::string& text) {
  for (const auto& w : s.warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace caustica::test
