// bvh_textures.h — the buffer textures through which the shaders' traversal reads the BVH nodes and
// the triangle positions (glsl/lib/traverse.glsl): views of the nodes and TriGeom buffers, no copies,
// and the 4-wide nodes (gpu::BvhWideNode) in a buffer of their own, uploaded here.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "gpu/gl_objects.h"
#include "shared/gpu_layout.h"

namespace caustica {

// Throws Error("WHAT: ARRAY_NEEDS N texels in one buffer texture; ...") when `texels` exceed
// GL_MAX_TEXTURE_BUFFER_SIZE; `what` is the scene's path, `arrayNeeds` e.g. "the materials need".
void checkBufferTextureTexels(std::size_t texels, const std::string& what, const std::string& arrayNeeds = "the BVH needs");

class BvhTextures {
 public:
  BvhTextures() = default;
  // Views `nodes` (gpu::BvhNode[]) and `triGeom` (gpu::TriGeom[]) as RGBA32UI texels, and uploads
  // `wide` (packBvhWideNodes' nodes, which traverse.glsl reads; empty: a root of empty slots, for
  // callers that use only the binary nodes) into a buffer of its own. Throws Error naming `what` (the
  // scene's path) when any has more texels than GL_MAX_TEXTURE_BUFFER_SIZE.
  BvhTextures(const GlBuffer& nodes, std::size_t nodeCount, const GlBuffer& triGeom, std::size_t triCount,
              const std::string& what, const std::vector<gpu::BvhWideNode>& wide = {});
  // The same with the 4-wide nodes already in `wideBuffer` (`wideCount` nodes; none: an empty root), so
  // that the caller can free its host copy before it uploads the rest (Renderer).
  BvhTextures(const GlBuffer& nodes, std::size_t nodeCount, const GlBuffer& triGeom, std::size_t triCount,
              const std::string& what, GlBuffer wideBuffer, std::size_t wideCount);
  // Binds them on CAUSTICA_TEXUNIT_BVH_NODES, CAUSTICA_TEXUNIT_TRI_GEOM and CAUSTICA_TEXUNIT_BVH_WIDE.
  void bind() const;

 private:
  GlBuffer wideBuffer_;  // the 4-wide nodes (declared before wide_, which views it)
  GlBufferTexture nodes_, triGeom_, wide_;
};

}  // namespace caustica
