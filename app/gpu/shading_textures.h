// shading_textures.h — the buffer textures through which the shaders read the materials, the light-tree
// nodes, the texture block and the TriShade words (bindings.glsl, light_tree.glsl, textures.glsl,
// tri_shade.glsl): views of those buffers, no copies. On llvmpipe a texelFetch is a vector gather, an SSBO
// load a loop over the SIMD lanes (docs/architecture.md, "Writing shaders for llvmpipe").
#pragma once
#include <string>

#include "gpu/gl_objects.h"

namespace caustica {

class ShadingTextures {
 public:
  ShadingTextures() = default;
  // Views `materials` (gpu::Material[]), `lightNodes` (gpu::LightNode[]), `texels` (TexInfo words, then
  // RGBA8 texels) and `triShade` (the TriShade words, 3 per texel; nullptr when they are split over several
  // storage blocks, which the shaders then read as SSBOs) as buffer textures. Throws Error naming `what`
  // (the scene's path) when one has more texels than GL_MAX_TEXTURE_BUFFER_SIZE.
  ShadingTextures(const GlBuffer& materials, const GlBuffer& lightNodes, const GlBuffer& texels, const GlBuffer* triShade,
                  const std::string& what);
  // Binds them on CAUSTICA_TEXUNIT_MATERIALS, _LIGHT_NODES, _TEXELS, _TEX_INFO and _TRI_SHADE.
  void bind() const;

 private:
  GlBufferTexture materials_, lightNodes_, texels_, texInfo_, triShade_;
};

}  // namespace caustica
