// scene_gltf.cpp — loads a glTF 2.0 file (.gltf or .glb) into caustica::Scene after the material
// contract in docs/materials.md. Every index, byte range and JSON type is checked here before use:
// bad input ends in caustica::Error("FILE: what is wrong"), never in a crash, hang or silent default.
#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wshadow"
#include <nlohmann/json.hpp>
#include <stb_image.h>
#include <tiny_gltf.h>
#pragma GCC diagnostic pop

#include "util/error.h"
#include "util/file_io.h"
#include "util/math_constants.h"
#include "scene/scene.h"

namespace caustica {
namespace {

using Json = nlohmann::json;

// ---- limits that keep hostile files from exhausting the stack or memory ------------------------
constexpr int kMaxJsonDepth = 64;                       // nesting of JSON arrays/objects
constexpr std::uint64_t kMaxIndex = 0x7fffffff;         // any glTF index (tinygltf stores int)
constexpr std::uint64_t kMaxByteCount = 1ull << 53;     // byte lengths/offsets (exact in a double)
constexpr std::uint64_t kMaxZeroElements = 1ull << 22;  // elements of an accessor without bufferView
constexpr std::uint64_t kMaxDecoded = 1ull << 28;       // accessor elements decoded for the whole scene
constexpr std::size_t kMaxTriangles = 1u << 24;         // triangles in a scene (GPU buffers: 112 B each)
constexpr int kMaxTextureSide = 16384;                  // texels
constexpr std::int64_t kMaxTexturePixels = 1ll << 26;   // texels in one texture (256 MiB as RGBA8)
constexpr std::size_t kMaxMessage = 300;                // characters kept from a third-party message

const char* const kSupportedExtensions[] = {
    "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume",
    "KHR_materials_dispersion", "KHR_materials_emissive_strength"};

bool isSupportedExtension(const std::string& name) {
  for (const char* s : kSupportedExtensions)
    if (name == s) return true;
  return false;
}

std::string supportedExtensionList() {
  std::string out;
  for (const char* s : kSupportedExtensions) out += (out.empty() ? "" : ", ") + std::string(s);
  return out;
}

// A third-party message (tinygltf, nlohmann, stb) as one printable line: lines joined with "; ",
// control and non-ASCII bytes replaced, and the length bounded.
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

std::string str(std::uint64_t v) { return std::to_string(v); }

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// Depth of the deepest array/object nesting, scanning no further than `limit` + 1 levels.
int jsonDepth(const char* text, std::size_t size, int limit) {
  int depth = 0, deepest = 0;
  bool inString = false;
  for (std::size_t i = 0; i < size; ++i) {
    const char c = text[i];
    if (inString) {
      if (c == '\\') ++i;
      else if (c == '"') inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) return deepest;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

// True when `count` elements of `elem` bytes, `stride` bytes apart, starting at `offset`, lie inside
// `length` bytes. Written without products that could overflow.
bool rangeFits(std::uint64_t offset, std::uint64_t stride, std::uint64_t count, std::uint64_t elem,
               std::uint64_t length) {
  if (count == 0) return offset <= length;
  if (offset > length || elem > length - offset) return false;
  const std::uint64_t room = length - offset - elem;  // bytes left for the other count - 1 strides
  return count - 1 == 0 || (stride != 0 && count - 1 <= room / stride);
}

// ---- JSON structure check (before tinygltf sees the document) ------------------------------------
// tinygltf silently ignores optional properties of the wrong type and does not bound-check some
// byte ranges; this pass rejects such files with a message naming the property.
class JsonChecker {
 public:
  // baseDir: folder of external files; binary: the document is a GLB's JSON chunk.
  JsonChecker(const std::string& path, const std::string& baseDir, bool binary)
      : path_(path), baseDir_(baseDir), binary_(binary) {}

  void check(const Json& root) {
    if (!root.is_object()) fail("the top-level JSON value is " + describe(root) + ", not an object");
    checkAsset(root);
    checkExtensionLists(root);
    // Shapes of the top-level arrays first: the checks below look across them.
    for (const char* key : {"scenes", "nodes", "meshes", "accessors", "bufferViews", "buffers", "images", "samplers",
                            "textures", "materials", "cameras", "skins", "animations"})
      forEach(root, key, [](const Json&, const std::string&) {});
    index(root, "", "scene");
    forEach(root, "scenes", [&](const Json& o, const std::string& at) { indexArray(o, at, "nodes"); });
    forEach(root, "nodes", [&](const Json& o, const std::string& at) { checkNode(o, at); });
    forEach(root, "meshes", [&](const Json& o, const std::string& at) { checkMesh(root, o, at); });
    forEach(root, "accessors", [&](const Json& o, const std::string& at) { checkAccessor(root, o, at); });
    forEach(root, "buffers", [&](const Json& o, const std::string& at) { checkBuffer(o, at); });
    forEach(root, "bufferViews", [&](const Json& o, const std::string& at) { checkBufferView(root, o, at); });
    forEach(root, "images", [&](const Json& o, const std::string& at) { checkImage(root, o, at); });
    forEach(root, "samplers", [&](const Json& o, const std::string& at) {
      for (const char* key : {"magFilter", "minFilter", "wrapS", "wrapT"}) index(o, at, key);
    });
    forEach(root, "textures", [&](const Json& o, const std::string& at) {
      index(o, at, "sampler");
      index(o, at, "source");
      object(o, at, "extensions");
    });
    forEach(root, "materials", [&](const Json& o, const std::string& at) { checkMaterial(o, at); });
    forEach(root, "cameras", [&](const Json& o, const std::string& at) { checkCamera(o, at); });
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw Error(path_ + ": " + what); }

  static std::string join(const std::string& at, const std::string& key) {
    return at.empty() ? key : at + "." + key;
  }

  static std::string describe(const Json& j) {
    switch (j.type()) {
      case Json::value_t::null: return "null";
      case Json::value_t::object: return "an object";
      case Json::value_t::array: return "an array";
      case Json::value_t::string: return "a string";
      case Json::value_t::boolean: return "a boolean";
      case Json::value_t::number_integer:
      case Json::value_t::number_unsigned: return "an integer";
      case Json::value_t::number_float: return "a number";
      default: return "an unexpected value";
    }
  }

  static const Json* find(const Json& obj, const char* key) {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  const Json* member(const Json& obj, const std::string& at, const char* key, bool required) const {
    const Json* v = find(obj, key);
    if (!v && required) fail(join(at, key) + " is missing");
    return v;
  }

  void expect(bool ok, const Json& v, const std::string& where, const char* what) const {
    if (!ok) fail(where + " must be " + what + ", but it is " + describe(v));
  }

  // A non-negative integer no larger than `max`.
  void checkIndexValue(const Json& v, const std::string& where, std::uint64_t max) const {
    bool ok = v.is_number_unsigned() || (v.is_number_integer() && v.get<std::int64_t>() >= 0);
    expect(ok, v, where, "a non-negative integer");
    if (v.get<std::uint64_t>() > max)
      fail(where + " is " + str(v.get<std::uint64_t>()) + ", too large (limit " + str(max) + ")");
  }

  const Json* index(const Json& obj, const std::string& at, const char* key, bool required = false,
                    std::uint64_t max = kMaxIndex) const {
    const Json* v = member(obj, at, key, required);
    if (v) checkIndexValue(*v, join(at, key), max);
    return v;
  }

  const Json* number(const Json& obj, const std::string& at, const char* key, bool required = false) const {
    const Json* v = member(obj, at, key, required);
    if (v) {
      expect(v->is_number(), *v, join(at, key), "a number");
      if (!std::isfinite(v->get<double>())) fail(join(at, key) + " is not a finite number");
    }
    return v;
  }

  void boolean(const Json& obj, const std::string& at, const char* key) const {
    const Json* v = member(obj, at, key, false);
    if (v) expect(v->is_boolean(), *v, join(at, key), "true or false");
  }

  const Json* string(const Json& obj, const std::string& at, const char* key, bool required = false) const {
    const Json* v = member(obj, at, key, required);
    if (v) expect(v->is_string(), *v, join(at, key), "a string");
    return v;
  }

  const Json* object(const Json& obj, const std::string& at, const char* key, bool required = false) const {
    const Json* v = member(obj, at, key, required);
    if (v) expect(v->is_object(), *v, join(at, key), "an object");
    return v;
  }

  const Json* array(const Json& obj, const std::string& at, const char* key, bool required = false) const {
    const Json* v = member(obj, at, key, required);
    if (v) expect(v->is_array(), *v, join(at, key), "an array");
    return v;
  }

  // An array of exactly `n` finite numbers (n = 0: any length).
  void numbers(const Json& obj, const std::string& at, const char* key, std::size_t n) const {
    const Json* v = array(obj, at, key);
    if (!v) return;
    if (n != 0 && v->size() != n)
      fail(join(at, key) + " must have " + str(n) + " numbers, but it has " + str(v->size()));
    for (std::size_t i = 0; i < v->size(); ++i) {
      const std::string where = join(at, key) + "[" + str(i) + "]";
      expect((*v)[i].is_number(), (*v)[i], where, "a number");
      if (!std::isfinite((*v)[i].get<double>())) fail(where + " is not a finite number");
    }
  }

  void indexArray(const Json& obj, const std::string& at, const char* key) const {
    const Json* v = array(obj, at, key);
    if (!v) return;
    for (std::size_t i = 0; i < v->size(); ++i)
      checkIndexValue((*v)[i], join(at, key) + "[" + str(i) + "]", kMaxIndex);
  }

  // Calls fn(element, "key[i]") for each element of the top-level array `key`, which must hold objects.
  template <class Fn>
  void forEach(const Json& root, const char* key, Fn fn) const {
    const Json* v = array(root, "", key);
    if (!v) return;
    for (std::size_t i = 0; i < v->size(); ++i) {
      const std::string at = std::string(key) + "[" + str(i) + "]";
      expect((*v)[i].is_object(), (*v)[i], at, "an object");
      fn((*v)[i], at);
    }
  }

  void checkAsset(const Json& root) const {
    const Json* asset = find(root, "asset");
    if (!asset) fail("the 'asset' object is missing (a glTF file must have asset.version \"2.0\")");
    expect(asset->is_object(), *asset, "asset", "an object");
    const Json* version = string(*asset, "asset", "version", true);
    const std::string v = version->get<std::string>();
    if (v.rfind("2.", 0) != 0) fail("asset.version is \"" + oneLine(v) + "\"; only glTF 2.x is supported");
    if (const Json* minVersion = string(*asset, "asset", "minVersion")) {
      const std::string mv = minVersion->get<std::string>();
      if (mv != "2.0") fail("asset.minVersion is \"" + oneLine(mv) + "\"; only glTF 2.0 is supported");
    }
  }

  void checkExtensionLists(const Json& root) const {
    for (const char* key : {"extensionsUsed", "extensionsRequired"}) {
      const Json* list = array(root, "", key);
      if (!list) continue;
      for (std::size_t i = 0; i < list->size(); ++i)
        expect((*list)[i].is_string(), (*list)[i], std::string(key) + "[" + str(i) + "]", "a string");
    }
    object(root, "", "extensions");
    if (const Json* required = find(root, "extensionsRequired")) {
      for (const Json& name : *required) {
        const std::string ext = name.get<std::string>();
        if (!isSupportedExtension(ext))
          fail("the file requires extension " + oneLine(ext) + ", which caustica does not support (supported: " +
               supportedExtensionList() + ")");
      }
    }
  }

  void checkNode(const Json& o, const std::string& at) const {
    index(o, at, "camera");
    index(o, at, "mesh");
    index(o, at, "skin");
    indexArray(o, at, "children");
    numbers(o, at, "matrix", 16);
    numbers(o, at, "rotation", 4);
    numbers(o, at, "scale", 3);
    numbers(o, at, "translation", 3);
    numbers(o, at, "weights", 0);
    string(o, at, "name");
  }

  static std::size_t arraySize(const Json& root, const char* key) {
    const Json* v = find(root, key);
    return v ? v->size() : 0;
  }

  // An index property that must also refer to an existing element of the top-level array `target`.
  const Json* reference(const Json& root, const Json& obj, const std::string& at, const char* key,
                        const char* target, bool required = false) const {
    const Json* v = index(obj, at, key, required);
    if (v) checkReference(root, *v, join(at, key), target);
    return v;
  }

  void checkReference(const Json& root, const Json& v, const std::string& where, const char* target) const {
    const std::size_t count = arraySize(root, target);
    if (v.get<std::uint64_t>() >= count)
      fail(where + " is " + str(v.get<std::uint64_t>()) + ", but the file has " + str(count) + " " + target);
  }

  void checkMesh(const Json& root, const Json& o, const std::string& at) const {
    const Json* prims = array(o, at, "primitives", true);
    for (std::size_t i = 0; i < prims->size(); ++i) {
      const Json& p = (*prims)[i];
      const std::string pat = join(at, "primitives") + "[" + str(i) + "]";
      expect(p.is_object(), p, pat, "an object");
      const Json* attributes = object(p, pat, "attributes", true);
      for (const auto& item : attributes->items()) {
        const std::string where = join(pat, "attributes") + "." + oneLine(item.key());
        checkIndexValue(item.value(), where, kMaxIndex);
        checkReference(root, item.value(), where, "accessors");
      }
      if (const Json* indices = reference(root, p, pat, "indices", "accessors")) {
        const Json& accessor = (*find(root, "accessors"))[indices->get<std::size_t>()];
        if (accessor.is_object() && !accessor.contains("bufferView"))
          fail(join(pat, "indices") + ": accessors[" + str(indices->get<std::uint64_t>()) +
               "] has no bufferView (index data must be stored)");
      }
      index(p, pat, "material");
      index(p, pat, "mode");
      array(p, pat, "targets");
    }
  }

  void checkAccessor(const Json& root, const Json& o, const std::string& at) const {
    reference(root, o, at, "bufferView", "bufferViews");
    index(o, at, "byteOffset", false, kMaxByteCount);
    const auto componentType = index(o, at, "componentType", true)->get<std::uint64_t>();
    if (componentType < 5120 || componentType > 5126 || componentType == 5124)
      fail(join(at, "componentType") + " is " + str(componentType) +
           "; it must be 5120 (BYTE), 5121, 5122, 5123, 5125 or 5126 (FLOAT)");
    boolean(o, at, "normalized");
    index(o, at, "count", true, kMaxByteCount);
    const std::string type = string(o, at, "type", true)->get<std::string>();
    static const char* const kTypes[] = {"SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4"};
    if (std::none_of(std::begin(kTypes), std::end(kTypes), [&](const char* t) { return type == t; }))
      fail(join(at, "type") + " is \"" + oneLine(type) + "\"; it must be SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4");
    numbers(o, at, "min", 0);
    numbers(o, at, "max", 0);
    if (const Json* sparse = object(o, at, "sparse")) {
      const std::string sat = join(at, "sparse");
      index(*sparse, sat, "count", true);
      const Json* indices = object(*sparse, sat, "indices", true);
      reference(root, *indices, join(sat, "indices"), "bufferView", "bufferViews", true);
      index(*indices, join(sat, "indices"), "byteOffset");
      index(*indices, join(sat, "indices"), "componentType", true);
      const Json* values = object(*sparse, sat, "values", true);
      reference(root, *values, join(sat, "values"), "bufferView", "bufferViews", true);
      index(*values, join(sat, "values"), "byteOffset");
    }
  }

  // Buffer sources are checked here so that the messages name the buffer (tinygltf's do not).
  void checkBuffer(const Json& o, const std::string& at) const {
    const auto length = index(o, at, "byteLength", true, kMaxByteCount)->get<std::uint64_t>();
    const Json* uriValue = string(o, at, "uri");
    if (!uriValue) {
      if (!binary_) fail(join(at, "uri") + " is missing (only a .glb file's buffer may omit it)");
      return;
    }
    const std::string uri = uriValue->get<std::string>();
    if (uri.rfind("data:", 0) == 0) {
      const auto comma = uri.find(";base64,");
      if (comma == std::string::npos) fail(join(at, "uri") + " is a data URI without base64 content");
      std::size_t chars = uri.size() - comma - 8;
      const char* payload = uri.c_str() + comma + 8;
      while (chars > 0 && payload[chars - 1] == '=') --chars;
      for (std::size_t i = 0; i < chars; ++i)
        if (!std::isalnum(static_cast<unsigned char>(payload[i])) && payload[i] != '+' && payload[i] != '/')
          fail(join(at, "uri") + " holds invalid base64 data (character " + str(i) + ")");
      const std::uint64_t decoded = chars / 4 * 3 + (chars % 4 == 0 ? 0 : chars % 4 - 1);
      if (decoded != length)
        fail(at + ": the data URI holds " + str(decoded) + " bytes but byteLength is " + str(length));
      return;
    }
    const std::filesystem::path file = std::filesystem::path(baseDir_) / uriDecode(uri);
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
      fail(join(at, "uri") + " '" + oneLine(uri) + "': file not found (" + oneLine(file.string()) + ")");
    const std::uint64_t size = std::filesystem::file_size(file, ec);
    if (!ec && size != length)
      fail(at + " '" + oneLine(uri) + "' is " + str(size) + " bytes, but byteLength is " + str(length));
  }

  // Percent-decoding of a relative URI (glTF URIs are RFC 3986).
  static std::string uriDecode(const std::string& uri) {
    std::string out;
    for (std::size_t i = 0; i < uri.size(); ++i) {
      if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
          std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
        out += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
        i += 2;
      } else {
        out += uri[i];
      }
    }
    return out;
  }

  // Byte ranges of buffer views are checked here because tinygltf reads embedded images through
  // them without a bounds check.
  void checkBufferView(const Json& root, const Json& o, const std::string& at) const {
    const auto buffer = index(o, at, "buffer", true)->get<std::uint64_t>();
    const Json* offsetValue = index(o, at, "byteOffset", false, kMaxByteCount);
    const auto offset = offsetValue ? offsetValue->get<std::uint64_t>() : 0;
    const auto length = index(o, at, "byteLength", true, kMaxByteCount)->get<std::uint64_t>();
    index(o, at, "byteStride");
    if (length == 0) fail(join(at, "byteLength") + " is 0 (it must be at least 1)");
    const Json* buffers = find(root, "buffers");
    const std::size_t bufferCount = buffers ? buffers->size() : 0;
    if (buffer >= bufferCount)
      fail(join(at, "buffer") + " is " + str(buffer) + ", but the file has " + str(bufferCount) + " buffers");
    const auto bufferLength = (*buffers)[buffer]["byteLength"].get<std::uint64_t>();
    if (!rangeFits(offset, 0, 1, length, bufferLength))
      fail(at + " (byteOffset " + str(offset) + ", byteLength " + str(length) + ") overruns buffers[" + str(buffer) +
           "] (" + str(bufferLength) + " bytes)");
  }

  void checkImage(const Json& root, const Json& o, const std::string& at) const {
    if (!o.contains("uri") && !o.contains("bufferView")) fail(at + " has neither a uri nor a bufferView");
    string(o, at, "uri");
    string(o, at, "mimeType");
    if (const Json* view = index(o, at, "bufferView")) {
      const Json* views = find(root, "bufferViews");
      const std::size_t viewCount = views ? views->size() : 0;
      if (view->get<std::uint64_t>() >= viewCount)
        fail(join(at, "bufferView") + " is " + str(view->get<std::uint64_t>()) + ", but the file has " +
             str(viewCount) + " buffer views");
    }
  }

  void textureInfo(const Json& o, const std::string& at, const char* key) const {
    const Json* info = object(o, at, key);
    if (!info) return;
    const std::string iat = join(at, key);
    index(*info, iat, "index", true);
    index(*info, iat, "texCoord");
    number(*info, iat, "scale");
    number(*info, iat, "strength");
    object(*info, iat, "extensions");
  }

  void checkMaterial(const Json& o, const std::string& at) const {
    string(o, at, "name");
    if (const Json* pbr = object(o, at, "pbrMetallicRoughness")) {
      const std::string pat = join(at, "pbrMetallicRoughness");
      numbers(*pbr, pat, "baseColorFactor", 4);
      textureInfo(*pbr, pat, "baseColorTexture");
      number(*pbr, pat, "metallicFactor");
      number(*pbr, pat, "roughnessFactor");
      textureInfo(*pbr, pat, "metallicRoughnessTexture");
    }
    textureInfo(o, at, "normalTexture");
    textureInfo(o, at, "occlusionTexture");
    textureInfo(o, at, "emissiveTexture");
    numbers(o, at, "emissiveFactor", 3);
    string(o, at, "alphaMode");
    number(o, at, "alphaCutoff");
    boolean(o, at, "doubleSided");
    const Json* ext = object(o, at, "extensions");
    if (!ext) return;
    const std::string eat = join(at, "extensions");
    if (const Json* e = object(*ext, eat, "KHR_materials_transmission")) {
      number(*e, join(eat, "KHR_materials_transmission"), "transmissionFactor");
      textureInfo(*e, join(eat, "KHR_materials_transmission"), "transmissionTexture");
    }
    if (const Json* e = object(*ext, eat, "KHR_materials_ior")) number(*e, join(eat, "KHR_materials_ior"), "ior");
    if (const Json* e = object(*ext, eat, "KHR_materials_volume")) {
      const std::string vat = join(eat, "KHR_materials_volume");
      number(*e, vat, "thicknessFactor");
      number(*e, vat, "attenuationDistance");
      numbers(*e, vat, "attenuationColor", 3);
      textureInfo(*e, vat, "thicknessTexture");
    }
    if (const Json* e = object(*ext, eat, "KHR_materials_dispersion"))
      number(*e, join(eat, "KHR_materials_dispersion"), "dispersion");
    if (const Json* e = object(*ext, eat, "KHR_materials_emissive_strength"))
      number(*e, join(eat, "KHR_materials_emissive_strength"), "emissiveStrength");
  }

  void checkCamera(const Json& o, const std::string& at) const {
    const std::string type = string(o, at, "type", true)->get<std::string>();
    if (type != "perspective" && type != "orthographic")
      fail(join(at, "type") + " is \"" + oneLine(type) + "\"; it must be perspective or orthographic");
    object(o, at, type.c_str(), true);
    string(o, at, "name");
    if (const Json* p = object(o, at, "perspective")) {
      const std::string pat = join(at, "perspective");
      const double yfov = number(*p, pat, "yfov", true)->get<double>();
      if (!(yfov > 0.0 && yfov < kPiD))
        fail(join(pat, "yfov") + " is " + num(yfov) + "; it must be an angle in radians between 0 and pi");
      if (const Json* aspect = number(*p, pat, "aspectRatio"))
        if (!(aspect->get<double>() > 0.0))
          fail(join(pat, "aspectRatio") + " is " + num(aspect->get<double>()) + "; it must be positive");
      number(*p, pat, "znear");
      number(*p, pat, "zfar");
    }
    object(o, at, "orthographic");
  }

  std::string path_;
  std::string baseDir_;
  bool binary_;
};

// ---- file reading --------------------------------------------------------------------------------
// File access for tinygltf (external buffers and images): regular files only, read with the same
// checks as the scene file itself (tinygltf's default reader trusts the size a directory reports).
bool fsFileExists(const std::string& path, void*) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

std::string fsExpandFilePath(const std::string& path, void*) { return path; }

bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void*) {
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

std::uint32_t readU32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
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

// ---- image decoding (tinygltf callback) ----------------------------------------------------------
// Decodes every image to 8-bit RGBA with stb_image. A failure is recorded rather than returned, so
// an unused broken image does not stop loading; using it is an error (SceneBuilder::texture).
struct ImageLog {
  std::map<int, std::string> failures;  // image index -> reason
};

bool decodeImage(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                 const unsigned char* bytes, int size, void* user) {
  auto* log = static_cast<ImageLog*>(user);
  int w = 0, h = 0, channels = 0;
  if (!bytes || size <= 0 || !stbi_info_from_memory(bytes, size, &w, &h, &channels)) {
    const char* reason = stbi_failure_reason();
    log->failures[index] = std::string("not a decodable PNG/JPEG image (") + (reason ? reason : "unknown format") + ")";
    return true;
  }
  if (w < 1 || h < 1 || w > kMaxTextureSide || h > kMaxTextureSide ||
      std::int64_t(w) * std::int64_t(h) > kMaxTexturePixels) {
    log->failures[index] = "its size " + str(std::uint64_t(std::max(w, 0))) + "x" + str(std::uint64_t(std::max(h, 0))) +
                           " is out of range (at most " + str(kMaxTextureSide) + " per side)";
    return true;
  }
  unsigned char* pixels = stbi_load_from_memory(bytes, size, &w, &h, &channels, 4);
  if (!pixels) {
    const char* reason = stbi_failure_reason();
    log->failures[index] = std::string("it could not be decoded (") + (reason ? reason : "unknown error") + ")";
    return true;
  }
  image->width = w;
  image->height = h;
  image->component = 4;
  image->bits = 8;
  image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  image->image.assign(pixels, pixels + std::size_t(w) * std::size_t(h) * 4);
  stbi_image_free(pixels);
  return true;
}

// ---- glTF model -> Scene -------------------------------------------------------------------------
struct Format {
  int componentType;
  bool normalized;
};

const char* componentName(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
    default: return nullptr;
  }
}

std::string formatName(int componentType, bool normalized) {
  const char* name = componentName(componentType);
  return std::string(normalized ? "normalized " : "") +
         (name ? name : "invalid (" + std::to_string(componentType) + ")");
}

const char* typeName(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "unknown";
  }
}

std::size_t componentSize(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

// One component, little-endian, with glTF's normalisation rules for integer types.
double readComponent(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double v = static_cast<std::int8_t>(p[0]);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      const double v = static_cast<std::int16_t>(std::uint16_t(p[0] | p[1] << 8));
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      const double v = std::uint16_t(p[0] | p[1] << 8);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return readU32(p);
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      const std::uint32_t bits = readU32(p);
      float f;
      std::memcpy(&f, &bits, 4);
      return f;
    }
    default: return 0.0;
  }
}

const tinygltf::Value* extension(const tinygltf::ExtensionMap& map, const char* name) {
  const auto it = map.find(name);
  return it == map.end() || !it->second.IsObject() ? nullptr : &it->second;
}

double extNumber(const tinygltf::Value* ext, const char* key, double fallback) {
  if (!ext || !ext->Has(key) || !ext->Get(key).IsNumber()) return fallback;
  return ext->Get(key).GetNumberAsDouble();
}

bool extHas(const tinygltf::Value* ext, const char* key) { return ext && ext->Has(key); }

struct NodeTransform {
  glm::dmat4 world{1.0};
  glm::dmat3 normal{1.0};  // inverse transpose of the upper 3x3
  bool flip = false;       // negative determinant: glTF then defines clockwise fronts
};

class SceneBuilder {
 public:
  SceneBuilder(const std::string& path, const tinygltf::Model& model, const ImageLog& images, Scene& scene)
      : path_(path), model_(model), images_(images), scene_(scene) {}

