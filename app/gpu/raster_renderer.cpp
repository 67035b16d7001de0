// raster_renderer.cpp — the raster mode: mesh building (no GL), shadow cube maps, the mirror passes
// with a stencil mask, and sorted blending for glass and cut-outs.
#include "gpu/raster_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "util/error.h"

namespace caustica {

namespace {

std::uint32_t materialOf(const gpu::TriGeom& g) {
  std::uint32_t m;
  std::memcpy(&m, &g.v0.w, 4);
  return m;
}

bool isEmissive(const gpu::Material& m) { return m.emission.x > 0.0f || m.emission.y > 0.0f || m.emission.z > 0.0f; }
bool isTransparent(const gpu::Material& m) { return (1.0f - m.params.x) * m.params.z > 0.0f || m.baseColor.a < 1.0f; }
bool isMirrorMaterial(const gpu::Material& m) { return m.params.x >= 0.5f && !isTransparent(m); }

// Uniform locations (raster.vert / raster.frag / shadow.*).
constexpr GLint kUViewProj = 0, kUClipPlane = 1, kUEye = 2, kUBaseColor = 3, kUEmission = 4, kUParams = 5,
                kUHasTexture = 6, kUPlanarMirror = 7, kUShadowTexels = 8, kUVertexAlpha = 9, kUVertexColors = 10,
                kULightPosFar = 1;

}  // namespace

RasterMesh buildRasterMesh(const GpuScene& scene) {
  RasterMesh mesh;
  const size_t n = scene.triGeom.size();
  Bounds bounds;
  for (const auto& g : scene.triGeom) {
    bounds.grow(glm::vec3(g.v0));
    bounds.grow(glm::vec3(g.v1));
    bounds.grow(glm::vec3(g.v2));
  }
  const float extent = bounds.empty() ? 1.0f : std::max(glm::length(bounds.max - bounds.min), 1e-30f);

  enum Kind { Opaque, Mirror, Transparent, Emissive };
  std::vector<int> kind(n);
  std::vector<int> plane(n, -1);  // mirror plane index per triangle
  std::vector<glm::vec3> geomNormal(n);
  for (size_t i = 0; i < n; ++i) {
    const auto& g = scene.triGeom[i];
    glm::vec3 cr = glm::cross(glm::vec3(g.v1) - glm::vec3(g.v0), glm::vec3(g.v2) - glm::vec3(g.v0));
    float len = glm::length(cr);
    geomNormal[i] = len > 0.0f ? cr / len : glm::vec3(0.0f, 0.0f, 1.0f);
    const gpu::Material& m = scene.materials[materialOf(g)];
    kind[i] = isEmissive(m) ? Emissive : isTransparent(m) ? Transparent : isMirrorMaterial(m) ? Mirror : Opaque;
  }

  // Planar mirrors: the planes each mirror material lies on; a material on more than
  // kRasterMirrorPlanes planes is curved (a mirror ball) and keeps only its highlight.
  std::vector<RasterMirror> planes;
  for (std::uint32_t mat = 0; mat < scene.materials.size(); ++mat) {
    std::vector<RasterMirror> found;
    std::vector<size_t> tris;
    bool curved = false;
    for (size_t i = 0; i < n && !curved; ++i) {
      if (kind[i] != Mirror || materialOf(scene.triGeom[i]) != mat) continue;
      glm::vec3 nn = geomNormal[i];
      float d = glm::dot(nn, glm::vec3(scene.triGeom[i].v0));
      int at = -1;
      for (size_t k = 0; k < found.size(); ++k) {
        float c = glm::dot(nn, found[k].normal);
        if (std::abs(c) > 0.9999f && std::abs(d - c * found[k].offset) < 1e-4f * extent) at = static_cast<int>(k);
      }
      if (at < 0) {
        if (static_cast<int>(found.size()) == kRasterMirrorPlanes ||
            static_cast<int>(planes.size() + found.size()) == kRasterMaxMirrors) {
          curved = true;
          break;
        }
        found.push_back(RasterMirror{nn, d, mat, 0, 0});
        at = static_cast<int>(found.size()) - 1;
      }
      plane[i] = static_cast<int>(planes.size()) + at;
      tris.push_back(i);
    }
    if (curved) {
      for (size_t i = 0; i < n; ++i)
        if (kind[i] == Mirror && materialOf(scene.triGeom[i]) == mat) kind[i] = Opaque, plane[i] = -1;
      continue;
    }
    planes.insert(planes.end(), found.begin(), found.end());
  }

  auto emit = [&](size_t i) {
    const auto& g = scene.triGeom[i];
    const glm::vec3 p[3] = {glm::vec3(g.v0), glm::vec3(g.v1), glm::vec3(g.v2)};
    const glm::vec3 nn[3] = {shadeNormal(scene, i, 0), shadeNormal(scene, i, 1), shadeNormal(scene, i, 2)};
    const glm::vec2 uv[3] = {shadeUv(scene, i, 0), shadeUv(scene, i, 1), shadeUv(scene, i, 2)};
    for (int k = 0; k < 3; ++k) {
      glm::vec3 ns = glm::length(nn[k]) > 0.5f ? glm::normalize(nn[k]) : geomNormal[i];
      mesh.vertices.push_back({p[k], ns, uv[k], geomNormal[i], shadeColor(scene, i, k)});
    }
  };
  auto batchesOf = [&](int which, std::vector<RasterMesh::Batch>& out) {
    for (std::uint32_t mat = 0; mat < scene.materials.size(); ++mat) {
      RasterMesh::Batch b{mat, static_cast<std::uint32_t>(mesh.vertices.size()), 0};
      for (size_t i = 0; i < n; ++i)
        if (kind[i] == which && materialOf(scene.triGeom[i]) == mat) emit(i);
      b.count = static_cast<std::uint32_t>(mesh.vertices.size()) - b.first;
      if (b.count) out.push_back(b);
    }
  };
  batchesOf(Opaque, mesh.opaque);
  for (size_t k = 0; k < planes.size(); ++k) {
    RasterMirror mirror = planes[k];
    mirror.first = static_cast<std::uint32_t>(mesh.vertices.size());
    for (size_t i = 0; i < n; ++i)
      if (plane[i] == static_cast<int>(k)) emit(i);
    mirror.count = static_cast<std::uint32_t>(mesh.vertices.size()) - mirror.first;
    if (mirror.count) mesh.mirrors.push_back(mirror);
  }
  mesh.transparentFirst = static_cast<std::uint32_t>(mesh.vertices.size());
  for (size_t i = 0; i < n; ++i)
    if (kind[i] == Transparent) {
      emit(i);
      mesh.transparentMaterial.push_back(materialOf(scene.triGeom[i]));
    }
  mesh.transparentCount = static_cast<std::uint32_t>(mesh.vertices.size()) - mesh.transparentFirst;
  mesh.occluderCount = static_cast<std::uint32_t>(mesh.vertices.size());
  batchesOf(Emissive, mesh.emissive);
  return mesh;
}

RasterRenderer::RasterRenderer(const ShaderLibrary& library, const GpuScene& scene, const gpu::PointLights& lights)
    : materials_(scene.materials), vertexColors_(scene.triShadeLayout.colors) {
  mesh_ = buildRasterMesh(scene);
  auto compile = [&](const char* vs, const char* fs) {
    ExpandedShader v = library.expand(vs, {});
    ExpandedShader f = library.expand(fs, {});
    return GlProgram::compileGraphics(v.source, [&](const std::string& log) { return v.mapLog(log); }, f.source,
                                      [&](const std::string& log) { return f.mapLog(log); }, vs);
  };
  program_ = compile("raster/raster.vert", "raster/raster.frag");
  shadowProgram_ = compile("raster/shadow.vert", "raster/shadow.frag");

  vertexBuffer_ = GlBuffer::fromVector(mesh_.vertices);
  using V = RasterMesh::Vertex;
  vao_ = GlVertexArray::create(vertexBuffer_, sizeof(V),
                               {{0, 3, offsetof(V, position)}, {1, 3, offsetof(V, normal)}, {2, 2, offsetof(V, uv)},
                                {3, 3, offsetof(V, geomNormal)}, {4, 4, offsetof(V, color)}});
  for (const gpu::TexInfo& t : scene.texInfo) {
    auto wrap = [](bool repeat, bool mirror) { return mirror ? GL_MIRRORED_REPEAT : repeat ? GL_REPEAT : GL_CLAMP_TO_EDGE; };
    textures_.push_back(GlTexture::createSrgb8(static_cast<int>(t.width), static_cast<int>(t.height),
                                               scene.texels.data() + t.offset, wrap(t.flags & 1u, t.flags & 4u),
                                               wrap(t.flags & 2u, t.flags & 8u), (t.flags & 16u) != 0u));
  }
  drawShadowMaps(lights);
}

void RasterRenderer::drawShadowMaps(const gpu::PointLights& lights) {
  const int count = static_cast<int>(std::min<std::uint32_t>(lights.count.x, CAUSTICA_MAX_POINT_LIGHTS));
  shadowMaps_ = GlTexture::createDepthCubeArray(kShadowMapTexels, count);
  // The six 90-degree views of a cube map face, in GL's face order (+X, -X, +Y, -Y, +Z, -Z).
  const glm::vec3 dirs[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const glm::vec3 ups[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
  GLint viewport[4];
  glGetIntegerv(GL_VIEWPORT, viewport);
  shadowProgram_.use();
  vao_.bind();
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glDisable(GL_STENCIL_TEST);
  glViewport(0, 0, kShadowMapTexels, kShadowMapTexels);
  for (int l = 0; l < count; ++l) {
    const glm::vec3 pos(lights.light[l].position);
    const float far = lights.light[l].intensity.w;  // beyond every occluder (Renderer: pointLightParams)
    glm::mat4 proj = glm::perspective(glm::radians(90.0f), 1.0f, far * 1e-4f, far);
    glUniform4f(kULightPosFar, pos.x, pos.y, pos.z, far);
    for (int face = 0; face < 6; ++face) {
      GlFramebuffer fb = GlFramebuffer::forDepthLayer(shadowMaps_, l * 6 + face);
      fb.bindDraw();
      glClearDepth(1.0);
      glClear(GL_DEPTH_BUFFER_BIT);
      glm::mat4 vp = proj * glm::lookAt(pos, pos + dirs[face], ups[face]);
      glUniformMatrix4fv(kUViewProj, 1, GL_FALSE, glm::value_ptr(vp));
      if (mesh_.occluderCount) glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(mesh_.occluderCount));
    }
  }
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
  checkGlError("shadow maps");
}

void RasterRenderer::setMaterial(std::uint32_t material, bool planarMirror) const {
  const gpu::Material& m = materials_[material];
  glUniform4fv(kUBaseColor, 1, glm::value_ptr(m.baseColor));
  glUniform4f(kUEmission, m.emission.x, m.emission.y, m.emission.z, (m.tex.z & gpu::kMatDoubleSided) ? 1.0f : 0.0f);
  glm::vec4 params = m.params;
  if (!(m.specular.w > 0.0f)) params.y = 1.0f;  // no specular layer: no highlight (phongRoughness in point_lights.glsl)
  glUniform4fv(kUParams, 1, glm::value_ptr(params));
  bool textured = m.tex.x != gpu::kInvalidIndex && m.tex.x < textures_.size();
  glUniform1i(kUHasTexture, textured ? 1 : 0);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, textured ? textures_[m.tex.x].id() : 0);
  glUniform1i(kUPlanarMirror, planarMirror ? 1 : 0);
  glUniform1i(kUVertexAlpha, (m.tex.z & gpu::kMatVertexAlpha) != 0u ? 1 : 0);
}

void RasterRenderer::drawBatches(const std::vector<RasterMesh::Batch>& batches) const {
  for (const auto& b : batches) {
    setMaterial(b.material, false);
    glDrawArrays(GL_TRIANGLES, static_cast<GLint>(b.first), static_cast<GLsizei>(b.count));
  }
}

// The view uniforms: clip-space transform, the clip plane (a fragment at p is kept where
// dot(clip.xyz, p) + clip.w >= 0; world space) and the eye.
void RasterRenderer::setView(const glm::mat4& viewProj, const glm::vec3& eye, const glm::vec4& clip) const {
  glUniformMatrix4fv(kUViewProj, 1, GL_FALSE, glm::value_ptr(viewProj));
  glUniform4fv(kUClipPlane, 1, glm::value_ptr(clip));
  glUniform3fv(kUEye, 1, glm::value_ptr(eye));
}

// Everything opaque: diffuse and curved metal, emitters, and the planar mirrors other than
// `skipMirror` as plain surfaces (a mirror seen in a mirror shows no second reflection).
void RasterRenderer::drawOpaqueScene(const glm::mat4& viewProj, const glm::vec3& eye, const glm::vec4& clip,
                                     int skipMirror) const {
  setView(viewProj, eye, clip);
  drawBatches(mesh_.opaque);
  drawBatches(mesh_.emissive);
  for (int k = 0; k < static_cast<int>(mesh_.mirrors.size()); ++k) {
    if (k == skipMirror) continue;
    setMaterial(mesh_.mirrors[k].material, false);
    glDrawArrays(GL_TRIANGLES, static_cast<GLint>(mesh_.mirrors[k].first), static_cast<GLsizei>(mesh_.mirrors[k].count));
  }
}

namespace {

// The clip-space transform of `camera` for a w x h image (row 0 at the top, as the accumulation image),
// its far plane beyond everything in `mesh` (twice that with mirrors: the reflected scene lies up to
// twice as far).
// The camera's view-projection and `eye`, the point the shading's view vectors start from: the camera's
// position, or for an orthographic camera a point far behind its image plane (drawn from there with
// the same view volume, so that the view vectors are parallel too).
glm::mat4 cameraViewProjection(const Camera& camera, int w, int h, const RasterMesh& mesh, float& far, glm::vec3& eye) {
  // The compute camera's frame: right = forward x up, image row 0 at the top.
  glm::vec3 fwd = glm::normalize(camera.forward);
  glm::vec3 right = glm::normalize(glm::cross(fwd, camera.up));
  glm::vec3 up = glm::cross(right, fwd);
  Bounds b;
  for (const auto& v : mesh.vertices) b.grow(v.position);
  far = 1.0f;
  if (!b.empty())
    for (int c = 0; c < 8; ++c) {
      glm::vec3 corner((c & 1) ? b.max.x : b.min.x, (c & 2) ? b.max.y : b.min.y, (c & 4) ? b.max.z : b.min.z);
      far = std::max(far, glm::length(corner - camera.position) * 1.01f);
    }
  if (!mesh.mirrors.empty()) far *= 2.0f;
  const float aspect = static_cast<float>(w) / static_cast<float>(h), h2 = camera.orthoHeight;
  const float back = camera.orthographic() ? 1000.0f * far : 0.0f;
  eye = camera.position - fwd * back;
  glm::mat4 proj = camera.orthographic() ? glm::ortho(-h2 * aspect, h2 * aspect, -h2, h2, back, back + far)
                                         : glm::perspective(camera.yfov, aspect, far * 1e-4f, far);
  // GL's window row 0 is the bottom; the accumulation image's row 0 is the top: flip y in clip space.
  proj = glm::scale(glm::mat4(1.0f), glm::vec3(1.0f, -1.0f, 1.0f)) * proj;
  return proj * glm::lookAt(eye, eye + fwd, up);
}

// Clears the bound framebuffer (black, alpha 1; depth 1; stencil 0) and sets the state of the opaque pass.
void beginRasterFrame(int w, int h) {
  glViewport(0, 0, w, h);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  glStencilMask(0xff);
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClearDepth(1.0);
  glClearStencil(0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDisable(GL_STENCIL_TEST);
  glEnable(GL_CLIP_DISTANCE0);
}

// Keeps every fragment (the clip plane's distance is always 1).
const glm::vec4 kKeepAll(0.0f, 0.0f, 0.0f, 1.0f);

}  // namespace

void RasterRenderer::draw(const Camera& camera, const GlTexture& target) {
  const int w = target.width(), h = target.height();
  if (depthStencil_.width() != w || depthStencil_.height() != h) depthStencil_ = GlTexture::createDepthStencil(w, h);
  framebuffer_ = GlFramebuffer::forTargets(target, depthStencil_);  // cheap; the target may be new
  float far = 1.0f;
  glm::vec3 eye;
  const glm::mat4 viewProj = cameraViewProjection(camera, w, h, mesh_, far, eye);

  GLint viewport[4];
  glGetIntegerv(GL_VIEWPORT, viewport);
  framebuffer_.bindDraw();
  beginRasterFrame(w, h);
  program_.use();
  vao_.bind();
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_CUBE_MAP_ARRAY, shadowMaps_.id());
  glUniform1f(kUShadowTexels, static_cast<float>(kShadowMapTexels));
  glUniform1i(kUVertexColors, vertexColors_ ? 1 : 0);

