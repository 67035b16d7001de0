// gpu_scene.cpp — Scene + BVH to shader storage arrays; the emitters' light tree.
#include "accel/gpu_scene.h"

#include <cmath>
#include <cstring>

#include <glm/gtc/packing.hpp>

#include "accel/intersect.h"
#include "accel/tlas.h"
#include "scene/caustic_casters.h"
#include "util/error.h"
#include "shading/microfacet.h"
#include "shading/oct_normal.h"
#include "shading/sampling.h"

namespace caustica {

bool hasRoughLobe(const Material& m) {
  const bool rough = m.roughness * m.roughness >= kDeltaAlpha || m.metallicRoughnessTexture >= 0;
  const bool metal = m.metallic > 0.0f || m.metallicRoughnessTexture >= 0;
  const bool glass = m.transmission > 0.0f && m.metallic < 1.0f;
  const bool layered = m.metallic < 1.0f && m.transmission < 1.0f && m.specularF90 > 0.0f;
  return (rough && (metal || glass)) || layered;
}

std::vector<bool> usedMaterials(const Scene& scene) {
  std::vector<bool> used(scene.materials.size(), false);
  for (const auto& t : scene.triangles)
    if (t.material < used.size()) used[t.material] = true;
  return used;
}

std::vector<std::string> TriShadeLayout::defines() const {
  std::vector<std::string> d;
  if (texcoords) d.push_back("CAUSTICA_TRISHADE_TEXCOORDS");
  if (colors) d.push_back("CAUSTICA_TRISHADE_COLORS");
  if (tangents) d.push_back("CAUSTICA_TRISHADE_TANGENTS");
  return d;
}

namespace {
std::uint32_t floatBits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

// The TriShade blocks the scene needs: full-float texcoords where a material some triangle uses reads
// a texture (the CAUSTICA_TEXTURES row of gpu/shader_features.cpp asks the same of the materials),
// vertex colours where the scene has them, tangents where it has them and textures (normal maps).
void setTriShadeLayout(const Scene& scene, GpuScene& g) {
  const std::vector<bool> used = usedMaterials(scene);
  for (std::size_t m = 0; m < scene.materials.size(); ++m)
    g.triShadeLayout.texcoords = g.triShadeLayout.texcoords || (used[m] && scene.materials[m].readsTextures());
  g.triShadeLayout.colors = !scene.colors.empty();
  g.triShadeLayout.tangents = g.triShadeLayout.texcoords && !scene.tangents.empty();
  g.triShadeStride = g.triShadeLayout.stride();
}

// Scene triangle `tri`'s shading words (gpu_layout.h) at w[0, layout.stride()): its octahedral normals,
// then full-float texcoords only where textures read them (half floats would move a texel on large
// textures), vertex colours as half floats, tangents octahedral with the sign in bit 0.
void writeTriShade(const Scene& scene, std::size_t tri, const TriShadeLayout& layout, std::uint32_t* w) {
  for (int k = 0; k < 3; ++k) w[k] = scene.triangles[tri].normalWord[k];  // stored octahedral already (scene.h)
  if (layout.texcoords)
    for (int k = 0; k < 3; ++k) {
      const glm::vec2 uv = triangleUv(scene, tri, k);
      w[3 + 2 * k] = floatBits(uv.x);
      w[4 + 2 * k] = floatBits(uv.y);
    }
  if (layout.colors)
    for (int k = 0; k < 3; ++k) {
      const glm::vec4 c = triangleColor(scene, tri, k);
      w[layout.colorOffset() + 2 * std::uint32_t(k)] = glm::packHalf2x16(glm::vec2(c.r, c.g));
      w[layout.colorOffset() + 2 * std::uint32_t(k) + 1] = glm::packHalf2x16(glm::vec2(c.b, c.a));
    }
  if (layout.tangents)
    for (int k = 0; k < 3; ++k) w[layout.tangentOffset() + std::uint32_t(k)] = tangentWord(triangleTangent(scene, tri, k));
}

// The environment's texels, CDFs and UBO. An environment lights every point from everywhere, so
// refractive casters are aimed at from every point: the sphere around the lights becomes one that
// holds every point (its squared radius still finite in float).
void packEnvironment(const Scene& scene, GpuScene& g) {
  gpu::EnvironmentParams& p = g.environmentParams;
  p.rotation = glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);
  if (scene.environment.emits()) {
    g.environment = buildEnvironmentDistribution(scene.environment);
    p.size = glm::uvec4(g.environment.width, g.environment.height, 0u, 0u);
    p.rotation = glm::vec4(g.environment.cosRotation, g.environment.sinRotation, 0.0f, 0.0f);
    g.emitterSphere = glm::vec4(0.5f * (scene.bounds.min + scene.bounds.max), 1.0e18f);
  }
  const Background& b = scene.background;
  p.size.z = b.kind == Background::Kind::Color         ? gpu::kBackgroundColor
             : b.kind == Background::Kind::Transparent ? gpu::kBackgroundTransparent
                                                       : gpu::kBackgroundEnvironment;
  p.background = glm::vec4(b.color, 0.0f);
}
}  // namespace

