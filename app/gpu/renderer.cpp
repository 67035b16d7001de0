// renderer.cpp — scene upload, shader variants, dispatch and readback for the GPU path tracer.
#include "gpu/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "accel/bvh_wide.h"
#include "accel/tlas.h"
#include "gpu/denoiser.h"
#include "gpu/raster_renderer.h"
#include "util/error.h"
#include "util/hash.h"
#include "util/memory_stats.h"

namespace caustica {

gpu::PointLights pointLightParams(const std::vector<LightGroup>& groups, const std::vector<PunctualLight>& punctual,
                                  const Bounds& bounds) {
  gpu::PointLights pl{};
  // Distance from a light to the farthest corner of the scene: the shadow maps' far plane.
  auto farthest = [&](const glm::vec3& p) {
    float far = 0.0f;
    if (!bounds.empty())
      for (int c = 0; c < 8; ++c) {
        glm::vec3 corner((c & 1) ? bounds.max.x : bounds.min.x, (c & 2) ? bounds.max.y : bounds.min.y,
                         (c & 4) ? bounds.max.z : bounds.min.z);
        far = std::max(far, glm::length(corner - p));
      }
    return std::max(far * 1.01f, 1e-6f);
  };
  std::uint32_t n = 0;
  for (const LightGroup& g : groups) {
    if (n == CAUSTICA_MAX_POINT_LIGHTS) break;
    gpu::PointLight& l = pl.light[n++];
    l.position = glm::vec4(g.position, g.isotropic);
    l.intensity = glm::vec4(g.intensity, farthest(g.position));
    l.axis = glm::vec4(g.axis, 0.0f);
  }
  // KHR_lights_punctual lights take the slots the emitter groups leave (most powerful first as listed).
  // A directional light becomes a point light far away (100 scene radii) whose intensity gives the
  // light's irradiance at the scene's centre.
  const glm::vec3 centre = bounds.empty() ? glm::vec3(0.0f) : (bounds.min + bounds.max) * 0.5f;
  const float radius = bounds.empty() ? 1.0f : std::max(glm::length(bounds.max - bounds.min) * 0.5f, 1e-6f);
  for (const PunctualLight& p : punctual) {
    if (n == CAUSTICA_MAX_POINT_LIGHTS) break;
    gpu::PointLight& l = pl.light[n++];
    glm::vec3 pos = p.position, intensity = p.intensity;
    if (p.type == PunctualType::Directional) {
      float d = 100.0f * radius;
      pos = centre - p.direction * d;
      intensity *= d * d;
    }
    l.position = glm::vec4(pos, 1.0f);  // isotropic
    l.intensity = glm::vec4(intensity, farthest(pos));
    if (p.type == PunctualType::Spot) {
      l.position.w = 0.0f;
      l.axis = glm::vec4(p.direction, 0.0f);
      l.cone = glm::vec4(std::cos(p.outerCone), std::cos(p.innerCone), 1.0f, 0.0f);
    }
  }
  pl.count.x = n;
  return pl;
}

Renderer::~Renderer() = default;

namespace {

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// World-space bounds of everything in the binary tree (empty for an empty tree).
Bounds treeBounds(const std::vector<gpu::BvhNode>& nodes) {
  Bounds b;
  glm::vec3 lo, hi;
  if (bvhBounds(nodes, lo, hi)) {
    b.grow(lo);
    b.grow(hi);
  }
  return b;
}

}  // namespace

Renderer::Renderer(const ShaderLibrary& library, const Scene& scene, const Camera& camera, const RenderSettings& settings,
                   const RendererOptions& options)
    : library_(library), options_(options), settings_(settings), camera_(camera) {
  checkLimits();
  created_ = std::chrono::steady_clock::now();
  loadScene(scene);
  transparent_ = gpuScene_.environmentParams.size.z == gpu::kBackgroundTransparent;
  allocateImages();
  const auto t1 = std::chrono::steady_clock::now();
  prepareMode();  // compile now, so shader errors surface before rendering starts
  load_.compile = secondsSince(t1);
  memTrace("compiled");
  load_.ready = secondsSince(created_);
}

void Renderer::loadScene(const Scene& scene) {
  memTrace("renderer start");
  std::vector<gpu::BvhWideNode> wideNodes = buildScene(scene);
  // The light tracer's fixed-point step: 2^-24 of the brightest emission, so a splat as bright as an
  // emitter has 24 bits below it and 40 above it (light_trace.comp).
  float brightest = 0.0f;
  for (const Material& m : scene.materials) brightest = std::max({brightest, m.emission.r, m.emission.g, m.emission.b});
  lightSplatUnit_ = std::isfinite(brightest) && brightest > 0.0f ? brightest * 0x1p-24f : 1.0f;
  const Bounds sceneBounds = treeBounds(gpuScene_.nodes);
  planBuffers(scene);
  const auto t0 = std::chrono::steady_clock::now();
  uploadScene(scene, std::move(wideNodes));
  createUniformBuffers();
  uploadLights(scene, sceneBounds);
  glFinish();
  load_.upload = secondsSince(t0);
  memTrace("upload done");
}

void Renderer::setScene(const Scene& scene, const Camera& camera) {
  created_ = std::chrono::steady_clock::now();
  load_ = LoadTimes{};
  camera_ = camera;
  raster_.reset();  // the raster pipeline holds the previous scene's mesh
  causticCells_ = CausticCells();  // the photon cells are the previous scene's: program() builds the new ones
  causticGuides_ = CausticCells(CellTable::Guide);
  lightSplatTexture_ = GlBufferTexture();  // the light tracer's splats: sized for the next scene when it first runs
  lightSplats_ = GlBuffer();
  guideTableMask_ = 0;
  cellTableMask_ = 0;
  cellCasters_ = 0;
  loadScene(scene);
  const bool transparent = gpuScene_.environmentParams.size.z == gpu::kBackgroundTransparent;
  if (transparent != transparent_) {
    transparent_ = transparent;
    allocateImages();  // the coverage image comes or goes (and clears the others)
  }
  reset();
  const auto t1 = std::chrono::steady_clock::now();
  prepareMode();  // the scene's variant: compiled once, the same features find it in programs_
  load_.compile = secondsSince(t1);
  load_.ready = secondsSince(created_);
}

void Renderer::checkLimits() {
  limits_ = queryGlLimits();
  if (limits_.maxComputeStorageBlocks < CAUSTICA_SSBO_COUNT)
    throw Error("this GPU allows " + std::to_string(limits_.maxComputeStorageBlocks) +
                " storage buffers per compute shader; caustica needs " + std::to_string(CAUSTICA_SSBO_COUNT));
  if (limits_.maxWorkGroupInvocations < CAUSTICA_WORKGROUP_X * CAUSTICA_WORKGROUP_Y)
    throw Error("this GPU's compute work groups are too small");
  settings_.validate();
  checkImageSize(limits_, settings_.width, settings_.height);
}

std::vector<gpu::BvhWideNode> Renderer::buildScene(const Scene& scene) {
  auto t0 = std::chrono::steady_clock::now();
  std::vector<gpu::BvhWideNode> wideNodes;  // what traverse.glsl reads in flat scenes
  if (!scene.instances.empty()) {  // two-level BVH over the stored meshes (tlas.h, docs/instancing.md)
    InstancedBvh ib;
    if (options_.sceneUpdates) {
      // Animation sequences: the meshes' BVHs are kept while the stored triangles stay the same (a
      // rigid animation moves only instances), and only the top level is built again.
      std::uint64_t key = fnv1a64(scene.triangles.data(), scene.triangles.size() * sizeof(Triangle));
      key = fnv1a64(scene.meshes.data(), scene.meshes.size() * sizeof(MeshRange), key);
      if (!meshBvhs_ || meshBvhsKey_ != key) {
        meshBvhs_ = std::make_unique<MeshBvhs>(buildMeshBvhs(scene));
        meshBvhsKey_ = key;
        ++meshBvhBuilds_;
      }
      ib = placeInstances(scene, *meshBvhs_);
    } else {
      ib = buildInstancedBvh(scene);
    }
    bvhSeconds_ = load_.bvh = secondsSince(t0);
    bvh_.depth = ib.depth;
    t0 = std::chrono::steady_clock::now();
    gpuScene_ = packInstancedScene(scene, ib);
  } else {
    meshBvhs_.reset();
    const BvhShape shape = bvhShapeFromEnv();
    bvh_ = buildBvh(scene.triangles, shape.build);
    memTrace("bvh built");
    bvhSeconds_ = load_.bvh = secondsSince(t0);
    t0 = std::chrono::steady_clock::now();
    std::vector<gpu::BvhNode> nodes = std::move(bvh_.nodes);  // moved, not copied (packScene copies them)
    bvh_.nodes.clear();
    gpuScene_ = packScene(scene, bvh_, false);  // TriGeom and TriShade: packed in slices by the upload
    gpuScene_.nodes = std::move(nodes);
    wideNodes = packBvhWideNodes(gpuScene_.nodes, shape.collapse).nodes;
    memTrace("wide nodes");
  }
  load_.pack = secondsSince(t0);
  sceneFeatures_ = detectFeatures(scene, gpuScene_);
  return wideNodes;
}

void Renderer::planBuffers(const Scene& scene) {
  GpuScene& g = gpuScene_;
  // Flat scenes trace through the 4-wide nodes only (traverse.glsl), so the binary node buffer keeps
  // just the root there (~32 B per triangle less on the GPU). Instanced scenes trace the binary
  // two-level BVH (nodes, then instance records) and get an empty wide tree.
  if (scene.instances.empty()) {  // released, not only resized: the binary nodes' memory is free before the upload
    std::vector<gpu::BvhNode> root(g.nodes.begin(), g.nodes.begin() + std::min<std::ptrdiff_t>(std::ptrdiff_t(g.nodes.size()), 1));
    g.nodes.swap(root);
  }
  bufferLayout_ = planSceneBuffers(g, limits_, scene.path);  // throws before anything is uploaded
  gpuBytes_ = gpuSceneBytes(g);
}

void Renderer::uploadScene(const Scene& scene, std::vector<gpu::BvhWideNode> wideNodes) {
  GpuScene& g = gpuScene_;
  gpuBytes_.nodes += wideNodes.size() * sizeof(gpu::BvhWideNode);
  // The 4-wide nodes go up first and their host copy is freed before the triangle records' blocks are
  // made, so the two copies of the nodes and the triangle blocks are never held at once (on llvmpipe
  // the "GPU" copy is host memory: docs/big-scenes.md).
  const std::size_t wideCount = wideNodes.size();
  checkBufferTextureTexels(wideCount * (sizeof(gpu::BvhWideNode) / 16), scene.path);
  GlBuffer wideBuffer = wideNodes.empty() ? GlBuffer() : GlBuffer::fromVector(wideNodes);
  std::vector<gpu::BvhWideNode>().swap(wideNodes);
  releaseFreedMemory();  // the build's records and the binary nodes (glibc keeps freed heap otherwise)
  memTrace("wide nodes uploaded");
  uploadSceneBuffers(g, scene, bvh_, bufferLayout_, buffers_);  // frees g.nodes
  memTrace("scene buffers uploaded");
  bvhTextures_ = BvhTextures(buffers_[CAUSTICA_BINDING_NODES], bufferLayout_.nodes.count,
                             buffers_[CAUSTICA_BINDING_TRIGEOM], bufferLayout_.triGeom.count, scene.path,
                             std::move(wideBuffer), wideCount);
  shadingTextures_ = ShadingTextures(buffers_[CAUSTICA_BINDING_MATERIALS], buffers_[CAUSTICA_BINDING_EMITTERS],
                                     buffers_[CAUSTICA_BINDING_TEXELS],
                                     bufferLayout_.triShade.parts == 1 ? &buffers_[CAUSTICA_BINDING_TRISHADE] : nullptr,
                                     scene.path);
  memTrace("bvh textures");
  // Host copies the GPU holds now: the BVH's order (its statistics stay), the leaf map.
  std::vector<std::uint32_t>().swap(bvh_.order);
  std::vector<std::uint32_t>().swap(g.lightTree.leafOf);
}

void Renderer::createUniformBuffers() {
  frameUbo_ = GlBuffer::create(sizeof(gpu::FrameParams), nullptr, GL_DYNAMIC_DRAW);
  casterUbo_ = GlBuffer::create(sizeof(gpu::CasterParams), nullptr, GL_DYNAMIC_DRAW);
  punctualUbo_ = GlBuffer::create(sizeof(gpu::PunctualParams), &gpuScene_.punctual, GL_STATIC_DRAW);
  uploadCasters();
}

void Renderer::uploadLights(const Scene& scene, const Bounds& sceneBounds) {
  if (!scene.instances.empty()) {  // the point lights of Whitted and raster: from world-space copies of the emissive meshes
    std::vector<bool> emissive(scene.materials.size());
    for (std::size_t m = 0; m < scene.materials.size(); ++m) emissive[m] = scene.materials[m].isEmissive();
    lightGroups_ = groupEmitters(flattenedSubset(scene, emissive), CAUSTICA_MAX_POINT_LIGHTS);
  } else {
    lightGroups_ = groupEmitters(scene, CAUSTICA_MAX_POINT_LIGHTS);
  }
  pointLights_ = pointLightParams(lightGroups_, scene.punctualLights, sceneBounds);
  pointLightUbo_ = GlBuffer::create(sizeof pointLights_, &pointLights_, GL_STATIC_DRAW);
  environment_.upload(gpuScene_, limits_, scene.path);
}

void Renderer::prepareMode() {
  const RenderModeSpec& mode = renderModeSpec(settings_.mode);
  if (!mode.instancedScenes && gpuScene_.instanceCount > 0)
    throw Error(std::string(mode.name) + " mode draws flattened scenes only: load this scene with --instances off");
  if (mode.entryShader) {
    program();
  } else if (!raster_) {
    downloadSceneArrays(gpuScene_, bufferLayout_, buffers_);  // the raster mesh is built from them
    raster_ = std::make_unique<RasterRenderer>(library_, gpuScene_, pointLights_);
    std::vector<gpu::TriGeom>().swap(gpuScene_.triGeom);
    std::vector<std::uint32_t>().swap(gpuScene_.triShade);
  }
}

std::vector<std::string> Renderer::shaderDefines() const {
  std::vector<std::string> d = variantFeatures(sceneFeatures_, resolveManifold(settings_, gpuScene_), features_).defines();  // shader_features.cpp
  // The TriShade word layout and split (split_buffers.glsl, tri_shade.glsl) follow the data, also
  // under allFeatures (whose CAUSTICA_TEXTURES and CAUSTICA_VERTEX_COLORS must not make a scene without
  // texcoords or colours read them).
  for (const std::string& split : bufferLayout_.defines()) d.push_back(split);
  for (const std::string& inst : gpuScene_.instanceDefines()) d.push_back(inst);  // two-level traversal
  return d;
}

const GlProgram& Renderer::program() {
  std::vector<std::string> defines = shaderDefines();
  // The caustic photon pass of manifold NEE, once per scene and set of casters (manifoldCasterMask),
  // before the first variant with manifold NEE runs.
  auto has = [&](const char* d) { return std::find(defines.begin(), defines.end(), d) != defines.end(); };
  if ((!causticCells_.built() || cellCasters_ != manifoldCasterMask(settings_.manifold, gpuScene_)) && has("CAUSTICA_MANIFOLD"))
    buildCausticCells(CellTable::Manifold);
  // The guide photon pass, once per scene, before the first variant with caster guiding runs.
  if (!causticGuides_.built() && has("CAUSTICA_GUIDING")) buildCausticCells(CellTable::Guide);
  if (has("CAUSTICA_LIGHT_TRACE")) compiledProgram("light_trace.comp", defines);  // compiled with the variant: its errors surface here
  const char* entry = renderModeSpec(settings_.mode).entryShader;
  if (!entry) throw Error(std::string("internal: the ") + renderModeName(settings_.mode) + " mode has no compute shader");
  return compiledProgram(entry, defines);
}

const GlProgram& Renderer::compiledProgram(const char* entry, const std::vector<std::string>& defines) {
  std::string key = std::string(entry) + ":";
  for (const auto& d : defines) key += d + " ";
  auto it = programs_.find(key);
  if (it != programs_.end()) return it->second;
  ExpandedShader src = library_.expand(entry, defines);
  GlProgram p = GlProgram::compileCompute(src.source, [&](const std::string& log) { return src.mapLog(log); }, entry);
  return programs_.emplace(key, std::move(p)).first->second;
}

void Renderer::setFeatureBuffers(bool on) {
  if (on == features_) return;
  features_ = on;
  if (!on) {
    albedo_ = GlTexture();
    normal_ = GlTexture();
    return;
  }
  try {
    if (renderModeSpec(settings_.mode).pathTracer) program();  // compile now: errors surface here
    albedo_ = GlTexture::create2D(settings_.width, settings_.height, GL_RGBA32F);
    normal_ = GlTexture::create2D(settings_.width, settings_.height, GL_RGBA32F);
  } catch (...) {
    features_ = false;
    albedo_ = GlTexture();
    normal_ = GlTexture();
    throw;
  }
  reset();
}

void Renderer::setCamera(const Camera& camera) {
  camera_ = camera;
  reset();
}

SettingsChange Renderer::apply(const RenderSettings& settings) {
  settings.validate();
  SettingsChange change = compareSettings(settings_, settings);
  if (!change.restart) return change;
  // Another variant whenever a row of the feature table turns on or off, whichever field its settings
  // test reads.
  change.shader = change.shader || !(variantFeatures(sceneFeatures_, resolveManifold(settings_, gpuScene_)) ==
                                    variantFeatures(sceneFeatures_, resolveManifold(settings, gpuScene_)));
  if (change.resize) checkImageSize(limits_, settings.width, settings.height);
  const RenderSettings previous = settings_;
  settings_ = settings;
  try {
    if (change.shader) prepareMode();  // compile now: errors surface here, and callers may warm it up
  } catch (...) {
    settings_ = previous;
    throw;
  }
  if (change.resize) {
    try {
      allocateImages();
    } catch (...) {  // e.g. out of GPU memory: back to the previous settings and images
      settings_ = previous;
      allocateImages();
      throw;
    }
  }
  if (change.casters) uploadCasters();
  if (!change.resize) reset();
  return change;
}

void Renderer::buildCausticCells(CellTable table) {
  std::vector<std::string> defines = sceneFeatures_.only(FeatureKind::Scene).defines();  // materials as the scene needs
  for (const std::string& split : bufferLayout_.defines()) defines.push_back(split);
  for (const std::string& inst : gpuScene_.instanceDefines()) defines.push_back(inst);
  const GlProgram& photons = compiledProgram("caustic_photons.comp", defines);  // one program for both tables
  gpu::FrameParams fp{};
  fp.options = glm::uvec4(settings_.maxDepth, 0u, static_cast<std::uint32_t>(gpuScene_.emitterCount), 1u);  // lights.glsl reads the emitter count
  frameUbo_.update(0, sizeof fp, &fp);
  bindSceneForDispatch();
  gpu::CasterParams cp = casterParams();
  if (table == CellTable::Guide) {
    causticGuides_.build(photons, gpuScene_.lightTree, cp, [&](const gpu::CasterParams& built) {
      guideTableMask_ = built.guide.x;
      uploadCasters();
    });
  } else {
    cellCasters_ = cp.count.w;
    causticCells_.build(photons, gpuScene_.lightTree, cp, [&](const gpu::CasterParams& built) {
      cellTableMask_ = built.count.z;
      uploadCasters();
    });
  }
  checkGlError("caustic photon pass");
}

gpu::CasterParams Renderer::casterParams() const {
  gpu::CasterParams cp{};
  cp.count.z = cellTableMask_;
  cp.guide.x = guideTableMask_;
  cp.guide.y = guideCasterMask(gpuScene_);  // the guide photon pass's casters
  cp.guide.z = aimCasterMask(gpuScene_);    // the casters a bounce aims at
  cp.count.w = manifoldCasterMask(settings_.manifold, gpuScene_);  // the photon pass's casters
  cp.count.x = static_cast<std::uint32_t>(std::min<size_t>(gpuScene_.casters.size(), CAUSTICA_MAX_CASTERS));
  cp.params = glm::vec4(settings_.casterProbability, kCasterLightMargin, settings_.guideProbability, lightSplatUnit_);
  cp.lights = gpuScene_.emitterSphere;
  for (std::uint32_t i = 0; i < cp.count.x; ++i) {
    cp.sphere[i] = gpuScene_.casters[i].sphere;
    if (gpuScene_.casters[i].refractive) cp.count.y |= 1u << i;
  }
  return cp;
}

void Renderer::uploadCasters() {
  const gpu::CasterParams cp = casterParams();
  casterUbo_.update(0, sizeof cp, &cp);
}

void Renderer::allocateImages() {
  accum_ = GlTexture::create2D(settings_.width, settings_.height, GL_RGBA32F);
  comp_ = GlTexture::create2D(settings_.width, settings_.height, GL_RGBA32F);
  half_ = GlTexture::create2D(settings_.width, settings_.height, GL_RGBA32F);
  coverage_ = transparent_ ? GlTexture::create2D(settings_.width, settings_.height, GL_R32F) : GlTexture();
  albedo_ = features_ ? GlTexture::create2D(settings_.width, settings_.height, GL_RGBA32F) : GlTexture();
  normal_ = features_ ? GlTexture::create2D(settings_.width, settings_.height, GL_RGBA32F) : GlTexture();
  const int tiles = ((settings_.width + CAUSTICA_WORKGROUP_X - 1) / CAUSTICA_WORKGROUP_X) *
                    ((settings_.height + CAUSTICA_WORKGROUP_Y - 1) / CAUSTICA_WORKGROUP_Y);
  tileList_ = GlTexture::create2D(CAUSTICA_TILE_LIST_WIDTH, (tiles + CAUSTICA_TILE_LIST_WIDTH - 1) / CAUSTICA_TILE_LIST_WIDTH,
                                  GL_R32UI);
  display_ = GlTexture();
  reset();
}

void Renderer::reset() {
  accum_.clear();
  comp_.clear();
  half_.clear();
  if (transparent_) coverage_.clear();
  if (features_) {
    albedo_.clear();
    normal_.clear();
  }
  useAllTiles();
  lightCount_ = 0;
  spp_ = 0;
  sampleBase_ = 0;
  stats_ = RenderStats{};
  gpu::Counters zero{};
  buffers_[CAUSTICA_BINDING_COUNTERS].update(0, sizeof zero, &zero);
}

void Renderer::renderRows(int y0, int y1, int spp) {
  y0 = std::max(0, y0);
  y1 = std::min(settings_.height, y1);
  if (y1 <= y0 || spp <= 0) return;
  if (!renderModeSpec(settings_.mode).entryShader) {
    // The raster pipeline: one deterministic frame drawn straight into the accumulation image (alpha
    // = 1 sample), once per restart (SampleRule::OneFrame): later passes would only draw it again.
    if (spp_ == 0 && y0 == 0) {
      prepareMode();
      pointLightUbo_.bindBase(GL_UNIFORM_BUFFER, CAUSTICA_BINDING_POINT_LIGHTS);
      raster_->draw(camera_, accum_);
      glFinish();
    }
    return;
  }
  dispatchSamples(spp, y0, y1, false);
}

void Renderer::renderPass(int spp) {
  if (tileListActive_ && renderModeSpec(settings_.mode).samples != SampleRule::OneFrame) {  // one frame: no samples to spread
    if (liveTiles_ > 0 && spp > 0) dispatchSamples(spp, 0, settings_.height, true);
  } else {
    renderRows(0, settings_.height, spp);
  }
  endPass(spp);
}

void Renderer::setLiveTiles(const std::vector<std::uint32_t>& tiles, int tileSize) {
  if (tileSize != 1 && tileSize != 2 && tileSize != 4 && tileSize != 8) throw Error("internal: adaptive tile size must be 1, 2, 4 or 8");
  const std::size_t all = static_cast<std::size_t>((settings_.width + tileSize - 1) / tileSize) *
                          static_cast<std::size_t>((settings_.height + tileSize - 1) / tileSize);
  if (tiles.size() > all) throw Error("internal: more live tiles than the image has");
  const std::size_t capacity = static_cast<std::size_t>(tileList_.width()) * static_cast<std::size_t>(tileList_.height());
  if (all > capacity)  // smaller tiles than the list was made for (allocateImages: 8x8)
    tileList_ = GlTexture::create2D(CAUSTICA_TILE_LIST_WIDTH, static_cast<int>((all + CAUSTICA_TILE_LIST_WIDTH - 1) / CAUSTICA_TILE_LIST_WIDTH),
                                    GL_R32UI);
  tileList_.uploadR32uiRows(tiles);
  liveTiles_ = static_cast<std::uint32_t>(tiles.size());
  liveTileSize_ = tileSize;
  tileListActive_ = true;
}

void Renderer::useAllTiles() {
  tileListActive_ = false;
  liveTiles_ = 0;
}

std::size_t Renderer::liveTileCount() const {
  if (tileListActive_) return liveTiles_;
  return static_cast<std::size_t>((settings_.width + CAUSTICA_WORKGROUP_X - 1) / CAUSTICA_WORKGROUP_X) *
         static_cast<std::size_t>((settings_.height + CAUSTICA_WORKGROUP_Y - 1) / CAUSTICA_WORKGROUP_Y);
}

ErrorEstimate Renderer::errorEstimate(int tileSize) const {
  return estimateError(settings_.width, settings_.height, accum_.readRgba32f(), comp_.readRgba32f(), half_.readRgba32f(),
                       tileSize);
}

namespace {
// llvmpipe caps the iterations of all a shader's loops together at 65535 per SIMD group and silently
// leaves them beyond (docs/architecture.md). A dispatch of K samples per pixel runs at most
// K * (depth cap + pass-throughs) bounce iterations per lane, each with its traversal loops; one
// sample at the largest depth cap (1024) is the bound the deep tests (invisible sphere, glass cube in
// a furnace, depth 1024) check to lose no energy, so K samples get that bound and no more.
constexpr int kRegenBounceBudget = 1024;
constexpr int kDefaultSamplesPerDispatch = 4;  // docs/benchmarks.md, "Path regeneration"
constexpr int kMaxPassThroughs = 256;          // path_state.glsl's kMaxPassThroughs
// Bytes the light tracer's splats may take for the samples of one dispatch (24 per pixel each): 1080p
// keeps the default 4 samples per dispatch, larger images fewer (the image does not depend on it).
constexpr std::uint64_t kLightSplatBudget = 256ull << 20;
}  // namespace

int Renderer::samplesPerDispatch() const {
  if (renderModeSpec(settings_.mode).samples != SampleRule::Regeneration) return 1;
  const int wanted = settings_.samplesPerDispatch > 0 ? settings_.samplesPerDispatch : kDefaultSamplesPerDispatch;
  int perSample = settings_.maxDepth;
  const FeatureSet variant = variantFeatures(sceneFeatures_, resolveManifold(settings_, gpuScene_));
  if (variant.has("CAUSTICA_OPACITY")) perSample += kMaxPassThroughs;
  int k = std::max(1, std::min(wanted, kRegenBounceBudget / perSample));
  if (variant.has("CAUSTICA_LIGHT_TRACE")) {  // the light tracer's splats: one slot per sample of a dispatch, within a budget
    const std::uint64_t slotBytes = static_cast<std::uint64_t>(settings_.width) * static_cast<std::uint64_t>(settings_.height) *
                                    gpu::kLightSplatWords * 4u;
    const std::uint64_t budget = std::min<std::uint64_t>(kLightSplatBudget, static_cast<std::uint64_t>(limits_.maxStorageBlockSize));
    k = static_cast<int>(std::max<std::uint64_t>(1u, std::min<std::uint64_t>(static_cast<std::uint64_t>(k), budget / slotBytes)));
  }
  return k;
}

// Rows [y0, y1), or with `tiles` one work group per live tile; samplesPerDispatch() samples per pixel
// in each dispatch.
void Renderer::dispatchSamples(int spp, int y0, int y1, bool tiles) {
  const GlProgram& prog = program();
  const int w = settings_.width, h = settings_.height;
  float aspect = static_cast<float>(w) / static_cast<float>(h);
  float tanHalf = std::tan(0.5f * camera_.yfov);
  glm::vec3 fwd = glm::normalize(camera_.forward);
  glm::vec3 right = glm::normalize(glm::cross(fwd, camera_.up));
  glm::vec3 up = glm::cross(right, fwd);
  gpu::FrameParams fp{};
  fp.camPos = glm::vec4(camera_.position, 1.0f);
  // Pinhole: the image plane at distance 1; orthographic (camForward.w = 1): the plane through the
  // eye, orthoHeight above and below it (camera.glsl).
  const float halfHeight = camera_.orthographic() ? camera_.orthoHeight : tanHalf;
  fp.camRight = glm::vec4(right * halfHeight * aspect, 0.0f);
  fp.camUp = glm::vec4(up * halfHeight, 0.0f);
  fp.camForward = glm::vec4(fwd, camera_.orthographic() ? 1.0f : 0.0f);
  fp.tile = glm::uvec4(0, y0, w, y1 - y0);

  prog.use();
  bindSceneForDispatch();
  accum_.bindImage(CAUSTICA_IMAGE_ACCUM, GL_READ_WRITE);
  comp_.bindImage(CAUSTICA_IMAGE_COMP, GL_READ_WRITE);
  half_.bindImage(CAUSTICA_IMAGE_HALF, GL_READ_WRITE);
  tileList_.bindImage(CAUSTICA_IMAGE_TILES, GL_READ_ONLY);
  if (hasAlpha()) coverage_.bindImage(CAUSTICA_IMAGE_COVERAGE, GL_READ_WRITE);
  if (features_) {
    albedo_.bindImage(CAUSTICA_IMAGE_ALBEDO, GL_READ_WRITE);
    normal_.bindImage(CAUSTICA_IMAGE_NORMAL, GL_READ_WRITE);
  }
  // K samples per pixel per dispatch (samplesPerDispatch(): within llvmpipe's loop cap). Sample
  // indices stay global, so the image does not depend on how samples are split into dispatches.
  // The GPU's ray counters are 32-bit: read them into the 64-bit totals before they could wrap
  // (a sample traces at most 2 * maxDepth + 1 rays, plus one per alpha pass-through: at most 256).
  const std::uint64_t pixelsPerDispatch =
      tiles ? std::uint64_t(liveTiles_) * std::uint64_t(liveTileSize_ * liveTileSize_)
            : static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(y1 - y0);
  const std::vector<std::string> defines = shaderDefines();
  const bool lightTrace = std::find(defines.begin(), defines.end(), "CAUSTICA_LIGHT_TRACE") != defines.end();
  // (each light subpath: at most maxDepth - 1 bounce rays and as many eye connections)
  const std::uint64_t lightRays = lightTrace ? lightSubpaths() * 2u * settings_.maxDepth : 0u;
  const std::uint64_t raysPerSample = pixelsPerDispatch * (2u * settings_.maxDepth + 1u + 256u) + lightRays;
  // Tile lists: one work group per 64 / tileSize^2 live tiles (adaptive.glsl), on a 2D grid, since one
  // dimension may hold only 65535 groups.
  const GLuint tilesPerGroup = GLuint(CAUSTICA_WORKGROUP_X * CAUSTICA_WORKGROUP_Y / (liveTileSize_ * liveTileSize_));
  const GLuint liveGroups = (liveTiles_ + tilesPerGroup - 1) / tilesPerGroup;
  const GLuint groupsX = tiles ? std::min<GLuint>(liveGroups, 65535u) : GLuint((w + CAUSTICA_WORKGROUP_X - 1) / CAUSTICA_WORKGROUP_X);
  const GLuint groupsY = tiles ? (liveGroups + groupsX - 1) / groupsX : GLuint((y1 - y0 + CAUSTICA_WORKGROUP_Y - 1) / CAUSTICA_WORKGROUP_Y);
  const int perDispatch = samplesPerDispatch();
  const std::uint64_t samplesPerRead = std::max<std::uint64_t>(1, (1ull << 31) / raysPerSample);
  std::uint64_t sinceRead = 0;  // samples dispatched since the counters were last read
  fp.listed = glm::uvec4(GLuint(liveTileSize_), 0u, 0u, 0u);
  for (int s = 0; s < spp;) {
    const int k = static_cast<int>(std::min<std::uint64_t>({std::uint64_t(perDispatch), std::uint64_t(spp - s), samplesPerRead}));
    if (sinceRead + k > samplesPerRead) {
      readCounters();
      sinceRead = 0;
    }
    fp.frame = glm::uvec4(w, h, sampleBase_ + static_cast<std::uint32_t>(s), settings_.seed);
    fp.options = glm::uvec4(settings_.maxDepth, tiles ? liveTiles_ : 0u, static_cast<std::uint32_t>(gpuScene_.emitterCount), std::uint32_t(k));
    frameUbo_.update(0, sizeof fp, &fp);
    if (lightTrace) {
      traceLight(fp.frame.z, k, defines);
      prog.use();
    }
    glDispatchCompute(groupsX, groupsY, 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_UNIFORM_BARRIER_BIT);
    s += k;
    sinceRead += k;
  }
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  checkGlError("path tracing dispatch");
  readCounters();  // waits for the dispatches
  if (load_.firstPass == 0.0) load_.firstPass = std::chrono::duration<double>(std::chrono::steady_clock::now() - created_).count();
}

std::uint64_t Renderer::lightSubpaths() const {
  const double pixels = static_cast<double>(settings_.width) * static_cast<double>(settings_.height);
  const double n = std::min(std::round(pixels * static_cast<double>(settings_.lightPaths)), 2147483648.0);  // a uint uniform
  return std::max<std::uint64_t>(1u, static_cast<std::uint64_t>(n));
}

void Renderer::traceLight(std::uint32_t first, int k, const std::vector<std::string>& defines) {
  if (lightCount_ == k && lightFirst_ == first) {  // the same sample indices (another band of rows): the same splats
    lightSplatTexture_.bind(CAUSTICA_TEXUNIT_LIGHT_SPLATS);
    return;
  }
  const std::uint64_t pixels = static_cast<std::uint64_t>(settings_.width) * static_cast<std::uint64_t>(settings_.height);
  const std::uint64_t words = static_cast<std::uint64_t>(k) * pixels * gpu::kLightSplatWords;
  if (lightSplats_.size() < words * 4u) {
    if (words * 4u > static_cast<std::uint64_t>(limits_.maxStorageBlockSize))
      throw Error("light tracing at " + std::to_string(settings_.width) + "x" + std::to_string(settings_.height) + " needs " +
                  std::to_string(words * 4u >> 20) + " MiB of splats per sample, over this GPU's storage-block limit of " +
                  std::to_string(limits_.maxStorageBlockSize >> 20) + " MiB: render with --light-tracing off or a smaller image");
    checkBufferTextureTexels(words / 3u, "light tracing at this image size", "its splats need");
    lightSplats_ = GlBuffer::create(words * 4u, nullptr, GL_DYNAMIC_COPY);
    lightSplatTexture_ = GlBufferTexture::create(lightSplats_, GL_RGB32UI);
  }
  const GLuint zero = 0;
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, lightSplats_.id());
  glClearBufferSubData(GL_SHADER_STORAGE_BUFFER, GL_R32UI, 0, words * 4u, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
  const std::uint64_t subpaths = lightSubpaths();
  const GlProgram& lt = compiledProgram("light_trace.comp", defines);
  lt.use();
  glUniform1ui(0, static_cast<GLuint>(subpaths));
  lightSplats_.bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_LIGHT_SPLATS);
  const std::uint64_t groups = (subpaths + 63u) / 64u;
  const GLuint groupsX = static_cast<GLuint>(std::min<std::uint64_t>(groups, 65535u));
  const GLuint groupsY = static_cast<GLuint>((groups + groupsX - 1u) / groupsX);
  glDispatchCompute(groupsX, groupsY, static_cast<GLuint>(k));
  // The path tracer fetches the splats; the next light pass clears them (a buffer update after shader writes).
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
  static_assert(CAUSTICA_BINDING_LIGHT_SPLATS == CAUSTICA_BINDING_NODES, "the light pass borrows the nodes' binding");
  buffers_[CAUSTICA_BINDING_NODES].bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_NODES);  // the scene's again
  lightSplatTexture_.bind(CAUSTICA_TEXUNIT_LIGHT_SPLATS);
  lightFirst_ = first;
  lightCount_ = k;
  checkGlError("light tracing dispatch");
}

