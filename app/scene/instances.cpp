// instances.cpp — flattenInstances: an instanced scene (LoadOptions::keepInstances) baked into the
// world-space triangles the loader makes without it (docs/instancing.md).
#include <cmath>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace caustica {

namespace {
// Where flattenInstance appends the per-triangle arrays a scene keeps besides its triangles.
struct TriangleExtras {
  std::vector<TriangleUv>* uv = nullptr;
  std::vector<TriangleColors>* colors = nullptr;
  std::vector<TriangleTangents>* tangents = nullptr;
};

// Appends instance `in`'s world-space triangles (zero-area ones dropped; with `materialWanted`, only
// those of the wanted materials) to `out`, and to `source` (when given) the Scene::triangles index each
// came from.
void flattenInstance(const Scene& scene, const Instance& in, std::vector<Triangle>& out,
                     std::vector<std::uint32_t>* source, const std::vector<bool>* materialWanted = nullptr,
                     TriangleExtras extras = {}) {
  const MeshRange& m = scene.meshes[in.mesh];
  const glm::dmat3 m3(in.world);
  const glm::dmat3 normal = glm::transpose(glm::inverse(m3));
  const bool flip = glm::determinant(m3) < 0.0;  // as the loader: restore counter-clockwise fronts
  for (std::uint32_t i = m.firstTriangle; i < m.firstTriangle + m.triangleCount; ++i) {
    const Triangle& src = scene.triangles[i];
    if (materialWanted && (src.material >= materialWanted->size() || !(*materialWanted)[src.material])) continue;
    Triangle t;
    TriangleUv uv;
    TriangleColors color;
    TriangleTangents tangent;
    t.material = src.material;
    glm::vec3 n[3];
    for (int k = 0; k < 3; ++k) {
      const int s = flip && k > 0 ? 3 - k : k;  // swaps corners 1 and 2
      t.p[k] = glm::vec3(glm::dvec3(in.world * glm::dvec4(glm::dvec3(src.p[s]), 1.0)) - scene.origin);
      // The object-space normal as stored (octahedral, within 4.3e-5 rad of the file's), transformed.
      const glm::dvec3 nw = normal * glm::dvec3(src.normal(s));
      const double len = glm::length(nw);
      n[k] = len > 0.0 && std::isfinite(len) ? glm::vec3(nw / len) : glm::vec3(0.0f);
      uv.uv[k] = triangleUv(scene, i, s);
      color.color[k] = triangleColor(scene, i, s);
      // Tangents turn with the instance (not its inverse transpose); a mirroring one flips the sign.
      const glm::vec4 ts = triangleTangent(scene, i, s);
      const glm::dvec3 tw = m3 * glm::dvec3(glm::vec3(ts));
      const double tl = glm::length(tw);
      if (ts.w != 0.0f && tl > 0.0 && std::isfinite(tl))
        tangent.tangent[k] = glm::vec4(glm::vec3(tw / tl), flip ? -ts.w : ts.w);
    }
    const glm::vec3 cross = glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
    const float area2 = glm::length(cross);
    if (!(area2 > 0.0f) || !std::isfinite(area2)) continue;  // zero area in world space
    if (n[0] == glm::vec3(0.0f) || n[1] == glm::vec3(0.0f) || n[2] == glm::vec3(0.0f)) n[0] = n[1] = n[2] = cross / area2;
    for (int k = 0; k < 3; ++k) t.setNormal(k, n[k]);
    out.push_back(t);
    if (extras.uv) extras.uv->push_back(uv);
    if (extras.colors) extras.colors->push_back(color);
    if (extras.tangents) extras.tangents->push_back(tangent);
    if (source) source->push_back(i);
  }
}
}  // namespace

void flattenInstances(Scene& scene) {
  if (scene.instances.empty()) return;
  std::vector<Triangle> out;
  // Only the arrays the scene keeps (texture coordinates, vertex colours, tangents).
  std::vector<TriangleUv> outUv;
  std::vector<TriangleColors> outColors;
  std::vector<TriangleTangents> outTangents;
  TriangleExtras extras;
  if (!scene.texcoords.empty()) extras.uv = &outUv;
  if (!scene.colors.empty()) extras.colors = &outColors;
  if (!scene.tangents.empty()) extras.tangents = &outTangents;
  out.reserve(instancedTriangleCount(scene));
  for (const Instance& in : scene.instances) flattenInstance(scene, in, out, nullptr, nullptr, extras);
  scene.triangles = std::move(out);
  scene.texcoords = std::move(outUv);
  scene.colors = std::move(outColors);
  scene.tangents = std::move(outTangents);
  scene.meshes.clear();
  scene.instances.clear();
}

std::uint64_t instancedTriangleCount(const Scene& scene) {
  std::uint64_t n = 0;
  for (const Instance& in : scene.instances) n += scene.meshes[in.mesh].triangleCount;
  return n;
}

namespace {
// Per mesh: how many of its triangles have materialWanted[material].
std::vector<std::uint64_t> wantedPerMesh(const Scene& scene, const std::vector<bool>& materialWanted) {
  std::vector<std::uint64_t> n(scene.meshes.size(), 0);
  for (std::size_t m = 0; m < scene.meshes.size(); ++m)
    for (std::uint32_t i = 0; i < scene.meshes[m].triangleCount; ++i) {
      const std::uint32_t mat = scene.triangles[scene.meshes[m].firstTriangle + i].material;
      if (mat < materialWanted.size() && materialWanted[mat]) ++n[m];
    }
  return n;
}
}  // namespace

std::uint64_t placedTriangles(const Scene& scene, const std::vector<bool>& materialWanted) {
  const std::vector<std::uint64_t> perMesh = wantedPerMesh(scene, materialWanted);
  std::uint64_t n = 0;
  for (const Instance& in : scene.instances) n += perMesh[in.mesh];
  return n;
}

Scene flattenedSubset(const Scene& scene, const std::vector<bool>& materialWanted, std::vector<InstancedTriangle>* source) {
  Scene out;
  out.path = scene.path;
  out.materials = scene.materials;
  out.punctualLights = scene.punctualLights;
  out.spotEmitters = scene.spotEmitters;
  out.bounds = scene.bounds;
  out.origin = scene.origin;
  const std::vector<std::uint64_t> perMesh = wantedPerMesh(scene, materialWanted);
  std::vector<std::uint32_t> from;
  for (std::uint32_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& in = scene.instances[i];
    if (perMesh[in.mesh] == 0) continue;
    from.clear();
    flattenInstance(scene, in, out.triangles, &from, &materialWanted);
    if (source)
      for (std::uint32_t t : from) source->push_back({i, t});
  }
  return out;
}

}  // namespace caustica