void packTriangleRange(const Scene& scene, const Bvh& bvh, const GpuScene& g, std::size_t first, std::size_t count,
                       std::vector<gpu::TriGeom>& geom, std::vector<std::uint32_t>& shade) {
  if (first + count > bvh.order.size() || g.lightTree.leafOf.size() != bvh.order.size())
    throw Error("internal: packTriangleRange outside the BVH's triangles");
  geom.resize(count);
  shade.resize(count * g.triShadeStride);
  for (std::size_t j = 0; j < count; ++j) {
    const std::size_t i = first + j;
    const Triangle& t = scene.triangles[bvh.order[i]];
    const std::uint32_t leaf = g.lightTree.leafOf[i];
    glm::vec3 q0, q1, q2;
    packedTrianglePositions(t.p, q0, q1, q2);  // a zero-area triangle as one point (intersect.glsl)
    geom[j].v0 = glm::vec4(q0, glm::uintBitsToFloat(t.material));
    geom[j].v1 = glm::vec4(q1, glm::uintBitsToFloat(leaf == gpu::kInvalidIndex ? 0u : leaf + 1u));
    geom[j].v2 = glm::vec4(q2, 0.0f);
    writeTriShade(scene, bvh.order[i], g.triShadeLayout, shade.data() + j * g.triShadeStride);
  }
}