  void build() {
    warnUnsupportedExtensions();
    for (std::size_t i = 0; i < model_.materials.size(); ++i) scene_.materials.push_back(convertMaterial(int(i)));
    traverse();
    if (degenerate_ > 0) warn("skipped " + str(degenerate_) + " degenerate (zero-area) triangle(s)");
    if (badNormals_ > 0)
      warn(str(badNormals_) + " triangle(s) had zero or non-finite vertex normals; flat normals used for them");
    if (scene_.triangles.empty()) {
      std::string why = firstSkip_;
      if (why.empty() && degenerate_ > 0) why = "all " + str(degenerate_) + " triangles have zero area";
      if (why.empty()) why = "the default scene's nodes reference no mesh triangles";
      fail("the scene has no triangles to render (" + why + ")");
    }
    for (const Triangle& t : scene_.triangles)
      for (const glm::vec3& p : t.p) scene_.bounds.grow(p);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw Error(path_ + ": " + what); }
  void warn(const std::string& what) { scene_.warnings.push_back(path_ + ": " + what); }

  void skip(const std::string& what) {
    if (firstSkip_.empty()) firstSkip_ = what;
    warn(what);
  }

  void warnUnsupportedExtensions() {
    std::string list;
    for (const std::string& ext : model_.extensionsUsed)
      if (!isSupportedExtension(ext)) list += (list.empty() ? "" : ", ") + oneLine(ext);
    if (!list.empty()) warn("ignoring unsupported extension(s): " + list);
  }

