// gltf_json_check.cpp — the JSON pass before tinygltf sees a glTF document: nesting depth, parsing,
// and a structure check of every property's type, index and byte range, naming the bad property.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iterator>
#include <string>
#include <system_error>

#include "util/error.h"
#include "util/math_constants.h"
#include "scene/gltf_internal.h"

namespace caustica::gltf {
namespace {

using Json = nlohmann::json;

const char* const kSupportedExtensions[] = {
    "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume",
    "KHR_materials_dispersion", "KHR_materials_emissive_strength", "KHR_materials_specular",
    "KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_unlit", "KHR_texture_transform",
    "KHR_lights_punctual", "EXT_mesh_gpu_instancing", "EXT_texture_webp", "KHR_mesh_quantization",
    "EXT_meshopt_compression", "KHR_draco_mesh_compression"};

std::string supportedExtensionList() {
  std::string out;
  for (const char* s : kSupportedExtensions) out += (out.empty() ? "" : ", ") + std::string(s);
  return out;
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

// ---- JSON structure check (before tinygltf sees the document) ------------------------------------
// tinygltf silently ignores optional properties of the wrong type and does not bound-check some
// byte ranges; this pass rejects such files with a message naming the property.
class JsonChecker {
 public:
  // access: where external files may come from; binary: the document is a GLB's JSON chunk.
  JsonChecker(const std::string& path, const FileAccess& access, bool binary, const LoadOptions& options)
      : path_(path), access_(access), binary_(binary), options_(options) {}

  JsonFacts check(const Json& root) {
    if (!root.is_object()) fail("the top-level JSON value is " + describe(root) + ", not an object");
    checkAsset(root);
    checkExtensionLists(root);
    // Shapes of the top-level arrays first: the checks below look across them.
    for (const char* key : {"scenes", "nodes", "meshes", "accessors", "bufferViews", "buffers", "images", "samplers",
                            "textures", "materials", "cameras", "skins", "animations"})
      forEach(root, key, [](const Json&, const std::string&) {});
    index(root, "", "scene");
    forEach(root, "scenes", [&](const Json& o, const std::string& at) { indexArray(o, at, "nodes"); });
    checkPunctualLights(root);  // before the nodes, which refer to its lights
    forEach(root, "nodes", [&](const Json& o, const std::string& at) { checkNode(root, o, at); });
    forEach(root, "meshes", [&](const Json& o, const std::string& at) { checkMesh(root, o, at); });
    forEach(root, "accessors", [&](const Json& o, const std::string& at) { checkAccessor(root, o, at); });
    // All declared byteLengths are added up before any buffer's file is looked at.
    std::uint64_t bufferBytes = 0;
    forEach(root, "buffers", [&](const Json& o, const std::string& at) { checkBufferLength(o, at, bufferBytes); });
    std::size_t bufferIndex = 0;
    forEach(root, "buffers", [&](const Json& o, const std::string& at) { checkBuffer(o, at, bufferIndex++); });
    forEach(root, "bufferViews", [&](const Json& o, const std::string& at) { checkBufferView(root, o, at); });
    forEach(root, "images", [&](const Json& o, const std::string& at) { checkImage(root, o, at); });
    std::size_t meshIndex = 0;
    forEach(root, "meshes", [&](const Json& o, const std::string& at) { checkDraco(root, o, at, meshIndex++); });
    forEach(root, "samplers", [&](const Json& o, const std::string& at) {
      for (const char* key : {"magFilter", "minFilter", "wrapS", "wrapT"}) index(o, at, key);
    });
    forEach(root, "textures", [&](const Json& o, const std::string& at) {
      index(o, at, "sampler");
      index(o, at, "source");
      if (const Json* ext = object(o, at, "extensions"))
        if (const Json* webp = object(*ext, join(at, "extensions"), "EXT_texture_webp"))
          reference(root, *webp, join(at, "extensions.EXT_texture_webp"), "source", "images", true);
    });
    forEach(root, "materials", [&](const Json& o, const std::string& at) { checkMaterial(o, at); });
    forEach(root, "cameras", [&](const Json& o, const std::string& at) { checkCamera(o, at); });
    return facts_;
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
    if (v.is_number_integer() && !v.is_number_unsigned() && v.get<std::int64_t>() < 0)
      fail(where + " is " + std::to_string(v.get<std::int64_t>()) + "; it must be a non-negative integer");
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

  // KHR_lights_punctual: the lights array (types, colours, intensities, cone angles; the spec's
  // ranges), so a bad light fails with the property it is about instead of rendering wrong.
  void checkPunctualLights(const Json& root) const {
    const Json* ext = find(root, "extensions");
    if (!ext || !ext->is_object()) return;
    const Json* lp = object(*ext, "extensions", "KHR_lights_punctual");
    if (!lp) return;
    const std::string lat = "extensions.KHR_lights_punctual";
    const Json* lights = array(*lp, lat, "lights");
    if (!lights) return;
    for (std::size_t i = 0; i < lights->size(); ++i) {
      const Json& l = (*lights)[i];
      const std::string at = join(lat, "lights") + "[" + str(i) + "]";
      expect(l.is_object(), l, at, "an object");
      string(l, at, "name");
      const std::string type = string(l, at, "type", true)->get<std::string>();
      if (type != "point" && type != "spot" && type != "directional")
        fail(join(at, "type") + " is \"" + oneLine(type) + "\"; it must be point, spot or directional");
      numbers(l, at, "color", 3);
      if (const Json* c = find(l, "color"))
        for (std::size_t k = 0; k < 3; ++k)
          if ((*c)[k].get<double>() < 0.0)
            fail(join(at, "color") + "[" + str(k) + "] is " + num((*c)[k].get<double>()) + "; colours must not be negative");
      if (const Json* v = number(l, at, "intensity"))
        if (v->get<double>() < 0.0)
          fail(join(at, "intensity") + " is " + num(v->get<double>()) + "; it must not be negative");
      if (const Json* v = number(l, at, "range"))
        if (!(v->get<double>() > 0.0)) fail(join(at, "range") + " is " + num(v->get<double>()) + "; it must be positive");
      const Json* spot = object(l, at, "spot", type == "spot");
      if (spot && type == "spot") {
        const std::string sat = join(at, "spot");
        const Json* in = number(*spot, sat, "innerConeAngle");
        const Json* out = number(*spot, sat, "outerConeAngle");
        const double inner = in ? in->get<double>() : 0.0, outer = out ? out->get<double>() : kPiD / 4.0;
        if (!(inner >= 0.0 && inner < outer && outer <= kPiD / 2.0))
          fail(sat + " has innerConeAngle " + num(inner) + " and outerConeAngle " + num(outer) +
               " (radians); they must satisfy 0 <= inner < outer <= pi/2");
      }
    }
  }

  void checkNode(const Json& root, const Json& o, const std::string& at) const {
    if (const Json* ext = object(o, at, "extensions"))
      if (const Json* lp = object(*ext, join(at, "extensions"), "KHR_lights_punctual")) {
        const std::string lat = join(at, "extensions.KHR_lights_punctual");
        const Json* light = index(*lp, lat, "light", true);
        const Json* rootExt = find(root, "extensions");
        const Json* lights = rootExt && rootExt->is_object() && rootExt->contains("KHR_lights_punctual")
                                 ? find((*rootExt)["KHR_lights_punctual"], "lights")
                                 : nullptr;
        const std::size_t count = lights ? lights->size() : 0;
        if (light->get<std::uint64_t>() >= count)
          fail(join(lat, "light") + " is " + str(light->get<std::uint64_t>()) + ", but the file has " + str(count) +
               " lights (extensions.KHR_lights_punctual.lights)");
      }
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
      const Json* pext = object(p, pat, "extensions");
      const bool draco = pext && pext->contains("KHR_draco_mesh_compression");
      if (const Json* indices = reference(root, p, pat, "indices", "accessors")) {
        const Json& accessor = (*find(root, "accessors"))[indices->get<std::size_t>()];
        if (accessor.is_object() && !accessor.contains("bufferView") && !draco)
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

  void checkBufferLength(const Json& o, const std::string& at, std::uint64_t& total) const {
    const auto length = index(o, at, "byteLength", true, kMaxByteCount)->get<std::uint64_t>();
    total = length > ~std::uint64_t(0) - total ? ~std::uint64_t(0) : total + length;  // saturating
    if (total > options_.maxBufferBytes)
      fail(join(at, "byteLength") + " is " + str(length) + ", which brings the buffers to " + mib(total) +
           ", more than the limit of " + mib(options_.maxBufferBytes) + " (use --max-buffer-mib to raise it)");
  }

  // A reference to an external file: refused, naming it, when it leads outside the scene's folder.
  void checkFileReference(const std::string& where, const std::string& uri) const {
    if (!referenceAllowed(access_, uriDecode(uri)))
      fail(where + " '" + oneLine(uri) + "' leads outside the scene's folder (use --allow-outside-paths to permit)");
  }

  // Buffer sources are checked here so that the messages name the buffer (tinygltf's do not).
  void checkBuffer(const Json& o, const std::string& at, std::size_t index) {
    const auto length = o["byteLength"].get<std::uint64_t>();
    // EXT_meshopt_compression: a fallback buffer holds what its compressed views decode to; a loader
    // that decodes them needs none of its data (withoutFallbackBuffers), so its uri is not followed.
    if (const Json* ext = object(o, at, "extensions"))
      if (const Json* meshopt = object(*ext, join(at, "extensions"), "EXT_meshopt_compression")) {
        boolean(*meshopt, join(at, "extensions.EXT_meshopt_compression"), "fallback");
        if (meshopt->value("fallback", false)) {
          facts_.fallbackBuffers.push_back(index);
          string(o, at, "uri");
          return;
        }
      }
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
    checkFileReference(join(at, "uri"), uri);
    const std::filesystem::path file = std::filesystem::path(access_.baseDir) / uriDecode(uri);
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
    if (const Json* ext = object(o, at, "extensions"))
      if (const Json* m = object(*ext, join(at, "extensions"), "EXT_meshopt_compression")) {
        // The compressed source: its buffer range (the modes, strides and filters: decodeMeshoptViews).
        const std::string mat = join(at, "extensions.EXT_meshopt_compression");
        const auto source = reference(root, *m, mat, "buffer", "buffers", true)->get<std::uint64_t>();
        const Json* so = index(*m, mat, "byteOffset", false, kMaxByteCount);
        const auto sourceOffset = so ? so->get<std::uint64_t>() : 0;
        const auto sourceLength = index(*m, mat, "byteLength", true, kMaxByteCount)->get<std::uint64_t>();
        index(*m, mat, "byteStride", true, 256);
        index(*m, mat, "count", true, kMaxByteCount);
        string(*m, mat, "mode", true);
        string(*m, mat, "filter");
        const auto sourceBufferLength = (*buffers)[source]["byteLength"].get<std::uint64_t>();
        if (!rangeFits(sourceOffset, 0, 1, sourceLength, sourceBufferLength))
          fail(mat + " (byteOffset " + str(sourceOffset) + ", byteLength " + str(sourceLength) + ") overruns buffers[" +
               str(source) + "] (" + str(sourceBufferLength) + " bytes)");
      }
  }

  // KHR_draco_mesh_compression on a primitive: its bufferView and the attributes' Draco ids.
  void checkDraco(const Json& root, const Json& o, const std::string& at, std::size_t mesh) {
    const Json& prims = o["primitives"];
    for (std::size_t i = 0; i < prims.size(); ++i) {
      const std::string pat = join(at, "primitives") + "[" + str(i) + "]";
      const Json* ext = find(prims[i], "extensions");
      if (!ext) continue;
      const Json* d = object(*ext, join(pat, "extensions"), "KHR_draco_mesh_compression");
      if (!d) continue;
      const std::string dat = join(pat, "extensions.KHR_draco_mesh_compression");
      reference(root, *d, dat, "bufferView", "bufferViews", true);
      const Json* attributes = object(*d, dat, "attributes", true);
      for (const auto& item : attributes->items())
        checkIndexValue(item.value(), join(dat, "attributes") + "." + oneLine(item.key()), kMaxIndex);
      if (const Json* indices = find(prims[i], "indices"))
        facts_.dracoIndices.push_back({mesh, i, indices->get<int>()});
    }
  }

  void checkImage(const Json& root, const Json& o, const std::string& at) const {
    if (!o.contains("uri") && !o.contains("bufferView")) fail(at + " has neither a uri nor a bufferView");
    if (const Json* uri = string(o, at, "uri")) {
      const std::string text = uri->get<std::string>();
      if (text.rfind("data:", 0) != 0) checkFileReference(join(at, "uri"), text);
    }
    string(o, at, "mimeType");
    if (const Json* view = index(o, at, "bufferView")) {
      const Json* views = find(root, "bufferViews");
      const std::size_t viewCount = views ? views->size() : 0;
      if (view->get<std::uint64_t>() >= viewCount)
        fail(join(at, "bufferView") + " is " + str(view->get<std::uint64_t>()) + ", but the file has " +
             str(viewCount) + " buffer views");
      // tinygltf decodes images from their buffer's data, which a fallback buffer does not hold.
      const Json& v = (*views)[view->get<std::size_t>()];
      const std::size_t buffer = v["buffer"].get<std::size_t>();
      if (std::find(facts_.fallbackBuffers.begin(), facts_.fallbackBuffers.end(), buffer) != facts_.fallbackBuffers.end())
        fail(at + " lies in buffers[" + str(buffer) +
             "], an EXT_meshopt_compression fallback buffer, which holds no data");
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
    if (const Json* ext = object(*info, iat, "extensions")) {
      const std::string eat = join(iat, "extensions");
      if (const Json* t = object(*ext, eat, "KHR_texture_transform")) {
        const std::string tat = join(eat, "KHR_texture_transform");
        numbers(*t, tat, "offset", 2);
        number(*t, tat, "rotation");
        numbers(*t, tat, "scale", 2);
        index(*t, tat, "texCoord");
      }
    }
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
    if (const Json* e = object(*ext, eat, "KHR_materials_specular")) {
      const std::string sat = join(eat, "KHR_materials_specular");
      number(*e, sat, "specularFactor");
      numbers(*e, sat, "specularColorFactor", 3);
      textureInfo(*e, sat, "specularTexture");
      textureInfo(*e, sat, "specularColorTexture");
    }
    if (const Json* e = object(*ext, eat, "KHR_materials_clearcoat")) {
      const std::string cat = join(eat, "KHR_materials_clearcoat");
      number(*e, cat, "clearcoatFactor");
      number(*e, cat, "clearcoatRoughnessFactor");
      textureInfo(*e, cat, "clearcoatTexture");
      textureInfo(*e, cat, "clearcoatRoughnessTexture");
      textureInfo(*e, cat, "clearcoatNormalTexture");
    }
    if (const Json* e = object(*ext, eat, "KHR_materials_sheen")) {
      const std::string sat = join(eat, "KHR_materials_sheen");
      numbers(*e, sat, "sheenColorFactor", 3);
      number(*e, sat, "sheenRoughnessFactor");
      textureInfo(*e, sat, "sheenColorTexture");
      textureInfo(*e, sat, "sheenRoughnessTexture");
    }
    object(*ext, eat, "KHR_materials_unlit");
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
    if (const Json* ortho = object(o, at, "orthographic")) {
      const std::string oat = join(at, "orthographic");
      for (const char* key : {"xmag", "ymag"})
        if (number(*ortho, oat, key, true)->get<double>() == 0.0) fail(join(oat, key) + " is 0; it must not be");
      const double znear = number(*ortho, oat, "znear", true)->get<double>();
      const double zfar = number(*ortho, oat, "zfar", true)->get<double>();
      if (!(znear >= 0.0) || !(zfar > znear))
        fail(oat + " has znear " + num(znear) + " and zfar " + num(zfar) + "; they must satisfy 0 <= znear < zfar");
    }
  }

  std::string path_;
  JsonFacts facts_;  // fallback buffers (checkBuffer), Draco primitives' indices (checkDraco)
  const FileAccess& access_;
  bool binary_;
  const LoadOptions& options_;
};

}  // namespace

bool isSupportedExtension(const std::string& name) {
  for (const char* s : kSupportedExtensions)
    if (name == s) return true;
  return false;
}

JsonFacts checkJson(const std::string& path, const std::string& jsonText, const FileAccess& access, bool binary,
                    const LoadOptions& options) {
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
  try {
    return JsonChecker(path, access, binary, options).check(document);
  } catch (const Json::exception& e) {  // a check that assumed a JSON type it had not verified
    throw Error(path + ": unexpected JSON structure: " + oneLine(e.what()));
  }
}

}  // namespace caustica::gltf