namespace {
// An emissive triangle's weight for the emitter choice: luminance(emission) * area * sides (area in
// scene units^2 from its vertices p[3]); 0 where that is not a positive finite number (no emitter).
double emitterWeight(const Material& m, const glm::vec3* p) {
  const double area = 0.5 * glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
  const double w = static_cast<double>(luminance(glm::max(m.emission, glm::vec3(0.0f)))) * area * (m.doubleSided ? 2.0 : 1.0);
  return w > 0.0 && std::isfinite(w) ? w : 0.0;
}

// The light tree's item for emitter `tri` (TriGeom index) with vertices p[3] and weight `power`.
LightTreeItem emitterItem(std::uint32_t tri, const glm::vec3* p, double power, bool twoSided) {
  LightTreeItem item;
  item.tri = tri;
  for (int k = 0; k < 3; ++k) item.v[k] = p[k];
  item.power = power;
  item.twoSided = twoSided;
  return item;
}

// What packScene and packInstancedScene share: environment, materials, punctual lights, textures
// (not the triangles, the casters or the emitters).
void packMaterialsAndTextures(const Scene& scene, GpuScene& g) {
  if (!scene.texcoords.empty() && scene.texcoords.size() != scene.triangles.size())
    throw Error("internal: Scene::texcoords is neither empty nor one per triangle");
  for (const Material& m : scene.materials) {
    gpu::Material gm{};
    gm.baseColor = m.baseColor;
    gm.emission = glm::vec4(glm::max(m.emission, glm::vec3(0.0f)), 0.0f);
    gm.params = glm::vec4(m.metallic, m.roughness, m.transmission, m.ior);
    glm::vec3 absorption(0.0f);
    std::uint32_t flags = m.doubleSided ? gpu::kMatDoubleSided : 0u;
    if (std::isfinite(m.attenuationDistance) && m.attenuationDistance > 0.0f) {
      absorption = -glm::log(glm::clamp(m.attenuationColor, glm::vec3(1e-6f), glm::vec3(1.0f))) / m.attenuationDistance;
      if (glm::any(glm::greaterThan(absorption, glm::vec3(0.0f)))) flags |= gpu::kMatHasVolume;
    }
    float abbe = m.dispersion > 0.0f ? 20.0f / m.dispersion : 0.0f;
    if (abbe > 0.0f) flags |= gpu::kMatDispersive;
    gm.absorption = glm::vec4(absorption, abbe);
    gm.tex = glm::uvec4(m.baseColorTexture >= 0 ? static_cast<std::uint32_t>(m.baseColorTexture) : gpu::kInvalidIndex,
                        m.emissiveTexture >= 0 ? static_cast<std::uint32_t>(m.emissiveTexture) : gpu::kInvalidIndex,
                        flags, 0u);
    const auto texIndex = [](int t) { return t >= 0 ? static_cast<std::uint32_t>(t) : gpu::kInvalidIndex; };
    if (m.alphaFromTexture) gm.tex.z |= gpu::kMatAlphaTexture;
    if (m.alphaFromTexture && m.alphaCutoff >= 0.0f) gm.tex.z |= gpu::kMatAlphaMask;
    if (g.triShadeLayout.colors && m.alphaFromVertices) {  // COLOR_0's alpha joins factor and texture
      gm.tex.z |= gpu::kMatVertexAlpha;
      if (m.alphaCutoff >= 0.0f) {  // MASK: thresholded per hit, from the factor's own alpha
        gm.tex.z |= gpu::kMatAlphaMask;
        gm.baseColor.a = m.maskAlpha;
      }
    }
    gm.specular = glm::vec4(m.specularF0, m.specularF90);
    gm.tex2 = glm::uvec4(texIndex(m.metallicRoughnessTexture), texIndex(m.normalTexture),
                         floatBits(m.normalScale), floatBits(m.alphaCutoff));
    const bool coat = m.hasClearcoat(), sheen = m.hasSheen();
    gm.coat = coat ? glm::vec4(m.clearcoat, m.clearcoatRoughness, m.clearcoatNormalScale, 0.0f) : glm::vec4(0.0f);
    gm.sheen = sheen ? glm::vec4(m.sheenColor, m.sheenRoughness) : glm::vec4(0.0f);
    gm.tex3 = glm::uvec4(texIndex(coat ? m.clearcoatTexture : -1), texIndex(coat ? m.clearcoatRoughnessTexture : -1),
                         texIndex(coat ? m.clearcoatNormalTexture : -1), texIndex(sheen ? m.sheenColorTexture : -1));
    gm.tex4 = glm::uvec4(texIndex(sheen ? m.sheenRoughnessTexture : -1), texIndex(m.specularTexture),
                         texIndex(m.specularColorTexture), texIndex(m.transmissionTexture));
    const float r = (m.ior - 1.0f) / (m.ior + 1.0f);
    gm.specularBase = glm::vec4(r * r * m.specularColorFactor, m.specularFactor);
    g.materials.push_back(gm);
  }
  for (const SpotEmitter& e : scene.spotEmitters) {  // --light-radius spheres of spot lights
    if (e.material >= g.materials.size()) continue;
    gpu::Material& gm = g.materials[e.material];
    gm.absorption = glm::vec4(e.axis, e.cosOuter);
    gm.emission.w = e.cosInner;
    gm.tex.z |= gpu::kMatSpotEmitter;
  }
  g.punctual = packPunctualLights(scene.punctualLights, scene.bounds, scene.path);

  for (const Texture& t : scene.textures) {
    gpu::TexInfo info{};
    info.offset = static_cast<std::uint32_t>(g.texels.size());
    if (t.pixelSource >= 0) {  // a transformed reference: the texels of an earlier entry
      if (std::size_t(t.pixelSource) >= g.texInfo.size()) throw Error("internal: texture pixel source out of order");
      info.offset = g.texInfo[std::size_t(t.pixelSource)].offset;
    }
    info.uvRow0 = glm::vec4(t.uvRow0, 0.0f);
    info.uvRow1 = glm::vec4(t.uvRow1, 0.0f);
    info.width = static_cast<std::uint32_t>(t.width);
    info.height = static_cast<std::uint32_t>(t.height);
    info.flags = (t.repeatS ? 1u : 0u) | (t.repeatT ? 2u : 0u) | (t.mirrorS ? 4u : 0u) | (t.mirrorT ? 8u : 0u) |
                 (t.nearest ? 16u : 0u);
    for (size_t i = 0; i + 3 < t.rgba.size(); i += 4)
      g.texels.push_back(std::uint32_t(t.rgba[i]) | std::uint32_t(t.rgba[i + 1]) << 8 |
                         std::uint32_t(t.rgba[i + 2]) << 16 | std::uint32_t(t.rgba[i + 3]) << 24);
    g.texInfo.push_back(info);
  }

}

// packInstancedScene's steps, in order.

// Emissive triangles are numbered within their mesh (TriGeom.v1.w = that number + 1, the order of
// the light-leaf table): emissiveIndex per Scene triangle (kInvalidIndex: not emissive), and the
// count per mesh.
void numberMeshEmitters(const Scene& scene, std::vector<std::uint32_t>& emissiveIndex,
                        std::vector<std::uint32_t>& meshEmitters) {
  emissiveIndex.assign(scene.triangles.size(), gpu::kInvalidIndex);
  meshEmitters.assign(scene.meshes.size(), 0);
  for (std::size_t mi = 0; mi < scene.meshes.size(); ++mi) {
    const MeshRange& r = scene.meshes[mi];
    for (std::uint32_t i = r.firstTriangle; i < r.firstTriangle + r.triangleCount; ++i)
      if (scene.materials[scene.triangles[i].material].isEmissive()) emissiveIndex[i] = meshEmitters[mi]++;
  }
}

// The emissive and specular (caster) triangles of every instance are flattened on the host
// (transiently), bounded so that many placed emitters or glass objects cannot exhaust the host.
// Casters only speed up caustics: skipped beyond the bound. Sets g.casters and g.emitterSphere;
// returns the world-space emissive triangles, `source` naming each one's instance and stored triangle.
Scene flattenCastersAndLights(const Scene& scene, GpuScene& g, std::vector<InstancedTriangle>& source) {
  std::vector<bool> emissive(scene.materials.size()), specular(scene.materials.size());
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    emissive[m] = scene.materials[m].isEmissive();
    specular[m] = scene.materials[m].metallic > 0.0f || scene.materials[m].transmission > 0.0f;
  }
  constexpr std::uint64_t kMaxFlattened = 1u << 22;
  if (placedTriangles(scene, specular) <= kMaxFlattened)
    g.casters = findCausticCasters(flattenedSubset(scene, specular), CAUSTICA_MAX_CASTERS);
  if (placedTriangles(scene, emissive) > kMaxFlattened)
    throw Error(scene.path + ": the instances place " + std::to_string(placedTriangles(scene, emissive)) +
                " emissive triangles; the light tree takes at most " + std::to_string(kMaxFlattened) +
                " of an instanced scene (load it with --instances off)");
  Scene lights = flattenedSubset(scene, emissive, &source);
  g.emitterSphere = emitterBoundingSphere(lights);
  rateCastersForManifold(g.casters, lights);
  return lights;
}