  // ---- materials ----
  double unit(double v, const std::string& what) {
    if (v < 0.0 || v > 1.0) {
      warn(what + " = " + num(v) + " is outside [0, 1]; clamped");
      return std::clamp(v, 0.0, 1.0);
    }
    return v;
  }

  Material convertMaterial(int index) {
    const tinygltf::Material& m = model_.materials[std::size_t(index)];
    const std::string at = "materials[" + str(std::uint64_t(index)) + "]";
    Material out;
    out.name = m.name.empty() ? "material " + str(std::uint64_t(index)) : m.name;
    const auto& pbr = m.pbrMetallicRoughness;

    glm::dvec4 base(1.0);
    for (std::size_t c = 0; c < 4 && c < pbr.baseColorFactor.size(); ++c)
      base[int(c)] = unit(pbr.baseColorFactor[c], at + ".baseColorFactor[" + str(c) + "]");
    out.metallic = float(unit(pbr.metallicFactor, at + ".metallicFactor"));
    out.roughness = float(unit(pbr.roughnessFactor, at + ".roughnessFactor"));
    out.baseColorTexture = texture(pbr.baseColorTexture, at + ".baseColorTexture");

    // Opacity: OPAQUE ignores alpha, MASK thresholds the factor, BLEND keeps it. Texture alpha is
    // not used (docs/materials.md).
    if (m.alphaMode == "OPAQUE" || m.alphaMode.empty()) {
      base.a = 1.0;
    } else if (m.alphaMode == "MASK") {
      base.a = base.a >= m.alphaCutoff ? 1.0 : 0.0;
    } else if (m.alphaMode != "BLEND") {
      fail(at + ".alphaMode is \"" + oneLine(m.alphaMode) + "\"; it must be OPAQUE, BLEND or MASK");
    }
    out.baseColor = glm::vec4(base);

    // Emission: emissiveFactor x KHR_materials_emissive_strength = radiance (linear).
    glm::dvec3 emissive(0.0);
    for (std::size_t c = 0; c < 3 && c < m.emissiveFactor.size(); ++c) {
      emissive[int(c)] = m.emissiveFactor[c];
      if (emissive[int(c)] < 0.0) {
        warn(at + ".emissiveFactor[" + str(c) + "] is negative; clamped to 0");
        emissive[int(c)] = 0.0;
      }
    }
    double strength = extNumber(extension(m.extensions, "KHR_materials_emissive_strength"), "emissiveStrength", 1.0);
    if (strength < 0.0) {
      warn(at + ": emissiveStrength " + num(strength) + " is negative; using 0");
      strength = 0.0;
    }
    out.emission = glm::vec3(emissive * strength);
    if (!std::isfinite(out.emission.r) || !std::isfinite(out.emission.g) || !std::isfinite(out.emission.b))
      fail(at + ": emitted radiance overflows a float");
    out.emissiveTexture = texture(m.emissiveTexture, at + ".emissiveTexture");
    out.doubleSided = m.doubleSided;

    std::string ignored;
    const auto ignore = [&](bool present, const char* what) {
      if (present) ignored += (ignored.empty() ? "" : ", ") + std::string(what);
    };
    ignore(pbr.metallicRoughnessTexture.index >= 0, "metallicRoughnessTexture");
    ignore(m.normalTexture.index >= 0, "normalTexture");
    ignore(m.occlusionTexture.index >= 0, "occlusionTexture");

    if (const tinygltf::Value* t = extension(m.extensions, "KHR_materials_transmission")) {
      out.transmission = float(unit(extNumber(t, "transmissionFactor", 0.0), at + ".transmissionFactor"));
      ignore(extHas(t, "transmissionTexture"), "transmissionTexture");
    }
    if (const tinygltf::Value* e = extension(m.extensions, "KHR_materials_ior")) {
      const double ior = extNumber(e, "ior", 1.5);
      if (ior < 1.0) warn(at + ": ior " + num(ior) + " is below 1; using 1.5");
      else out.ior = float(ior);
    }
    if (const tinygltf::Value* v = extension(m.extensions, "KHR_materials_volume")) {
      // thicknessFactor is ignored: the ray tracer follows the real geometry through the volume.
      ignore(extHas(v, "thicknessTexture"), "thicknessTexture");
      if (extHas(v, "attenuationColor") && v->Get("attenuationColor").ArrayLen() == 3)
        for (int c = 0; c < 3; ++c)
          out.attenuationColor[c] = float(unit(v->Get("attenuationColor").Get(c).GetNumberAsDouble(),
                                               at + ".attenuationColor[" + str(std::uint64_t(c)) + "]"));
      const double distance = extNumber(v, "attenuationDistance", std::numeric_limits<double>::infinity());
      if (!(distance > 0.0)) warn(at + ": attenuationDistance " + num(distance) + " is not positive; no absorption");
      else out.attenuationDistance = float(distance);
    }
    if (const tinygltf::Value* d = extension(m.extensions, "KHR_materials_dispersion")) {
      const double dispersion = extNumber(d, "dispersion", 0.0);
      if (dispersion < 0.0) warn(at + ": dispersion " + num(dispersion) + " is negative; using 0");
      else out.dispersion = float(dispersion);
    }
    if (!ignored.empty()) warn(at + " '" + oneLine(out.name) + "': ignoring unsupported " + ignored);
    if (out.roughness > 0.0f && (out.metallic > 0.0f || out.transmission > 0.0f))
      warn(at + " '" + oneLine(out.name) + "': roughness " + num(out.roughness) +
           " on a mirror/glass component is rendered as perfectly smooth (rough lobes are not implemented)");
    return out;
  }

