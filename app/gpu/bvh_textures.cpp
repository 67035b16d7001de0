// bvh_textures.cpp — buffer-texture views of the BVH nodes and triangle positions for the traversal.
#include "gpu/bvh_textures.h"

#include <cstdint>
#include <limits>

#include "shared/gpu_layout.h"
#include "util/error.h"
#include "util/memory_stats.h"

namespace caustica {

void checkBufferTextureTexels(std::size_t texels, const std::string& what, const std::string& arrayNeeds) {
  GLint maxTexels = 0;
  glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &maxTexels);
  if (texels > static_cast<std::size_t>(maxTexels))
    throw Error(what + ": " + arrayNeeds + " " + std::to_string(texels) + " texels in one buffer texture; this GL offers " +
                std::to_string(maxTexels) + " (GL_MAX_TEXTURE_BUFFER_SIZE)");
}

BvhTextures::BvhTextures(const GlBuffer& nodes, std::size_t nodeCount, const GlBuffer& triGeom, std::size_t triCount,
                         const std::string& what, const std::vector<gpu::BvhWideNode>& wide) {
  checkBufferTextureTexels(wide.size() * (sizeof(gpu::BvhWideNode) / 16), what);
  *this = BvhTextures(nodes, nodeCount, triGeom, triCount, what, wide.empty() ? GlBuffer() : GlBuffer::fromVector(wide),
                      wide.size());
}

BvhTextures::BvhTextures(const GlBuffer& nodes, std::size_t nodeCount, const GlBuffer& triGeom, std::size_t triCount,
                         const std::string& what, GlBuffer wideBuffer, std::size_t wideCount) {
  const std::size_t nodeTexels = nodeCount * (sizeof(gpu::BvhNode) / 16);
  const std::size_t triTexels = triCount * (sizeof(gpu::TriGeom) / 16);
  const std::size_t wideTexels = wideCount * (sizeof(gpu::BvhWideNode) / 16);
  for (std::size_t texels : {nodeTexels, triTexels, wideTexels}) checkBufferTextureTexels(texels, what);
  nodes_ = GlBufferTexture::create(nodes, GL_RGBA32UI);
  triGeom_ = GlBufferTexture::create(triGeom, GL_RGBA32UI);
  if (wideCount == 0) {
    gpu::BvhWideNode empty{};  // every slot empty, boxes at +inf: the traversal enters none
    for (int k = 0; k < 4; ++k) {
      empty.minX[k] = empty.maxX[k] = empty.minY[k] = empty.maxY[k] = empty.minZ[k] = empty.maxZ[k] =
          std::numeric_limits<float>::infinity();
      empty.child[k] = gpu::kBvhEmptyRef;
    }
    wideBuffer_ = GlBuffer::create(sizeof(empty), &empty);
  } else {
    wideBuffer_ = std::move(wideBuffer);
  }
  wide_ = GlBufferTexture::create(wideBuffer_, GL_RGBA32UI);
}

void BvhTextures::bind() const {
  nodes_.bind(CAUSTICA_TEXUNIT_BVH_NODES);
  triGeom_.bind(CAUSTICA_TEXUNIT_TRI_GEOM);
  wide_.bind(CAUSTICA_TEXUNIT_BVH_WIDE);
}

}  // namespace caustica