// Stored triangles: object-space TriGeom (bvh.tris, moved into g) and TriShade words, in bvh.tris
// order. Returns each Scene triangle's stored index (kInvalidIndex: not stored).
std::vector<std::uint32_t> packStoredTriangles(const Scene& scene, InstancedBvh& bvh,
                                               const std::vector<std::uint32_t>& emissiveIndex, GpuScene& g) {
  g.triangleCount = bvh.tris.size();
  g.triGeom = std::move(bvh.tris);
  g.triShade.resize(g.triangleCount * g.triShadeStride);
  std::vector<std::uint32_t> storedIndex(scene.triangles.size(), gpu::kInvalidIndex);
  for (std::size_t x = 0; x < g.triangleCount; ++x) {
    const std::uint32_t i = bvh.triSource[x];
    storedIndex[i] = static_cast<std::uint32_t>(x);
    g.triGeom[x].v1.w = glm::uintBitsToFloat(emissiveIndex[i] == gpu::kInvalidIndex ? 0u : emissiveIndex[i] + 1u);
    writeTriShade(scene, i, g.triShadeLayout, g.triShade.data() + x * g.triShadeStride);
  }
  return storedIndex;
}

// Emitters: every emissive triangle of every instance, in world space as flattenInstances makes it.
void packInstancedEmitters(const Scene& scene, const Scene& lights, const std::vector<InstancedTriangle>& source,
                           const std::vector<std::uint32_t>& storedIndex, GpuScene& g) {
  std::vector<LightTreeItem> lightItems;
  double totalWeight = 0.0;
  for (std::size_t e = 0; e < lights.triangles.size(); ++e) {
    const Triangle& tri = lights.triangles[e];
    const Material& m = scene.materials[tri.material];
    if (!m.isEmissive()) continue;
    const double w = emitterWeight(m, tri.p);
    if (w == 0.0) continue;
    totalWeight += w;
    lightItems.push_back(emitterItem(storedIndex[source[e].triangle], tri.p, w, m.doubleSided));
    lightItems.back().instance = source[e].instance;
  }
  g.emitterCount = lightItems.size();
  g.lightTree = buildLightTree(std::move(lightItems), g.triangleCount);
  std::vector<std::uint32_t>().swap(g.lightTree.leafOf);  // per stored triangle: meaningless here
  g.totalEmitterWeight = static_cast<float>(totalWeight);
  g.totalPower = kPi * totalWeight;
}

