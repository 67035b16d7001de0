// shading_textures.cpp — buffer-texture views of the materials, light-tree nodes and texture block.
#include "gpu/shading_textures.h"

#include <cstddef>

#include "gpu/bvh_textures.h"  // checkBufferTextureTexels
#include "shared/gpu_layout.h"
#include "util/error.h"

namespace caustica {

ShadingTextures::ShadingTextures(const GlBuffer& materials, const GlBuffer& lightNodes, const GlBuffer& texels,
                                 const GlBuffer* triShade, const std::string& what) {
  const struct {
    const char* name;
    std::size_t texels;
  } views[] = {{"materials", materials.size() / 16}, {"light tree", lightNodes.size() / 16}, {"textures", texels.size() / 4},
                   {"triangle shading data", triShade ? triShade->size() / 12 : 0}};
  for (const auto& v : views) checkBufferTextureTexels(v.texels, what, std::string("the ") + v.name + " need");
  materials_ = GlBufferTexture::create(materials, GL_RGBA32UI);
  lightNodes_ = GlBufferTexture::create(lightNodes, GL_RGBA32UI);
  texels_ = GlBufferTexture::create(texels, GL_R32UI);
  texInfo_ = GlBufferTexture::create(texels, GL_RGBA32UI);
  if (triShade) triShade_ = GlBufferTexture::create(*triShade, GL_RGB32UI);
}

void ShadingTextures::bind() const {
  materials_.bind(CAUSTICA_TEXUNIT_MATERIALS);
  lightNodes_.bind(CAUSTICA_TEXUNIT_LIGHT_NODES);
  texels_.bind(CAUSTICA_TEXUNIT_TEXELS);
  texInfo_.bind(CAUSTICA_TEXUNIT_TEX_INFO);
  if (triShade_.id() != 0) triShade_.bind(CAUSTICA_TEXUNIT_TRI_SHADE);
}

}  // namespace caustica