void Renderer::bindSceneForDispatch() {
  for (GLuint i = 0; i < buffers_.size(); ++i) buffers_[i].bindBase(GL_SHADER_STORAGE_BUFFER, i);
  frameUbo_.bindBase(GL_UNIFORM_BUFFER, CAUSTICA_BINDING_FRAME);
  casterUbo_.bindBase(GL_UNIFORM_BUFFER, CAUSTICA_BINDING_CASTERS);
  pointLightUbo_.bindBase(GL_UNIFORM_BUFFER, CAUSTICA_BINDING_POINT_LIGHTS);
  environment_.bind();
  bvhTextures_.bind();
  shadingTextures_.bind();
  causticCells_.bind();
  causticGuides_.bind();
  punctualUbo_.bindBase(GL_UNIFORM_BUFFER, CAUSTICA_BINDING_PUNCTUAL);
}

void Renderer::endPass(int spp) {
  spp_ += spp;
  sampleBase_ += static_cast<std::uint32_t>(spp);
}

void Renderer::readCounters() {
  gpu::Counters c{};
  GlBuffer& buf = buffers_[CAUSTICA_BINDING_COUNTERS];
  buf.read(0, sizeof c, &c);
  stats_.primaryRays += c.primaryRays;
  stats_.secondaryRays += c.secondaryRays;
  stats_.shadowRays += c.shadowRays;
  stats_.nonFinite += c.nonFinite;
  gpu::Counters zero{};
  buf.update(0, sizeof zero, &zero);
}