// The light-leaf table: per instance of an emissive mesh, its emitters' leaves in emissiveIndex order;
// leafBase[i]: where instance i's entries start.
std::vector<std::uint32_t> lightLeafTable(const Scene& scene, const InstancedBvh& bvh, const GpuScene& g,
                                          const std::vector<std::uint32_t>& emissiveIndex,
                                          const std::vector<std::uint32_t>& meshEmitters,
                                          std::vector<std::uint32_t>& leafBase) {
  leafBase.assign(scene.instances.size(), 0);
  std::size_t tableSize = 0;
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    leafBase[i] = static_cast<std::uint32_t>(tableSize);
    tableSize += meshEmitters[scene.instances[i].mesh];
  }
  std::vector<std::uint32_t> table(tableSize, gpu::kInvalidIndex);
  for (std::size_t n = 0; n < g.lightTree.nodes.size(); ++n) {
    const glm::uvec4& link = g.lightTree.nodes[n].link;
    if ((link.y & gpu::kLightNodeLeaf) == 0u) continue;
    const std::uint32_t inst = link.y >> gpu::kLightNodeInstanceShift;
    table[leafBase[inst] + emissiveIndex[bvh.triSource[link.x]]] = static_cast<std::uint32_t>(n);
  }
  return table;
}

// Nodes (bvh.nodes, moved into g), then InstanceRecords (top-level leaf order), InstanceShades
// (Scene::instances order), the light-leaf table.
void packInstanceBlocks(const Scene& scene, InstancedBvh& bvh, const std::vector<std::uint32_t>& leafBase,
                        const std::vector<std::uint32_t>& table, GpuScene& g) {
  g.nodes = std::move(bvh.nodes);
  g.instanceCount = static_cast<std::uint32_t>(scene.instances.size());
  g.instanceRecordBase = static_cast<std::uint32_t>(g.nodes.size());
  const auto append = [&](const void* data, std::size_t bytes) {
    const std::size_t first = g.nodes.size();
    g.nodes.resize(first + (bytes + sizeof(gpu::BvhNode) - 1) / sizeof(gpu::BvhNode), gpu::BvhNode{});
    if (bytes) std::memcpy(static_cast<void*>(g.nodes.data() + first), data, bytes);
  };
  append(bvh.instances.data(), bvh.instances.size() * sizeof(gpu::InstanceRecord));
  std::vector<gpu::InstanceShade> shades(scene.instances.size());
  glm::dmat4 rebase0(1.0);
  rebase0[3] = glm::dvec4(-scene.origin, 1.0);
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& in = scene.instances[i];
    const glm::dmat4 w = rebase0 * in.world;
    gpu::InstanceShade& sh = shades[i];
    sh.row0 = glm::vec4(w[0][0], w[1][0], w[2][0], w[3][0]);
    sh.row1 = glm::vec4(w[0][1], w[1][1], w[2][1], w[3][1]);
    sh.row2 = glm::vec4(w[0][2], w[1][2], w[2][2], w[3][2]);
    sh.lightLeafBase = leafBase[i];
    sh.flags = glm::determinant(glm::dmat3(in.world)) < 0.0 ? gpu::kInstanceMirrored : 0u;
  }
  g.instancedTriangles = instancedTriangleCount(scene);
  append(shades.data(), shades.size() * sizeof(gpu::InstanceShade));
  g.lightLeafTableTexel = static_cast<std::uint32_t>(g.nodes.size() * (sizeof(gpu::BvhNode) / 16));
  append(table.data(), table.size() * sizeof(std::uint32_t));
  std::vector<gpu::InstanceRecord>().swap(bvh.instances);
}
}  // namespace

