// scene_buffers.cpp — splitting the big scene arrays over storage blocks, and their upload.
#include "gpu/scene_buffers.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "util/error.h"

namespace caustica {

namespace {
// Bytes as MiB, or KiB below 1 MiB (lowered test limits would read "0.0 MiB").
std::string mib(double bytes) {
  char buf[32];
  if (bytes < 1024.0 * 1024.0) std::snprintf(buf, sizeof buf, "%.1f KiB", bytes / 1024.0);
  else std::snprintf(buf, sizeof buf, "%.1f MiB", bytes / (1024.0 * 1024.0));
  return buf;
}

// Splits `a` into parts of at most `maxBytes`, each a multiple of `granule` elements (whole triangles).
void planArray(SplitArray& a, std::int64_t maxBytes, std::size_t granule, const std::string& scenePath) {
  std::size_t perPart = static_cast<std::size_t>(maxBytes) / a.elementBytes;
  perPart -= perPart % granule;
  if (perPart == 0) throw Error(scenePath + ": the GPU's storage blocks are too small for one " + a.name + " record");
  a.perPart = perPart;
  a.parts = static_cast<int>(std::max<std::size_t>(1, (a.count + perPart - 1) / perPart));
  if (a.parts > CAUSTICA_MAX_SPLIT_PARTS)
    throw Error(scenePath + ": " + a.name + " need " + mib(double(a.count) * double(a.elementBytes)) + ", more than " +
                std::to_string(CAUSTICA_MAX_SPLIT_PARTS) + " storage blocks of " + mib(double(maxBytes)) +
                " this GPU allows (GL_MAX_SHADER_STORAGE_BLOCK_SIZE)");
}

// Copies elements [first, first + count) of `v` into a new buffer.
template <class T>
GlBuffer part(const std::vector<T>& v, std::size_t first, std::size_t count) {
  count = std::min(count, v.size() - std::min(first, v.size()));
  return GlBuffer::create(count * sizeof(T), count ? v.data() + first : nullptr);
}

template <class T>
void uploadArray(std::vector<T>& v, const SplitArray& a, int binding, std::vector<GlBuffer>& buffers) {
  for (int k = 0; k < a.parts; ++k) {
    const int b = k == 0 ? binding : a.bindings[static_cast<std::size_t>(k - 1)];
    if (buffers.size() <= static_cast<std::size_t>(b)) buffers.resize(static_cast<std::size_t>(b) + 1);
    buffers[static_cast<std::size_t>(b)] = part(v, static_cast<std::size_t>(k) * a.perPart, a.perPart);
  }
  std::vector<T>().swap(v);  // the GPU holds it now
}
}  // namespace

std::vector<std::string> SceneBufferLayout::defines() const {
  std::vector<std::string> d = shade.defines();
  for (const SplitArray* a : {&nodes, &triGeom, &triShade}) {
    if (a->parts < 2) continue;
    const std::string key = a == &nodes ? "CAUSTICA_NODES" : a == &triGeom ? "CAUSTICA_TRIGEOM" : "CAUSTICA_TRISHADE";
    d.push_back(key + "_PARTS=" + std::to_string(a->parts));
    d.push_back(key + "_PART=" + std::to_string(a->perPart) + "u");
    for (std::size_t k = 0; k < a->bindings.size(); ++k)
      d.push_back(key + "_BINDING" + std::to_string(k + 1) + "=" + std::to_string(a->bindings[k]));
  }
  return d;
}

std::string SceneBufferLayout::describe() const {
  std::string s;
  for (const SplitArray* a : {&nodes, &triGeom, &triShade})
    if (a->parts > 1) s += (s.empty() ? "" : ", ") + std::string(a->name) + " in " + std::to_string(a->parts) + " blocks";
  return s.empty() ? "one block per array" : s;
}

SceneBufferLayout planSceneBuffers(const GpuScene& g, const GlLimits& limits, const std::string& scenePath) {
  SceneBufferLayout l;
  l.nodes = {"BVH nodes", sizeof(gpu::BvhNode), g.nodes.size(), 0, 1, {}};
  l.triGeom = {"triangles", sizeof(gpu::TriGeom), g.triangleCount, 0, 1, {}};
  l.triShade = {"triangle shading data", 4, g.triangleCount * g.triShadeStride, 0, 1, {}};
  // Nodes and TriGeom are read through buffer textures (bvh_textures.*): one buffer each, bounded by
  // GL_MAX_TEXTURE_BUFFER_SIZE, not by the storage-block size.
  l.shade = g.triShadeLayout;
  for (SplitArray* a : {&l.nodes, &l.triGeom}) a->perPart = std::max<std::size_t>(a->count, 1);
  planArray(l.triShade, limits.maxStorageBlockSize, g.triShadeStride, scenePath);
  // Materials, the light tree and the texture block are read through buffer textures too
  // (shading_textures.*, which refuses one over GL_MAX_TEXTURE_BUFFER_SIZE texels): no storage-block bound.
  const int blocks = CAUSTICA_SSBO_COUNT + l.extraBlocks();
  const int usable = std::min(limits.maxComputeStorageBlocks, limits.maxStorageBufferBindings);
  if (blocks > usable)
    throw Error(scenePath + ": the scene needs " + std::to_string(blocks) + " storage blocks (" + l.describe() +
                ") but this GPU allows " + std::to_string(usable) + " per compute shader");
  int next = CAUSTICA_BINDING_SPLIT_FIRST;
  for (SplitArray* a : {&l.nodes, &l.triGeom, &l.triShade})
    for (int k = 1; k < a->parts; ++k) a->bindings.push_back(next++);
  return l;
}

void uploadSceneBuffers(GpuScene& g, const Scene& scene, const Bvh& bvh, const SceneBufferLayout& l,
                        std::vector<GlBuffer>& buffers) {
  if (buffers.size() < CAUSTICA_SSBO_COUNT) buffers.resize(CAUSTICA_SSBO_COUNT);
  uploadArray(g.nodes, l.nodes, CAUSTICA_BINDING_NODES, buffers);
  if (g.triGeom.size() == g.triangleCount && g.triShade.size() == g.triangleCount * g.triShadeStride) {
    uploadArray(g.triGeom, l.triGeom, CAUSTICA_BINDING_TRIGEOM, buffers);
    uploadArray(g.triShade, l.triShade, CAUSTICA_BINDING_TRISHADE, buffers);
  } else {  // packed here in slices of 64 Ki triangles, straight into the blocks
    const auto create = [&](const SplitArray& a, int binding) {
      for (int k = 0; k < a.parts; ++k) {
        const std::size_t first = static_cast<std::size_t>(k) * a.perPart;
        const std::size_t n = std::min(a.perPart, a.count - std::min(first, a.count));
        const int b = k == 0 ? binding : a.bindings[static_cast<std::size_t>(k - 1)];
        if (buffers.size() <= static_cast<std::size_t>(b)) buffers.resize(static_cast<std::size_t>(b) + 1);
        buffers[static_cast<std::size_t>(b)] = GlBuffer::create(n * a.elementBytes, nullptr);
      }
    };
    create(l.triGeom, CAUSTICA_BINDING_TRIGEOM);
    create(l.triShade, CAUSTICA_BINDING_TRISHADE);
    // Writes elements [first, first + n) of array `a` (which may straddle a part boundary).
    const auto write = [&](const SplitArray& a, int binding, std::size_t first, std::size_t n, const void* data) {
      const auto* bytes = static_cast<const unsigned char*>(data);
      while (n > 0) {
        const std::size_t k = first / a.perPart, offset = first - k * a.perPart;
        const std::size_t m = std::min(n, a.perPart - offset);
        const int b = k == 0 ? binding : a.bindings[k - 1];
        buffers[static_cast<std::size_t>(b)].update(offset * a.elementBytes, m * a.elementBytes, bytes);
        bytes += m * a.elementBytes;
        first += m;
        n -= m;
      }
    };
    std::vector<gpu::TriGeom> geom;
    std::vector<std::uint32_t> shade;
    const std::size_t slice = 65536;
    for (std::size_t first = 0; first < g.triangleCount; first += slice) {
      const std::size_t n = std::min(slice, g.triangleCount - first);
      packTriangleRange(scene, bvh, g, first, n, geom, shade);
      write(l.triGeom, CAUSTICA_BINDING_TRIGEOM, first, n, geom.data());
      write(l.triShade, CAUSTICA_BINDING_TRISHADE, first * g.triShadeStride, n * g.triShadeStride, shade.data());
    }
  }
  buffers[CAUSTICA_BINDING_MATERIALS] = GlBuffer::fromVector(g.materials);
  buffers[CAUSTICA_BINDING_EMITTERS] = GlBuffer::fromVector(g.lightTree.nodes);
  // TexInfo records, then the texels; offsets on the GPU count from the start of the block.
  const std::size_t head = g.texInfo.size() * gpu::kTexInfoWords;
  std::vector<std::uint32_t> words(head + g.texels.size());
  for (std::size_t i = 0; i < g.texInfo.size(); ++i) {
    gpu::TexInfo t = g.texInfo[i];
    t.offset += static_cast<std::uint32_t>(head);
    static_assert(sizeof t == gpu::kTexInfoWords * 4, "TexInfo words");
    std::memcpy(words.data() + i * gpu::kTexInfoWords, &t, sizeof t);
  }
  std::copy(g.texels.begin(), g.texels.end(), words.begin() + static_cast<std::ptrdiff_t>(head));
  buffers[CAUSTICA_BINDING_TEXELS] = GlBuffer::fromVector(words);
  buffers[CAUSTICA_BINDING_COUNTERS] = GlBuffer::create(sizeof(gpu::Counters), nullptr, GL_DYNAMIC_READ);
}

namespace {
template <class T>
void downloadArray(std::vector<T>& v, const SplitArray& a, int binding, const std::vector<GlBuffer>& buffers) {
  v.resize(a.count);
  for (int k = 0; k < a.parts; ++k) {
    const std::size_t first = static_cast<std::size_t>(k) * a.perPart;
    const std::size_t n = std::min(a.perPart, a.count - std::min(first, a.count));
    const int b = k == 0 ? binding : a.bindings[static_cast<std::size_t>(k - 1)];
    if (n) buffers[static_cast<std::size_t>(b)].read(0, n * sizeof(T), v.data() + first);
  }
}
}  // namespace

void downloadSceneArrays(GpuScene& g, const SceneBufferLayout& l, const std::vector<GlBuffer>& buffers) {
  downloadArray(g.triGeom, l.triGeom, CAUSTICA_BINDING_TRIGEOM, buffers);
  downloadArray(g.triShade, l.triShade, CAUSTICA_BINDING_TRISHADE, buffers);
}

}  // namespace caustica
