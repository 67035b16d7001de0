// raster_renderer.h — the raster mode (docs/render-modes.md): the OpenGL vertex/fragment pipeline on
// the packed scene: Blinn-Phong from the grouped point lights, omnidirectional shadow maps, planar
// mirrors by a mirrored-camera pass inside a stencil mask, transparency by sorted blending.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "accel/gpu_scene.h"
#include "gpu/gl_objects.h"
#include "gpu/shader_library.h"
#include "scene/scene.h"

namespace caustica {

constexpr int kRasterMaxMirrors = 4;       // planar mirrors given a reflection pass (stencil values 1..4)
constexpr int kRasterMirrorPlanes = 4;     // a metallic material on more planes than this is curved: highlights only
constexpr int kShadowMapTexels = 512;      // side of one shadow cube face

// One planar mirror: coplanar triangles of one mirror material (metallic >= 0.5, no transmission).
struct RasterMirror {
  glm::vec3 normal{0.0f};  // unit plane normal (world space): dot(normal, x) = offset on the plane
  float offset = 0.0f;
  std::uint32_t material = 0;
  std::uint32_t first = 0, count = 0;  // vertex range
};

// The raster mode's view of the scene, built without GL (tested in tests/gpu/raster_test.cpp).
struct RasterMesh {
  struct Vertex {
    glm::vec3 position;    // world space
    glm::vec3 normal;      // unit shading normal (the flat normal when the mesh has none)
    glm::vec2 uv;
    glm::vec3 geomNormal;  // unit front-face normal of the triangle
    glm::vec4 color;       // vertex colour (COLOR_0, linear RGBA; white without)
  };
  struct Batch {
    std::uint32_t material = 0;
    std::uint32_t first = 0, count = 0;  // vertex range
  };
  std::vector<Vertex> vertices;  // three per triangle: [opaque][mirrors][transparent][emissive]
  std::vector<Batch> opaque;       // per material, not emissive, not mirror, not transparent
  std::vector<RasterMirror> mirrors;
  std::uint32_t transparentFirst = 0, transparentCount = 0;  // triangles of glass or alpha < 1 (vertex range)
  std::vector<std::uint32_t> transparentMaterial;           // per transparent triangle
  std::vector<Batch> emissive;     // per material
  std::uint32_t occluderCount = 0; // vertices [0, occluderCount) cast shadows (all but emitters)
};
RasterMesh buildRasterMesh(const GpuScene& scene);

class RasterRenderer {
 public:
  // Needs a current GL 4.3 context. Draws the shadow maps once (lights and scene do not move).
  RasterRenderer(const ShaderLibrary& library, const GpuScene& scene, const gpu::PointLights& lights);
  // Draws the frame seen by `camera` into `target` (rgba32f, row 0 = top of the image, alpha 1).
  // The caller binds the PointLights UBO (the same one the shadow maps were drawn for).
  void draw(const Camera& camera, const GlTexture& target);
  const RasterMesh& mesh() const { return mesh_; }

 private:
  void drawShadowMaps(const gpu::PointLights& lights);
  void setMaterial(std::uint32_t material, bool planarMirror) const;
  void drawBatches(const std::vector<RasterMesh::Batch>& batches) const;
  void setView(const glm::mat4& viewProj, const glm::vec3& eye, const glm::vec4& clip) const;
  void drawOpaqueScene(const glm::mat4& viewProj, const glm::vec3& eye, const glm::vec4& clip, int skipMirror) const;
  void drawPlanarMirror(int k, const glm::mat4& viewProj, const glm::vec3& eye, float far) const;
  void drawTransparent(const glm::mat4& viewProj, const glm::vec3& eye);

  std::vector<gpu::Material> materials_;
  bool vertexColors_ = false;  // the scene has COLOR_0: the vertices' colours multiply the base colour
  RasterMesh mesh_;
  GlBuffer vertexBuffer_, indexBuffer_;
  GlVertexArray vao_;
  GlProgram program_, shadowProgram_;
  std::vector<GlTexture> textures_;  // one per TexInfo
  GlTexture shadowMaps_;
  GlTexture depthStencil_;
  GlFramebuffer framebuffer_;
};

}  // namespace caustica