  static void wrapMode(int mode, bool& repeat, bool& mirror) {
    repeat = mode != TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    mirror = mode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT;
  }

  int texture(const tinygltf::TextureInfo& info, const std::string& at) {
    if (info.index < 0) return -1;
    if (std::size_t(info.index) >= model_.textures.size())
      fail(at + ".index is " + str(std::uint64_t(info.index)) + ", but the file has " + str(model_.textures.size()) +
           " textures");
    if (info.texCoord != 0)
      warn(at + " uses TEXCOORD_" + str(std::uint64_t(info.texCoord)) + "; only TEXCOORD_0 is loaded and used instead");
    if (info.extensions.count("KHR_texture_transform")) warn(at + ": KHR_texture_transform is not supported; ignored");
    const auto cached = textureMap_.find(info.index);
    if (cached != textureMap_.end()) return cached->second;

    const tinygltf::Texture& tex = model_.textures[std::size_t(info.index)];
    const std::string tat = "textures[" + str(std::uint64_t(info.index)) + "]";
    int result = -1;
    if (tex.source < 0) {
      warn(tat + " has no PNG/JPEG source image; ignored");
    } else {
      if (std::size_t(tex.source) >= model_.images.size())
        fail(tat + ".source is " + str(std::uint64_t(tex.source)) + ", but the file has " + str(model_.images.size()) +
             " images");
      const tinygltf::Image& img = model_.images[std::size_t(tex.source)];
      const std::string iat = "images[" + str(std::uint64_t(tex.source)) + "]" +
                              (img.uri.empty() ? std::string() : " '" + oneLine(img.uri) + "'");
      if (img.image.empty()) {
        const auto reason = images_.failures.find(tex.source);
        fail(iat + " could not be loaded: " +
             (reason != images_.failures.end() ? reason->second : std::string("file not found or unreadable")));
      }
      if (img.width < 1 || img.height < 1 || img.component != 4 || img.bits != 8 ||
          img.image.size() != std::size_t(img.width) * std::size_t(img.height) * 4)
        fail(iat + " has an unexpected pixel layout");
      Texture out;
      out.width = img.width;
      out.height = img.height;
      out.rgba = img.image;
      if (tex.sampler >= 0) {
        if (std::size_t(tex.sampler) >= model_.samplers.size())
          fail(tat + ".sampler is " + str(std::uint64_t(tex.sampler)) + ", but the file has " +
               str(model_.samplers.size()) + " samplers");
        const tinygltf::Sampler& s = model_.samplers[std::size_t(tex.sampler)];
        wrapMode(s.wrapS, out.repeatS, out.mirrorS);
        wrapMode(s.wrapT, out.repeatT, out.mirrorT);
        out.nearest = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
      }
      scene_.textures.push_back(std::move(out));
      result = int(scene_.textures.size() - 1);
    }
    textureMap_[info.index] = result;
    return result;
  }

