// gltf_compression.cpp — compressed geometry through Debian's libraries: EXT_meshopt_compression
// (meshoptimizer's vertex and index codecs and filters, with the extension's fallback buffers) and
// KHR_draco_mesh_compression (Draco). Corrupt data ends in Error("FILE: ..."), like any bad input.
#include <cstdint>
#include <cstring>
#include <limits>
#include <set>
#include <string>
#include <vector>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wshadow"
#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>
#include <meshoptimizer.h>
#pragma GCC diagnostic pop

#include "scene/gltf_internal.h"

namespace caustica::gltf {
namespace {

// A non-negative integer property of an extension object (already type-checked by checkJson), or fallback.
std::uint64_t count(const tinygltf::Value& v, const char* key, std::uint64_t fallback) {
  if (!v.Has(key)) return fallback;
  const tinygltf::Value& x = v.Get(key);
  const double d = x.IsInt() ? double(x.GetNumberAsInt()) : x.GetNumberAsDouble();
  return d >= 0.0 && d < 9.0e15 ? std::uint64_t(d) : std::numeric_limits<std::uint64_t>::max();
}

std::string text(const tinygltf::Value& v, const char* key) {
  return v.Has(key) && v.Get(key).IsString() ? v.Get(key).Get<std::string>() : std::string();
}

}  // namespace

std::string tinygltfJson(const std::string& jsonText, const JsonFacts& facts) {
  nlohmann::json doc = nlohmann::json::parse(jsonText);  // checkJson parsed and checked it already
  for (std::size_t b : facts.fallbackBuffers) {
    nlohmann::json& buffer = doc["buffers"][b];
    buffer["byteLength"] = 1;
    buffer["uri"] = "data:application/octet-stream;base64,AA==";
  }
  for (const JsonFacts::DracoIndices& d : facts.dracoIndices)
    doc["meshes"][d.mesh]["primitives"][d.primitive].erase("indices");
  return doc.dump();
}

void restoreDracoIndices(tinygltf::Model& model, const JsonFacts& facts) {
  for (const JsonFacts::DracoIndices& d : facts.dracoIndices)
    if (d.mesh < model.meshes.size() && d.primitive < model.meshes[d.mesh].primitives.size())
      model.meshes[d.mesh].primitives[d.primitive].indices = d.accessor;
}

void decodeMeshoptViews(const std::string& path, tinygltf::Model& model, const std::vector<std::size_t>& fallback,
                        const LoadOptions& options) {
  const auto fail = [&](const std::string& what) { throw Error(path + ": " + what); };
  const std::set<std::size_t> fallbackSet(fallback.begin(), fallback.end());
  const std::size_t sourceBuffers = model.buffers.size();
  std::uint64_t decodedBytes = 0;
  for (std::size_t v = 0; v < model.bufferViews.size(); ++v) {
    tinygltf::BufferView& view = model.bufferViews[v];
    const std::string at = "bufferViews[" + str(v) + "]";
    const tinygltf::Value* ext = extension(view.extensions, "EXT_meshopt_compression");
    if (!ext) {
      if (view.buffer >= 0 && fallbackSet.count(std::size_t(view.buffer)))
        fail(at + " lies in buffers[" + str(std::uint64_t(view.buffer)) +
             "], an EXT_meshopt_compression fallback buffer, which holds no data, and is not compressed itself");
      continue;
    }
    const std::string eat = at + ".extensions.EXT_meshopt_compression";
    const std::uint64_t buffer = count(*ext, "buffer", ~0ull), offset = count(*ext, "byteOffset", 0),
                        length = count(*ext, "byteLength", ~0ull), stride = count(*ext, "byteStride", ~0ull),
                        elements = count(*ext, "count", ~0ull);
    const std::string mode = text(*ext, "mode"), filter = ext->Has("filter") ? text(*ext, "filter") : "NONE";
    if (buffer >= sourceBuffers) fail(eat + ".buffer is out of range");
    if (fallbackSet.count(buffer)) fail(eat + ".buffer is a fallback buffer itself, which holds no data");
    const std::vector<unsigned char>& source = model.buffers[buffer].data;
    if (!rangeFits(offset, 0, 1, length, source.size()))
      fail(eat + " (byteOffset " + str(offset) + ", byteLength " + str(length) + ") overruns buffers[" + str(buffer) +
           "] (" + str(source.size()) + " bytes)");
    // The parameters meshoptimizer's decoders assert on, checked here so hostile values fail cleanly.
    if (mode == "ATTRIBUTES") {
      if (stride == 0 || stride % 4 != 0 || stride > 256)
        fail(eat + ".byteStride is " + str(stride) + "; ATTRIBUTES need a multiple of 4 up to 256");
      if ((filter == "OCTAHEDRAL" && stride != 4 && stride != 8) || (filter == "QUATERNION" && stride != 8))
        fail(eat + ".byteStride " + str(stride) + " does not suit filter " + oneLine(filter) +
             " (OCTAHEDRAL: 4 or 8, QUATERNION: 8)");
      if (filter != "NONE" && filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")
        fail(eat + ".filter is \"" + oneLine(filter) + "\"; it must be NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
    } else if (mode == "TRIANGLES" || mode == "INDICES") {
      if (stride != 2 && stride != 4) fail(eat + ".byteStride is " + str(stride) + "; " + mode + " need 2 or 4");
      if (mode == "TRIANGLES" && elements % 3 != 0)
        fail(eat + ".count is " + str(elements) + "; TRIANGLES need a multiple of 3");
      if (filter != "NONE") fail(eat + ".filter " + oneLine(filter) + " is only allowed with mode ATTRIBUTES");
    } else {
      fail(eat + ".mode is \"" + oneLine(mode) + "\"; it must be ATTRIBUTES, TRIANGLES or INDICES");
    }
    if (elements > view.byteLength / stride)
      fail(eat + ": count " + str(elements) + " x byteStride " + str(stride) + " is more than the view's byteLength " +
           str(view.byteLength));
    decodedBytes += view.byteLength;
    if (decodedBytes > options.maxBufferBytes)
      fail(at + ": the decoded EXT_meshopt_compression views come to " + mib(decodedBytes) + ", more than the limit of " +
           mib(options.maxBufferBytes) + " (use --max-buffer-mib to raise it)");
    tinygltf::Buffer decoded;
    decoded.data.assign(view.byteLength, 0);
    const unsigned char* src = source.data() + offset;
    int rc = 0;
    if (mode == "ATTRIBUTES") rc = meshopt_decodeVertexBuffer(decoded.data.data(), elements, stride, src, length);
    else if (mode == "TRIANGLES") rc = meshopt_decodeIndexBuffer(decoded.data.data(), elements, stride, src, length);
    else rc = meshopt_decodeIndexSequence(decoded.data.data(), elements, stride, src, length);
    if (rc != 0)
      fail(eat + ": the compressed data is corrupt (meshoptimizer's " + mode + " decoder returned " +
           std::to_string(rc) + ")");
    if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(decoded.data.data(), elements, stride);
    else if (filter == "QUATERNION") meshopt_decodeFilterQuat(decoded.data.data(), elements, stride);
    else if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(decoded.data.data(), elements, stride);
    model.buffers.push_back(std::move(decoded));
    view.buffer = int(model.buffers.size() - 1);
    view.byteOffset = 0;
  }
}

SceneBuilder::DracoPrimitive SceneBuilder::decodeDraco(const tinygltf::Primitive& prim, const std::string& at) {
  const tinygltf::Value* ext = extension(prim.extensions, "KHR_draco_mesh_compression");
  const std::string eat = at + ".extensions.KHR_draco_mesh_compression";
  if (!ext || !ext->Has("bufferView") || !ext->Get("attributes").IsObject())
    fail(eat + " needs a bufferView and an attributes object");
  const ViewBytes view = bufferView(ext->Get("bufferView").GetNumberAsInt(), eat);
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(view.data), std::size_t(view.length));
  const auto geometry = draco::Decoder::GetEncodedGeometryType(&buffer);
  if (!geometry.ok()) fail(eat + ": not Draco data (" + oneLine(geometry.status().error_msg_string()) + ")");
  if (geometry.value() != draco::TRIANGULAR_MESH) fail(eat + ": the Draco data is a point cloud, not a triangle mesh");
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok())
    fail(eat + ": the Draco data cannot be decoded (" + oneLine(decoded.status().error_msg_string()) + ")");
  const draco::Mesh& mesh = *decoded.value();
  const std::uint64_t points = mesh.num_points(), faces = mesh.num_faces();

  DracoPrimitive out;
  out.indexed = prim.indices >= 0;
  if (out.indexed && model_.accessors[std::size_t(prim.indices)].count != faces * 3)
    fail(eat + ": the Draco mesh has " + str(faces) + " triangles, but the indices accessor has " +
         str(model_.accessors[std::size_t(prim.indices)].count) + " indices");
  countDecoded(faces * 3);
  out.indices.reserve(std::size_t(faces) * 3);
  for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t i = mesh.face(f)[k].value();
      if (i >= points) fail(eat + ": a Draco face refers to point " + str(i) + " of " + str(points));
      out.indices.push_back(double(i));
    }