GpuScene packScene(const Scene& scene, const Bvh& bvh, bool triangleArrays) {
  GpuScene g;
  g.casters = findCausticCasters(scene, CAUSTICA_MAX_CASTERS);
  g.emitterSphere = emitterBoundingSphere(scene);
  rateCastersForManifold(g.casters, scene);
  packEnvironment(scene, g);
  g.nodes = bvh.nodes;
  g.triangleCount = bvh.order.size();
  setTriShadeLayout(scene, g);
  packMaterialsAndTextures(scene, g);

  // Emitters: every triangle whose material emits, weighted by luminance * area * sides.
  double totalWeight = 0.0;
  std::vector<LightTreeItem> lightItems;
  for (size_t i = 0; i < g.triangleCount; ++i) {
    const Triangle& tri = scene.triangles[bvh.order[i]];
    const Material& m = scene.materials[tri.material];
    if (!m.isEmissive()) continue;
    const double w = emitterWeight(m, tri.p);  // tri.p: TriGeom's vertices
    if (w == 0.0) continue;
    totalWeight += w;
    lightItems.push_back(emitterItem(static_cast<std::uint32_t>(i), tri.p, w, m.doubleSided));
  }
  // The light tree the shaders choose emitters with; each emissive triangle finds its leaf through
  // TriGeom.v1.w (leaf index + 1 as uint bits, 0: not in the tree).
  g.emitterCount = lightItems.size();
  g.lightTree = buildLightTree(std::move(lightItems), g.triangleCount);
  if (triangleArrays) packTriangleRange(scene, bvh, g, 0, g.triangleCount, g.triGeom, g.triShade);
  g.totalEmitterWeight = static_cast<float>(totalWeight);
  g.totalPower = kPi * totalWeight;
  return g;
}