  std::uint32_t defaultMaterial(const std::string& at) {
    if (defaultMaterial_ < 0) {
      Material m;
      m.name = "default (no material)";
      m.baseColor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
      m.metallic = 0.0f;
      m.roughness = 1.0f;
      scene_.materials.push_back(m);
      defaultMaterial_ = int(scene_.materials.size() - 1);
      warn(at + " has no material; primitives without one use a plain diffuse grey (albedo 0.8)");
    }
    return std::uint32_t(defaultMaterial_);
  }

  // ---- node hierarchy ----
  glm::dmat4 localMatrix(const tinygltf::Node& node, const std::string& at) {
    if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major, as glTF
    glm::dmat4 m(1.0);
    if (node.translation.size() == 3)
      m = glm::translate(m, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
    if (node.rotation.size() == 4) {
      glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);  // (w, x, y, z)
      const double length = glm::length(q);
      if (!(length > 1e-12) || !std::isfinite(length)) {
        warn(at + ".rotation is not a unit quaternion (length " + num(length) + "); using no rotation");
      } else {
        m *= glm::mat4_cast(q / length);
      }
    }
    if (node.scale.size() == 3) m = glm::scale(m, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
    return m;
  }

  // Rejects children out of range, nodes with two parents and cycles, so the walk below terminates.
  std::vector<int> checkHierarchy() {
    const std::size_t n = model_.nodes.size();
    std::vector<int> parent(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
      for (int child : model_.nodes[i].children) {
        const std::string at = "nodes[" + str(i) + "].children";
        if (child < 0 || std::size_t(child) >= n)
          fail(at + " lists node " + std::to_string(child) + ", but the file has " + str(n) + " nodes");
        if (std::size_t(child) == i) fail(at + " lists the node itself (a cycle in the node graph)");
        if (parent[std::size_t(child)] >= 0)
          fail("nodes[" + str(std::uint64_t(child)) + "] has two parents (nodes[" +
               str(std::uint64_t(parent[std::size_t(child)])) + "] and nodes[" + str(i) +
               "]); glTF node hierarchies must be trees");
        parent[std::size_t(child)] = int(i);
      }
    }
    // Every node has at most one parent, so following parents either reaches a root or loops.
    enum : char { kUnseen, kOnPath, kLeadsToRoot };
    std::vector<char> state(n, kUnseen);
    std::vector<std::size_t> path;
    for (std::size_t start = 0; start < n; ++start) {
      path.clear();
      for (std::size_t i = start; state[i] != kLeadsToRoot; i = std::size_t(parent[i])) {
        if (state[i] == kOnPath)
          fail("the node graph has a cycle through nodes[" + str(i) + "] (node hierarchies must be trees)");
        state[i] = kOnPath;
        path.push_back(i);
        if (parent[i] < 0) break;
      }
      for (std::size_t p : path) state[p] = kLeadsToRoot;
    }
    return parent;
  }

  void traverse() {
    const std::vector<int> parent = checkHierarchy();
    std::vector<int> roots;
    if (model_.scenes.empty()) {
      for (std::size_t i = 0; i < parent.size(); ++i)
        if (parent[i] < 0) roots.push_back(int(i));
    } else {
      const int sceneIndex = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (std::size_t(sceneIndex) >= model_.scenes.size())
        fail("scene is " + str(std::uint64_t(sceneIndex)) + ", but the file has " + str(model_.scenes.size()) +
             " scenes");
      roots = model_.scenes[std::size_t(sceneIndex)].nodes;
      for (int r : roots)
        if (r < 0 || std::size_t(r) >= model_.nodes.size())
          fail("scenes[" + str(std::uint64_t(sceneIndex)) + "].nodes lists node " + std::to_string(r) +
               ", but the file has " + str(model_.nodes.size()) + " nodes");
    }
    // Depth-first, pre-order, children in file order; an explicit stack bounds native recursion.
    std::vector<bool> visited(model_.nodes.size(), false);
    std::vector<std::pair<int, glm::dmat4>> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, glm::dmat4(1.0));
    while (!stack.empty()) {
      const auto [index, parentWorld] = stack.back();
      stack.pop_back();
      const std::string at = "nodes[" + str(std::uint64_t(index)) + "]";
      if (visited[std::size_t(index)]) {
        warn(at + " is reached twice from the scene's root nodes; the second instance is skipped");
        continue;
      }
      visited[std::size_t(index)] = true;
      const tinygltf::Node& node = model_.nodes[std::size_t(index)];
      NodeTransform xf;
      xf.world = parentWorld * localMatrix(node, at);
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
          if (!std::isfinite(xf.world[c][r])) fail(at + ": its world transform is not finite");
      if (node.skin >= 0 && !warnedSkin_) {
        warn(at + ": skins are not supported; meshes are drawn in their bind pose");
        warnedSkin_ = true;
      }
      if (node.camera >= 0) addCamera(node.camera, xf.world, node, at);
      if (node.mesh >= 0) {
        const glm::dmat3 m3(xf.world);
        const double det = glm::determinant(m3);
        if (!(std::abs(det) > 1e-300) || !std::isfinite(det)) {
          skip(at + ": its transform is singular (scale 0?); its mesh is skipped");
        } else {
          xf.normal = glm::transpose(glm::inverse(m3));
          xf.flip = det < 0.0;
          addMesh(node.mesh, xf, at);
        }
      }
      for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) stack.emplace_back(*it, xf.world);
    }
  }