  const tinygltf::Value& attributes = ext->Get("attributes");
  for (const std::string& name : attributes.Keys()) {
    const std::string aat = eat + ".attributes." + oneLine(name);
    const auto accessorIt = prim.attributes.find(name);
    if (accessorIt == prim.attributes.end()) fail(aat + " has no matching attribute in the primitive's attributes");
    if (accessorIt->second < 0 || std::size_t(accessorIt->second) >= model_.accessors.size())
      fail(at + " " + oneLine(name) + " refers to accessor " + std::to_string(accessorIt->second) + ", but the file has " +
           str(model_.accessors.size()) + " accessors");
    const tinygltf::Accessor& acc = model_.accessors[std::size_t(accessorIt->second)];
    const tinygltf::Value& id = attributes.Get(name);
    const draco::PointAttribute* attribute =
        id.IsInt() && id.GetNumberAsInt() >= 0 ? mesh.GetAttributeByUniqueId(std::uint32_t(id.GetNumberAsInt())) : nullptr;
    if (!attribute) fail(aat + " names no attribute of the Draco mesh");
    const int components = tinygltf::GetNumComponentsInType(std::uint32_t(acc.type));
    if (components < 1 || components > 4 || attribute->num_components() != components)
      fail(aat + ": the Draco attribute has " + str(attribute->num_components()) + " components, the accessor " +
           str(std::uint64_t(std::max(components, 0))));
    if (acc.count != points)
      fail(aat + ": the Draco mesh has " + str(points) + " points, but the accessor's count is " + str(acc.count));
    countDecoded(points);
    // Draco returns integers as stored unless its attribute is marked normalized; the accessor's
    // normalized flag then applies glTF's rules, as for uncompressed data.
    const bool integral = attribute->data_type() != draco::DT_FLOAT32 && attribute->data_type() != draco::DT_FLOAT64;
    const bool normalize = acc.normalized && integral && !attribute->normalized();
    std::vector<double>& values = out.attributes[name];
    values.resize(std::size_t(points) * std::size_t(components));
    double element[4];
    for (draco::PointIndex p(0); p < mesh.num_points(); ++p) {
      if (!attribute->ConvertValue<double>(attribute->mapped_index(p), std::int8_t(components), element))
        fail(aat + ": the Draco attribute's value of point " + str(p.value()) + " cannot be read");
      for (int c = 0; c < components; ++c) {
        double x = normalize ? normalizedValue(element[c], acc.componentType) : element[c];
        if (acc.normalized && attribute->normalized()) x = std::max(x, -1.0);
        values[std::size_t(p.value()) * std::size_t(components) + std::size_t(c)] = x;
      }
    }
  }
  return out;
}

}  // namespace caustica::gltf
