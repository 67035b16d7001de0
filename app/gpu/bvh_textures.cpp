// bvh_textures.cpp — buffer-texture views of the BVH nodes and triangle positions for the traversal.
#include "gpu/bvh_textures.h"

#include <cstdint>

#include "shared/gpu_layout.h"
#include "util/error.h"

namespace caustica {

BvhTextures::BvhTextures(const GlBuffer& nodes, std::size_t nodeCount, const GlBuffer& triGeom, std::size_t triCount,
                         const std::string& what) {
  GLint maxTexels = 0;
  glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &maxTexels);
  const std::size_t nodeTexels = nodeCount * (sizeof(gpu::BvhNode) / 16);
  const std::size_t triTexels = triCount * (sizeof(gpu::TriGeom) / 16);
  for (std::size_t texels : {nodeTexels, triTexels})
    if (texels > static_cast<std::size_t>(maxTexels))
      throw Error(what + ": the BVH needs " + std::to_string(texels) + " texels in one buffer texture; this GL offers " +
                  std::to_string(maxTexels) + " (GL_MAX_TEXTURE_BUFFER_SIZE)");
  nodes_ = GlBufferTexture::create(nodes, GL_RGBA32UI);
  triGeom_ = GlBufferTexture::create(triGeom, GL_RGBA32UI);
}

void BvhTextures::bind() const {
  nodes_.bind(CAUSTICA_TEXUNIT_BVH_NODES);
  triGeom_.bind(CAUSTICA_TEXUNIT_TRI_GEOM);
}

}  // namespace caustica