  void addCamera(int index, const glm::dmat4& world, const tinygltf::Node& node, const std::string& at) {
    if (std::size_t(index) >= model_.cameras.size())
      fail(at + ".camera is " + str(std::uint64_t(index)) + ", but the file has " + str(model_.cameras.size()) +
           " cameras");
    const tinygltf::Camera& cam = model_.cameras[std::size_t(index)];
    const std::string cat = "cameras[" + str(std::uint64_t(index)) + "]";
    if (cam.type != "perspective") {
      warn(cat + " is " + oneLine(cam.type) + "; only perspective cameras are used");
      return;
    }
    const double yfov = cam.perspective.yfov;
    if (!(yfov > 0.0 && yfov < kPiD))
      fail(cat + ".perspective.yfov is " + num(yfov) + "; it must be an angle in radians between 0 and pi");
    const glm::dmat3 m3(world);
    const glm::dvec3 position(world * glm::dvec4(0.0, 0.0, 0.0, 1.0));
    const glm::dvec3 f = m3 * glm::dvec3(0.0, 0.0, -1.0);
    const glm::dvec3 u = m3 * glm::dvec3(0.0, 1.0, 0.0);
    const double fl = glm::length(f);
    const glm::dvec3 forward = f / fl;
    const glm::dvec3 upOrtho = u - glm::dot(u, forward) * forward;
    const double ul = glm::length(upOrtho);
    if (!(fl > 1e-12) || !(ul > 1e-9 * std::max(1.0, glm::length(u))) || !std::isfinite(fl) || !std::isfinite(ul)) {
      warn(at + ": camera transform is degenerate (zero scale, or up parallel to forward); camera skipped");
      return;
    }
    Camera out;
    out.name = !cam.name.empty() ? cam.name : !node.name.empty() ? node.name : cat;
    out.position = glm::vec3(position);
    out.forward = glm::vec3(forward);
    out.up = glm::vec3(upOrtho / ul);
    out.yfov = float(yfov);
    out.aspect = cam.perspective.aspectRatio > 0.0 ? float(cam.perspective.aspectRatio) : 0.0f;
    scene_.cameras.push_back(out);
  }

  // ---- accessors ----
  struct ViewBytes {
    const unsigned char* data = nullptr;
    std::uint64_t length = 0;
    std::uint64_t stride = 0;  // 0 = tightly packed
  };

  ViewBytes bufferView(int index, const std::string& at) const {
    if (index < 0 || std::size_t(index) >= model_.bufferViews.size())
      fail(at + " refers to bufferView " + std::to_string(index) + ", but the file has " +
           str(model_.bufferViews.size()) + " buffer views");
    const tinygltf::BufferView& view = model_.bufferViews[std::size_t(index)];
    const std::string vat = "bufferViews[" + str(std::uint64_t(index)) + "]";
    if (view.buffer < 0 || std::size_t(view.buffer) >= model_.buffers.size())
      fail(vat + ".buffer is " + std::to_string(view.buffer) + ", but the file has " + str(model_.buffers.size()) +
           " buffers");
    const tinygltf::Buffer& buffer = model_.buffers[std::size_t(view.buffer)];
    if (!rangeFits(view.byteOffset, 0, 1, view.byteLength, buffer.data.size()))
      fail(vat + " (byteOffset " + str(view.byteOffset) + ", byteLength " + str(view.byteLength) +
           ") overruns buffers[" + str(std::uint64_t(view.buffer)) + "] (" + str(buffer.data.size()) + " bytes)");
    return {buffer.data.data() + view.byteOffset, view.byteLength, view.byteStride};
  }