  // 1. The opaque scene; planar mirrors first get a plain surface like everything else.
  drawOpaqueScene(viewProj, eye, kKeepAll, -1);
  // 2. Each planar mirror, inside its stencil mask.
  glEnable(GL_STENCIL_TEST);
  for (int k = 0; k < static_cast<int>(mesh_.mirrors.size()); ++k) drawPlanarMirror(k, viewProj, eye, far);
  glDisable(GL_STENCIL_TEST);
  // 3. Glass and cut-outs, back to front, blended over what lies behind.
  if (mesh_.transparentCount) drawTransparent(viewProj, eye);

  glDisable(GL_CLIP_DISTANCE0);
  glDisable(GL_DEPTH_TEST);  // leave the state the compute passes and the viewer's blit expect
  glBindVertexArray(0);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glViewport(viewport[0], viewport[1], viewport[2], viewport[3]);
  checkGlError("raster frame");
}

// Planar mirror k (the paper's method): mark its visible pixels in the stencil buffer, push their depth
// to the far plane, draw the scene seen by the mirrored camera there (clipped to the mirror's front),
// then lay the mirror's tint and own shading over it and restore its depth. Stencil test enabled.
void RasterRenderer::drawPlanarMirror(int k, const glm::mat4& viewProj, const glm::vec3& eye, float far) const {
  const RasterMirror& mirror = mesh_.mirrors[k];
  glm::vec3 n = mirror.normal;
  float d = mirror.offset;
  float side = glm::dot(n, eye) - d;
  if (std::abs(side) < 1e-6f * far) return;
  if (side < 0.0f) n = -n, d = -d;  // the plane's normal towards the camera
  const GLint first = static_cast<GLint>(mirror.first);
  const GLsizei count = static_cast<GLsizei>(mirror.count);
  const GLint ref = k + 1;

  setView(viewProj, eye, kKeepAll);
  setMaterial(mirror.material, true);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_FALSE);
  glDepthFunc(GL_LEQUAL);
  glStencilFunc(GL_ALWAYS, ref, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  glDrawArrays(GL_TRIANGLES, first, count);

  glStencilFunc(GL_EQUAL, ref, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_ALWAYS);
  glDepthRange(1.0, 1.0);
  glDrawArrays(GL_TRIANGLES, first, count);
  glDepthRange(0.0, 1.0);

  // Reflection in the plane n.x = d: x' = x - 2 (n.x - d) n.
  glm::mat4 reflect(1.0f);
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) reflect[c][r] = (c == r ? 1.0f : 0.0f) - 2.0f * n[c] * n[r];
  reflect[3] = glm::vec4(2.0f * d * n, 1.0f);
  glm::vec3 mirroredEye = glm::vec3(reflect * glm::vec4(eye, 1.0f));
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthFunc(GL_LESS);
  drawOpaqueScene(viewProj * reflect, mirroredEye, glm::vec4(n, -d), k);

