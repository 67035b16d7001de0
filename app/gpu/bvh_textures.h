// bvh_textures.h — the buffer textures through which the shaders' traversal reads the BVH nodes and
// the triangle positions (glsl/lib/traverse.glsl): views of the nodes and TriGeom buffers, no copies.
#pragma once
#include <cstddef>
#include <string>

#include "gpu/gl_objects.h"

namespace caustica {

class BvhTextures {
 public:
  BvhTextures() = default;
  // Views `nodes` (gpu::BvhNode[]) and `triGeom` (gpu::TriGeom[]) as RGBA32UI texels. Throws Error
  // naming `what` (the scene's path) when either has more texels than GL_MAX_TEXTURE_BUFFER_SIZE.
  BvhTextures(const GlBuffer& nodes, std::size_t nodeCount, const GlBuffer& triGeom, std::size_t triCount,
              const std::string& what);
  // Binds both on CAUSTICA_TEXUNIT_BVH_NODES and CAUSTICA_TEXUNIT_TRI_GEOM.
  void bind() const;

 private:
  GlBufferTexture nodes_, triGeom_;
};

}  // namespace caustica
