// gltf_accessors.cpp — glTF accessors and buffer views: bounds-checked byte ranges, component types
// and their decoding (normalisation, sparse substitution) into doubles; Draco-decoded attributes
// stand in for their accessors' data.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "scene/gltf_internal.h"

namespace caustica::gltf {
namespace {

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

}  // namespace

namespace {
constexpr int kByte = TINYGLTF_COMPONENT_TYPE_BYTE, kUbyte = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
              kShort = TINYGLTF_COMPONENT_TYPE_SHORT, kUshort = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
              kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
}  // namespace

const Formats& attributeFormats(VertexAttribute a, bool quantized) {
  static const Formats kFloatOnly = {{kFloat, false}};
  static const Formats kAny = {{kFloat, false}, {kByte, false},  {kByte, true},   {kUbyte, false}, {kUbyte, true},
                               {kShort, false}, {kShort, true}, {kUshort, false}, {kUshort, true}};
  static const Formats kNormalized = {{kFloat, false}, {kUbyte, true}, {kUshort, true}};
  static const Formats kSignedNormalized = {{kFloat, false}, {kByte, true}, {kShort, true}};
  switch (a) {
    case VertexAttribute::Position: return quantized ? kAny : kFloatOnly;
    case VertexAttribute::Normal:
    case VertexAttribute::Tangent: return quantized ? kSignedNormalized : kFloatOnly;
    case VertexAttribute::Texcoord: return quantized ? kAny : kNormalized;
    case VertexAttribute::Color: return kNormalized;
  }
  return kFloatOnly;
}
const Formats kIndexFormats = {{kUbyte, false}, {kUshort, false}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false}};

std::string formatName(int componentType, bool normalized) {
  const char* name = componentName(componentType);
  return std::string(normalized ? "normalized " : "") +
         (name ? name : "invalid (" + std::to_string(componentType) + ")");
}

namespace {

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
  double v = 0.0;
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: v = static_cast<std::int8_t>(p[0]); break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: v = p[0]; break;
    case TINYGLTF_COMPONENT_TYPE_SHORT: v = static_cast<std::int16_t>(std::uint16_t(p[0] | p[1] << 8)); break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: v = std::uint16_t(p[0] | p[1] << 8); break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return readU32(p);
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      const std::uint32_t bits = readU32(p);
      float f;
      std::memcpy(&f, &bits, 4);
      return f;
    }
    default: return 0.0;
  }
  return normalized ? normalizedValue(v, type) : v;
}

}  // namespace

bool rangeFits(std::uint64_t offset, std::uint64_t stride, std::uint64_t count, std::uint64_t elem,
               std::uint64_t length) {
  if (count == 0) return offset <= length;
  if (offset > length || elem > length - offset) return false;
  const std::uint64_t room = length - offset - elem;  // bytes left for the other count - 1 strides
  return count - 1 == 0 || (stride != 0 && count - 1 <= room / stride);
}

std::uint32_t readU32(const unsigned char* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

double normalizedValue(double raw, int componentType) {
  switch (componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return std::max(raw / 127.0, -1.0);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return raw / 255.0;
    case TINYGLTF_COMPONENT_TYPE_SHORT: return std::max(raw / 32767.0, -1.0);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return raw / 65535.0;
    default: return raw;
  }
}

SceneBuilder::ViewBytes SceneBuilder::bufferView(int index, const std::string& at) const {
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

const tinygltf::Accessor& SceneBuilder::checkedAccessor(int index, int type, const Formats& allowed,
                                                        const std::string& use) const {
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
  return acc;
}

// Reads accessor `index` as doubles (count x components), applying normalisation and sparse
// substitution; `allowed` lists the (componentType, normalized) pairs legal for this use.
void SceneBuilder::countDecoded(std::uint64_t n) {
  decoded_ += n;
  if (decoded_ > kMaxDecoded) fail("the meshes are too large (more than " + str(kMaxDecoded) + " accessor elements)");
}

std::vector<double> SceneBuilder::readAccessor(int index, int type, const Formats& allowed,
                                               const std::string& use) {
  const tinygltf::Accessor& acc = checkedAccessor(index, type, allowed, use);
  const std::string at = "accessors[" + str(std::uint64_t(index)) + "] (" + use + ")";
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
  countDecoded(acc.count);
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

std::vector<double> SceneBuilder::readAttribute(const tinygltf::Primitive& prim, const char* name, int type,
                                                const Formats& allowed, std::size_t vertexCount,
                                                const std::string& at) {
  const auto it = prim.attributes.find(name);
  if (it == prim.attributes.end()) return {};
  std::vector<double> values;
  const auto decoded = draco_ ? draco_->attributes.find(name) : std::map<std::string, std::vector<double>>::const_iterator();
  if (draco_ && decoded != draco_->attributes.end()) {
    checkedAccessor(it->second, type, allowed, at + " " + name);  // the accessor still declares type and format
    values = decoded->second;
  } else {
    values = readAccessor(it->second, type, allowed, at + " " + name);
  }
  const std::size_t components = std::size_t(tinygltf::GetNumComponentsInType(std::uint32_t(type)));
  if (vertexCount != kAnyCount && values.size() != vertexCount * components)
    fail(at + ": " + name + " has " + str(values.size() / components) + " elements but POSITION has " +
         str(vertexCount));
  return values;
}

}  // namespace caustica::gltf