  const gpu::Material& m = materials_[mirror.material];
  glm::vec3 tint = glm::vec3(m.baseColor) * m.params.x;
  glEnable(GL_BLEND);
  glBlendColor(tint.r, tint.g, tint.b, 1.0f);
  glBlendFuncSeparate(GL_ONE, GL_CONSTANT_COLOR, GL_ZERO, GL_ONE);
  setView(viewProj, eye, kKeepAll);
  setMaterial(mirror.material, true);
  glDepthFunc(GL_ALWAYS);
  glDrawArrays(GL_TRIANGLES, first, count);
  glDisable(GL_BLEND);
  glDepthFunc(GL_LESS);
}

// Glass and cut-outs: their triangles sorted back to front by centroid, drawn in runs of one material,
// blended over what lies behind (premultiplied; alpha stays 1), without writing depth.
void RasterRenderer::drawTransparent(const glm::mat4& viewProj, const glm::vec3& eye) {
  const std::uint32_t tris = mesh_.transparentCount / 3;
  std::vector<float> dist2(tris);
  for (std::uint32_t t = 0; t < tris; ++t) {
    const auto* v = &mesh_.vertices[mesh_.transparentFirst + 3 * t];
    glm::vec3 c = (v[0].position + v[1].position + v[2].position) / 3.0f - eye;
    dist2[t] = glm::dot(c, c);
  }
  std::vector<std::uint32_t> order(tris);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b2) { return dist2[a] > dist2[b2]; });
  std::vector<std::uint32_t> indices;
  indices.reserve(3 * tris);
  for (std::uint32_t t : order)
    for (std::uint32_t k = 0; k < 3; ++k) indices.push_back(mesh_.transparentFirst + 3 * t + k);
  indexBuffer_ = GlBuffer::fromVector(indices, GL_STREAM_DRAW);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, indexBuffer_.id());
  setView(viewProj, eye, kKeepAll);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
  glDepthMask(GL_FALSE);
  for (std::uint32_t start = 0; start < tris;) {  // runs of one material
    std::uint32_t mat = mesh_.transparentMaterial[order[start]], end = start;
    while (end < tris && mesh_.transparentMaterial[order[end]] == mat) ++end;
    setMaterial(mat, false);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * (end - start)), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(static_cast<std::size_t>(start) * 3 * sizeof(std::uint32_t)));
    start = end;
  }
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
}

}  // namespace caustica