AccumulationState Renderer::saveAccumulation() const {
  AccumulationState st;
  st.width = settings_.width;
  st.height = settings_.height;
  st.spp = spp_;
  st.sampleBase = sampleBase_;
  st.accum = accum_.readRgba32f();
  st.comp = comp_.readRgba32f();
  st.half = half_.readRgba32f();
  if (transparent_) st.coverage = coverage_.readR32f();
  if (features_) {
    st.albedo = albedo_.readRgba32f();
    st.normal = normal_.readRgba32f();
  }
  return st;
}

void Renderer::restoreAccumulation(const AccumulationState& state) {
  const size_t n = static_cast<size_t>(settings_.width) * settings_.height * 4;
  if (state.width != settings_.width || state.height != settings_.height)
    throw Error("the saved accumulation is " + std::to_string(state.width) + "x" + std::to_string(state.height) +
                " but the renderer is " + std::to_string(settings_.width) + "x" + std::to_string(settings_.height));
  if (state.accum.size() != n || state.comp.size() != n || state.half.size() != n || state.spp < 0)
    throw Error("the saved accumulation is incomplete");
  if (transparent_ && state.coverage.size() != n / 4)
    throw Error("the saved accumulation has no coverage (alpha): it was not rendered with --background transparent");
  if (features_ && (state.albedo.size() != n || state.normal.size() != n))
    throw Error("the saved accumulation has no feature sums: it was rendered without --denoise or --aov");
  reset();
  accum_.uploadRgba32f(state.accum);
  comp_.uploadRgba32f(state.comp);
  half_.uploadRgba32f(state.half);
  if (transparent_) coverage_.uploadR32f(state.coverage);
  if (features_) {
    albedo_.uploadRgba32f(state.albedo);
    normal_.uploadRgba32f(state.normal);
  }
  spp_ = state.spp;
  sampleBase_ = state.sampleBase;
}