  // Reads accessor `index` as doubles (count x components), applying normalisation and sparse
  // substitution; `allowed` lists the (componentType, normalized) pairs legal for this use.
  std::vector<double> readAccessor(int index, int type, std::initializer_list<Format> allowed, const std::string& use) {
    if (index < 0 || std::size_t(index) >= model_.accessors.size())
      fail(use + " refers to accessor " + std::to_string(index) + ", but the file has " + str(model_.accessors.size()) +
           " accessors");
    const tinygltf::Accessor& acc = model_.accessors[std::size_t(index)];
    const std::string at = "accessors[" + str(std::uint64_t(index)) + "] (" + use + ")";
    if (acc.type != type) fail(at + " has type " + typeName(acc.type) + "; expected " + typeName(type));
    bool legal = false;
    std::string legalList;
    for (const Format& f : allowed) {
      legal = legal || (f.componentType == acc.componentType && f.normalized == acc.normalized);
      legalList += (legalList.empty() ? "" : ", ") + formatName(f.componentType, f.normalized);
    }
    if (!legal)
      fail(at + " has component type " + formatName(acc.componentType, acc.normalized) + "; allowed: " + legalList);
    const std::size_t components = std::size_t(tinygltf::GetNumComponentsInType(std::uint32_t(type)));
    const std::size_t size = componentSize(acc.componentType);
    const std::size_t elem = components * size;
    // Check the byte range before allocating: with a bufferView the count is bounded by real data.
    ViewBytes view;
    std::uint64_t stride = elem;
    if (acc.bufferView >= 0) {
      view = bufferView(acc.bufferView, at);
      if (view.stride != 0 && view.stride < elem)
        fail(at + ": bufferViews[" + str(std::uint64_t(acc.bufferView)) + "].byteStride " + str(view.stride) +
             " is smaller than one element (" + str(elem) + " bytes)");
      if (view.stride != 0) stride = view.stride;
      if (!rangeFits(acc.byteOffset, stride, acc.count, elem, view.length))
        fail(at + ": " + str(acc.count) + " elements of " + str(elem) + " bytes (byteOffset " + str(acc.byteOffset) +
             ", stride " + str(stride) + ") overrun bufferViews[" + str(std::uint64_t(acc.bufferView)) + "] (" +
             str(view.length) + " bytes)");
    } else if (acc.count > kMaxZeroElements) {
      fail(at + ": count " + str(acc.count) + " is too large for an accessor without a bufferView");
    }
    decoded_ += acc.count;
    if (decoded_ > kMaxDecoded) fail("the meshes are too large (more than " + str(kMaxDecoded) + " accessor elements)");
    std::vector<double> out(acc.count * components, 0.0);  // no bufferView: zeros (glTF 3.6.2.3)

    if (acc.bufferView >= 0) {
      const unsigned char* base = view.data + acc.byteOffset;
      for (std::size_t i = 0; i < acc.count; ++i)
        for (std::size_t c = 0; c < components; ++c)
          out[i * components + c] = readComponent(base + i * stride + c * size, acc.componentType, acc.normalized);
    }

    if (acc.sparse.isSparse) {
      const auto& sparse = acc.sparse;
      const std::string sat = at + ": sparse";
      if (sparse.count < 1 || std::uint64_t(sparse.count) > acc.count)
        fail(sat + ".count " + std::to_string(sparse.count) + " must be between 1 and the accessor's count " +
             str(acc.count));
      const int indexType = sparse.indices.componentType;
      if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
          indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        fail(sat + ".indices.componentType " + formatName(indexType, false) +
             " must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
      const std::size_t indexSize = componentSize(indexType);
      const ViewBytes indices = bufferView(sparse.indices.bufferView, sat + ".indices");
      const ViewBytes values = bufferView(sparse.values.bufferView, sat + ".values");
      const auto count = std::uint64_t(sparse.count);
      if (sparse.indices.byteOffset < 0 ||
          !rangeFits(std::uint64_t(sparse.indices.byteOffset), indexSize, count, indexSize, indices.length))
        fail(sat + ".indices overrun bufferViews[" + std::to_string(sparse.indices.bufferView) + "]");
      if (sparse.values.byteOffset < 0 ||
          !rangeFits(std::uint64_t(sparse.values.byteOffset), elem, count, elem, values.length))
        fail(sat + ".values overrun bufferViews[" + std::to_string(sparse.values.bufferView) + "]");
      for (std::uint64_t k = 0; k < count; ++k) {
        const auto target = std::uint64_t(
            readComponent(indices.data + sparse.indices.byteOffset + k * indexSize, indexType, false));
        if (target >= acc.count)
          fail(sat + " index " + str(target) + " is out of range (the accessor has " + str(acc.count) + " elements)");
        const unsigned char* src = values.data + sparse.values.byteOffset + k * elem;
        for (std::size_t c = 0; c < components; ++c)
          out[target * components + c] = readComponent(src + c * size, acc.componentType, acc.normalized);
      }
    }
    return out;
  }

  std::vector<double> readAttribute(const tinygltf::Primitive& prim, const char* name, int type,
                                    std::initializer_list<Format> allowed, std::size_t vertexCount,
                                    const std::string& at) {
    const auto it = prim.attributes.find(name);
    if (it == prim.attributes.end()) return {};
    std::vector<double> values = readAccessor(it->second, type, allowed, at + " " + name);
    const std::size_t components = std::size_t(tinygltf::GetNumComponentsInType(std::uint32_t(type)));
    if (values.size() != vertexCount * components)
      fail(at + ": " + name + " has " + str(values.size() / components) + " elements but POSITION has " +
           str(vertexCount));
    return values;
  }

  // ---- meshes ----
  void addMesh(int meshIndex, const NodeTransform& xf, const std::string& nodeAt) {
    if (std::size_t(meshIndex) >= model_.meshes.size())
      fail(nodeAt + ".mesh is " + str(std::uint64_t(meshIndex)) + ", but the file has " + str(model_.meshes.size()) +
           " meshes");
    const tinygltf::Mesh& mesh = model_.meshes[std::size_t(meshIndex)];
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
      addPrimitive(mesh.primitives[p], xf,
                   "meshes[" + str(std::uint64_t(meshIndex)) + "].primitives[" + str(p) + "]");
  }

  void addPrimitive(const tinygltf::Primitive& prim, const NodeTransform& xf, const std::string& at) {
    static const char* const kModeNames[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
    if (prim.mode >= 0 && prim.mode <= 3) {
      skip(at + ": mode " + kModeNames[prim.mode] + " is not supported (triangles only); primitive skipped");
      return;
    }
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        prim.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      skip(at + ": mode " + std::to_string(prim.mode) + " is not a valid primitive mode; primitive skipped");
      return;
    }
    if (!prim.targets.empty() && !warnedTargets_) {
      warn(at + ": morph targets are not supported; the base shape is used");
      warnedTargets_ = true;
    }
    const auto posIt = prim.attributes.find("POSITION");
    if (posIt == prim.attributes.end()) {
      skip(at + " has no POSITION attribute; primitive skipped");
      return;
    }
    const std::vector<double> positions =
        readAccessor(posIt->second, TINYGLTF_TYPE_VEC3, {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}}, at + " POSITION");
    const std::size_t vertexCount = positions.size() / 3;
    for (std::size_t i = 0; i < positions.size(); ++i)
      if (!std::isfinite(positions[i]))
        fail(at + ": POSITION of vertex " + str(i / 3) + " is " + (std::isnan(positions[i]) ? "NaN" : "infinite"));
    const std::vector<double> normals = readAttribute(
        prim, "NORMAL", TINYGLTF_TYPE_VEC3, {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}}, vertexCount, at);
    const std::vector<double> uvs =
        readAttribute(prim, "TEXCOORD_0", TINYGLTF_TYPE_VEC2,
                      {{TINYGLTF_COMPONENT_TYPE_FLOAT, false},
                       {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true},
                       {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true}},
                      vertexCount, at);
    for (std::size_t i = 0; i < uvs.size(); ++i)
      if (!std::isfinite(uvs[i])) fail(at + ": TEXCOORD_0 of vertex " + str(i / 2) + " is not finite");