GpuScene packInstancedScene(const Scene& scene, InstancedBvh& bvh) {
  if (bvh.triSource.size() != bvh.tris.size()) throw Error("internal: packInstancedScene without triSource");
  GpuScene g;
  setTriShadeLayout(scene, g);
  std::vector<std::uint32_t> emissiveIndex, meshEmitters;
  numberMeshEmitters(scene, emissiveIndex, meshEmitters);
  std::vector<InstancedTriangle> source;
  const Scene lights = flattenCastersAndLights(scene, g, source);
  packEnvironment(scene, g);
  packMaterialsAndTextures(scene, g);
  const std::vector<std::uint32_t> storedIndex = packStoredTriangles(scene, bvh, emissiveIndex, g);
  packInstancedEmitters(scene, lights, source, storedIndex, g);
  std::vector<std::uint32_t> leafBase;
  const std::vector<std::uint32_t> table = lightLeafTable(scene, bvh, g, emissiveIndex, meshEmitters, leafBase);
  packInstanceBlocks(scene, bvh, leafBase, table, g);
  return g;
}

glm::vec3 shadeNormal(const GpuScene& g, std::size_t tri, int k) {
  return octDecode(g.triShade[tri * g.triShadeStride + static_cast<std::size_t>(k)]);
}

glm::vec2 shadeUv(const GpuScene& g, std::size_t tri, int k) {
  if (!g.triShadeLayout.texcoords) return glm::vec2(0.0f);
  const std::uint32_t* w = g.triShade.data() + tri * g.triShadeStride + 3 + 2 * k;
  return glm::vec2(glm::uintBitsToFloat(w[0]), glm::uintBitsToFloat(w[1]));
}

glm::vec4 shadeColor(const GpuScene& g, std::size_t tri, int k) {
  if (!g.triShadeLayout.colors) return glm::vec4(1.0f);
  const std::uint32_t* w = g.triShade.data() + tri * g.triShadeStride + g.triShadeLayout.colorOffset() + 2 * k;
  return glm::vec4(glm::unpackHalf2x16(w[0]), glm::unpackHalf2x16(w[1]));
}

glm::vec4 shadeTangent(const GpuScene& g, std::size_t tri, int k) {
  if (!g.triShadeLayout.tangents) return glm::vec4(0.0f);
  return tangentFromWord(g.triShade[tri * g.triShadeStride + g.triShadeLayout.tangentOffset() + std::size_t(k)]);
}

std::vector<std::string> GpuScene::instanceDefines() const {
  if (instanceCount == 0) return {};
  return {"CAUSTICA_INSTANCED", "CAUSTICA_INSTANCE_RECORD_BASE=" + std::to_string(instanceRecordBase) + "u",
          "CAUSTICA_INSTANCE_COUNT=" + std::to_string(instanceCount) + "u",
          "CAUSTICA_LIGHT_LEAF_TABLE=" + std::to_string(lightLeafTableTexel) + "u"};
}

GpuSceneBytes gpuSceneBytes(const GpuScene& g) {
  GpuSceneBytes b;
  b.nodes = g.nodes.size() * sizeof(gpu::BvhNode);
  b.triGeom = g.triangleCount * sizeof(gpu::TriGeom);
  b.triShade = g.triangleCount * g.triShadeStride * 4;
  b.materials = g.materials.size() * sizeof(gpu::Material);
  b.lightTree = g.lightTree.nodes.size() * sizeof(gpu::LightNode);
  b.textures = (g.texels.size() + g.texInfo.size() * gpu::kTexInfoWords) * 4;
  return b;
}

}  // namespace caustica