void Renderer::startAtSample(std::uint32_t index) {
  if (spp_ != 0) throw Error("internal: startAtSample on a render that has samples");
  sampleBase_ = index;
}

Image meanImage(int width, int height, const std::vector<float>& rgba, const std::vector<float>* coverage) {
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  Image img{width, height, std::vector<float>(pixels * 3)};
  for (size_t i = 0; i < pixels; ++i) {
    float n = rgba[i * 4 + 3];
    for (int c = 0; c < 3; ++c) img.rgb[i * 3 + c] = n > 0.0f ? rgba[i * 4 + c] / n : 0.0f;
  }
  if (coverage) {  // rgb stays the mean over all samples (misses add 0): premultiplied by alpha
    const std::vector<float>& hits = *coverage;
    img.alpha.resize(hits.size());
    for (size_t i = 0; i < hits.size(); ++i) {
      float n = rgba[i * 4 + 3];
      img.alpha[i] = n > 0.0f ? std::min(hits[i] / n, 1.0f) : 0.0f;
    }
  }
  return img;
}

Image Renderer::image() const { return meansOf(accum_.readRgba32f()); }

Image Renderer::meansOf(const std::vector<float>& rgba) const {
  if (!hasAlpha()) return meanImage(settings_.width, settings_.height, rgba, nullptr);
  const std::vector<float> hits = coverage_.readR32f();
  return meanImage(settings_.width, settings_.height, rgba, &hits);
}