    std::vector<std::uint32_t> indices;
    if (prim.indices >= 0) {
      const std::vector<double> raw =
          readAccessor(prim.indices, TINYGLTF_TYPE_SCALAR,
                       {{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, false},
                        {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false},
                        {TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false}},
                       at + " indices");
      indices.reserve(raw.size());
      for (std::size_t i = 0; i < raw.size(); ++i) {
        if (raw[i] >= double(vertexCount))
          fail(at + ": index " + str(std::uint64_t(raw[i])) + " (entry " + str(i) + ") is out of range: POSITION has " +
               str(vertexCount) + " vertices");
        indices.push_back(std::uint32_t(raw[i]));
      }
    } else {
      indices.resize(vertexCount);
      for (std::size_t i = 0; i < vertexCount; ++i) indices[i] = std::uint32_t(i);
    }

    std::uint32_t material;
    if (prim.material >= 0) {
      if (std::size_t(prim.material) >= model_.materials.size())
        fail(at + ".material is " + str(std::uint64_t(prim.material)) + ", but the file has " +
             str(model_.materials.size()) + " materials");
      material = std::uint32_t(prim.material);
    } else {
      material = defaultMaterial(at);
    }

    // Corner triples in glTF's counter-clockwise order for each mode (glTF 3.7.2.1).
    const std::size_t n = indices.size();
    auto corner = [&](std::size_t t, int k) -> std::uint32_t {
      if (prim.mode == TINYGLTF_MODE_TRIANGLES) return indices[3 * t + std::size_t(k)];
      if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        const std::size_t odd = t % 2;
        const std::size_t offset[3] = {0, 1 + odd, 2 - odd};
        return indices[t + offset[k]];
      }
      return k == 2 ? indices[0] : indices[t + 1 + std::size_t(k)];  // fan: (i+1, i+2, 0)
    };
    std::size_t triangles = 0;
    if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
      triangles = n / 3;
      if (n % 3 != 0)
        warn(at + ": " + str(n) + " indices are not a multiple of 3; the last " + str(n % 3) + " are ignored");
    } else if (n >= 3) {
      triangles = n - 2;
    }
    candidates_ += triangles;  // counted before degenerate ones are dropped, so work stays bounded
    if (candidates_ > kMaxTriangles) fail("the scene has more than " + str(kMaxTriangles) + " triangles");

    for (std::size_t t = 0; t < triangles; ++t) {
      std::uint32_t v[3] = {corner(t, 0), corner(t, 1), corner(t, 2)};
      if (xf.flip) std::swap(v[1], v[2]);  // negative determinant: restore counter-clockwise fronts
      Triangle tri;
      tri.material = material;
      bool finite = true;
      for (int k = 0; k < 3; ++k) {
        const std::size_t i = v[k];
        const glm::dvec4 p = xf.world * glm::dvec4(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2], 1.0);
        tri.p[k] = glm::vec3(p);
        finite = finite && std::isfinite(tri.p[k].x) && std::isfinite(tri.p[k].y) && std::isfinite(tri.p[k].z);
        tri.uv[k] = uvs.empty() ? glm::vec2(0.0f) : glm::vec2(float(uvs[2 * i]), float(uvs[2 * i + 1]));
      }
      if (!finite) fail(at + ": a vertex position overflows a float after the node transform");
      const glm::vec3 cross = glm::cross(tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]);
      const float area2 = glm::length(cross);
      if (!(area2 > 0.0f) || !std::isfinite(area2)) {
        ++degenerate_;
        continue;
      }
      const glm::vec3 flat = cross / area2;
      bool smooth = !normals.empty();
      for (int k = 0; k < 3 && smooth; ++k) {
        const std::size_t i = v[k];
        const glm::dvec3 nw = xf.normal * glm::dvec3(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
        const double len = glm::length(nw);
        if (!(len > 1e-20) || !std::isfinite(len)) {
          smooth = false;
          ++badNormals_;
        } else {
          tri.n[k] = glm::vec3(nw / len);
        }
      }
      if (!smooth) tri.n[0] = tri.n[1] = tri.n[2] = flat;
      scene_.triangles.push_back(tri);
    }
  }

  const std::string& path_;
  const tinygltf::Model& model_;
  const ImageLog& images_;
  Scene& scene_;
  std::map<int, int> textureMap_;  // glTF texture index -> Scene::textures index (-1: ignored)
  int defaultMaterial_ = -1;
  std::size_t degenerate_ = 0;   // zero-area triangles dropped
  std::size_t badNormals_ = 0;   // triangles whose vertex normals were unusable
  std::size_t candidates_ = 0;   // triangles assembled so far, degenerate ones included
  std::uint64_t decoded_ = 0;    // accessor elements decoded so far
  bool warnedSkin_ = false;
  bool warnedTargets_ = false;
  std::string firstSkip_;  // first reason a primitive was skipped, quoted when nothing is left
};

}  // namespace

Scene loadScene(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext != ".gltf" && ext != ".glb")
    throw Error(path + ": unsupported file extension '" + oneLine(ext) + "' (supported: .gltf, .glb)");
  const std::vector<unsigned char> bytes = readFileBytes(path);
  if (bytes.empty()) throw Error(path + ": the file is empty");

  // glTF-Binary is recognised by its magic, whatever the extension says.
  const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  Scene scene;
  scene.path = path;
  if (binary != (ext == ".glb")) {
    if (ext == ".glb") glbJson(path, bytes);  // reports the bad header
    scene.warnings.push_back(path + ": binary glTF content in a .gltf file; loaded as GLB");
  }
  const std::string jsonText =
      binary ? glbJson(path, bytes) : std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size());

  if (jsonDepth(jsonText.data(), jsonText.size(), kMaxJsonDepth) > kMaxJsonDepth)
    throw Error(path + ": JSON is nested more than " + std::to_string(kMaxJsonDepth) + " levels deep");
  Json document;
  try {
    document = Json::parse(jsonText);
  } catch (const Json::exception& e) {
    std::string what = e.what();
    const auto bracket = what.find("] ");
    if (what.rfind("[json.exception.", 0) == 0 && bracket != std::string::npos) what = what.substr(bracket + 2);
    throw Error(path + ": invalid JSON: " + oneLine(what));
  }
  const std::string baseDir = std::filesystem::path(path).parent_path().string();
  try {
    JsonChecker(path, baseDir, binary).check(document);
  } catch (const Json::exception& e) {  // a check that assumed a JSON type it had not verified
    throw Error(path + ": unexpected JSON structure: " + oneLine(e.what()));
  }

  tinygltf::Model model;
  ImageLog imageLog;
  try {
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(decodeImage, &imageLog);
    loader.SetFsCallbacks({fsFileExists, fsExpandFilePath, fsReadWholeFile, fsWriteWholeFile, nullptr});
    std::string err, warn;
    const bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                                         static_cast<unsigned int>(bytes.size()), baseDir)
                           : loader.LoadASCIIFromString(&model, &err, &warn, jsonText.data(),
                                                        static_cast<unsigned int>(jsonText.size()), baseDir);
    if (!ok) throw Error(path + ": " + (err.empty() ? std::string("tinygltf could not load the file") : oneLine(err)));
    if (!warn.empty()) scene.warnings.push_back(path + ": " + oneLine(warn));
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(path + ": " + oneLine(e.what()));
  }

  try {
    SceneBuilder(path, model, imageLog, scene).build();
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