const GlTexture& Renderer::denoise() {
  if (!canDenoise()) return accum_;
  if (!denoiser_) denoiser_ = std::make_unique<Denoiser>(library_);  // compiles its programs (not timed)
  glFinish();  // the work queued before (a sample pass) is not the filter's
  const auto t0 = std::chrono::steady_clock::now();
  const GlTexture& out = denoiser_->run(accum_, albedo_, normal_);  // returns when the GPU is done
  denoiseMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  denoiseMsTotal_ += denoiseMs_;
  return out;
}

Image Renderer::denoisedImage() { return meansOf(denoise().readRgba32f()); }

const GlTexture& Renderer::updateDisplay(const ToneMapSettings& tone, bool denoised) {
  const GlTexture& source = denoised ? denoise() : accum_;
  if (!tonemapProgram_.id()) {
    ExpandedShader src = library_.expand("tonemap.comp", {});
    tonemapProgram_ = GlProgram::compileCompute(src.source, [&](const std::string& log) { return src.mapLog(log); },
                                                "tonemap.comp");
  }
  if (display_.width() != settings_.width || display_.height() != settings_.height)
    display_ = GlTexture::create2D(settings_.width, settings_.height, GL_RGBA8);
  tonemapProgram_.use();
  glUniform1f(0, std::exp2(tone.exposureStops));
  glUniform1i(1, static_cast<int>(tone.curve));
  glUniform1i(2, hasAlpha() ? 1 : 0);  // composite over a checkerboard (tonemap.comp)
  source.bindImage(CAUSTICA_IMAGE_ACCUM, GL_READ_ONLY);
  if (hasAlpha()) coverage_.bindImage(CAUSTICA_IMAGE_COVERAGE, GL_READ_ONLY);
  display_.bindImage(CAUSTICA_IMAGE_DISPLAY, GL_WRITE_ONLY);
  glDispatchCompute((settings_.width + CAUSTICA_WORKGROUP_X - 1) / CAUSTICA_WORKGROUP_X,
                    (settings_.height + CAUSTICA_WORKGROUP_Y - 1) / CAUSTICA_WORKGROUP_Y, 1);
  glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
  checkGlError("tone mapping");
  return display_;
}

}  // namespace caustica
