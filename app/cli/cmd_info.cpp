// cmd_info.cpp — `caustica info`: what a scene holds and what the renderer needs for it (no GL).
#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>

#include "cli/cli_common.h"
#include "cli/load_report.h"
#include "cli/commands.h"
#include "cli/environment_options.h"
#include "accel/bvh.h"
#include "accel/bvh_wide.h"
#include "util/error.h"
#include "accel/gpu_scene.h"
#include "accel/tlas.h"
#include "gpu/shader_features.h"
#include "shading/microfacet.h"

namespace caustica::cli {

namespace {
std::string materialKind(const Material& m) {
  std::string kind;
  const bool rough = m.roughness * m.roughness >= kDeltaAlpha;  // GGX lobes (docs/materials.md)
  if (m.metallic >= 1.0f) kind = rough ? "rough metal" : "mirror";
  else if (m.transmission > 0.0f) kind = m.transmission >= 1.0f && m.metallic <= 0.0f ? "glass" : "glass/diffuse mix";
  else if (m.metallic > 0.0f) kind = "mirror/diffuse mix";
  else kind = m.specularF90 > 0.0f ? "plastic (specular layer over diffuse)" : "diffuse";
  if (rough && m.transmission > 0.0f && m.metallic < 1.0f) kind += " (rough glass)";
  if (m.dispersion > 0.0f) kind += " +dispersion";
  if (m.hasSheen()) kind += " +sheen";
  if (m.hasClearcoat()) kind += " +clear coat";
  if (m.baseColor.a < 1.0f) kind += " +opacity";
  if (m.unlit) return "unlit (emits its base colour)" + std::string(m.baseColor.a < 1.0f ? " +opacity" : "");
  if (m.isEmissive()) kind = "emitter, " + kind;
  return kind;
}
std::string vec(const glm::vec3& v) {
  char b[96];
  std::snprintf(b, sizeof b, "(%.3g, %.3g, %.3g)", v.x, v.y, v.z);
  return b;
}
// The acceleration structure and packed scene `info` describes, as render builds them, with timings.
struct InfoBuild {
  bool instanced = false;  // --instances (docs/big-scenes.md)
  Bvh bvh;
  InstancedBvh ibvh;
  BvhShape shape;
  std::size_t topNodes = 0, allNodes = 0;  // of ibvh, before packing moves its nodes
  GpuScene g;
  double buildSeconds = 0.0, packSeconds = 0.0;
};

void buildAndPack(const Scene& s, InfoBuild& b) {
  auto t0 = std::chrono::steady_clock::now();
  b.instanced = !s.instances.empty();
  if (b.instanced) b.ibvh = buildInstancedBvh(s);
  b.shape = bvhShapeFromEnv();
  if (!b.instanced) b.bvh = buildBvh(s.triangles, b.shape.build);
  b.buildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  b.topNodes = b.ibvh.topNodeCount;
  b.allNodes = b.ibvh.nodes.size();
  t0 = std::chrono::steady_clock::now();
  // Flat scenes: the triangle records are not packed whole (as in render, which packs them in slices
  // straight into the GPU blocks); their sizes are still known (gpuSceneBytes).
  b.g = b.instanced ? packInstancedScene(s, b.ibvh) : packScene(s, b.bvh, /*triangleArrays=*/false);
  b.packSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// KHR_lights_punctual, with their share of the light choices (by power, punctual_lights.h).
void printPunctualLights(const Scene& s) {
  std::printf("punctual:   %zu light(s)%s\n", s.punctualLights.size(),
              s.punctualLights.empty() ? "" : " (point/spot: intensity in cd; directional: lux; chosen by power)");
  double totalPunctual = 0.0;
  for (const PunctualLight& l : s.punctualLights) totalPunctual += punctualPower(l, s.bounds);
  for (const PunctualLight& l : s.punctualLights) {
    std::string where = l.type == PunctualType::Directional ? "shining " + vec(l.direction) : "at " + vec(l.position);
    if (l.type == PunctualType::Spot) {
      char b[96];
      std::snprintf(b, sizeof b, " towards %s, cone %.1f-%.1f deg", vec(l.direction).c_str(), l.innerCone * 57.29578f,
                    l.outerCone * 57.29578f);
      where += b;
    }
    const double share = totalPunctual > 0.0 ? punctualPower(l, s.bounds) / totalPunctual : 0.0;
    std::printf("            %s '%s' %s, intensity %s, chosen %.3g of the time\n", punctualTypeName(l.type),
                l.name.c_str(), where.c_str(), vec(l.intensity).c_str(), share);
  }
}

// The lines from "scene:" to "origin:": what the scene holds.
void printContents(const Scene& s, const InfoBuild& b) {
  const GpuScene& g = b.g;
  std::printf("scene:      %s\n", s.path.c_str());
  std::printf("triangles:  %zu\n", s.triangles.size());
  std::printf("instances:  %s\n", b.instanced ? (instancesSummary(g) + " of " + std::to_string(s.meshes.size()) + " meshes").c_str()
                                              : instancesSummary(g).c_str());
  std::printf("emitters:   %zu triangles, total power %.4g (radiance x area x pi, scene units)\n", g.emitterCount,
              g.totalPower);
  std::printf("lighting:   %s\n", lightingSummary(s, g.emitterCount).c_str());
  printPunctualLights(s);
  std::map<std::string, int> kinds;
  for (const auto& m : s.materials) kinds[materialKind(m)]++;
  std::printf("materials:  %zu\n", s.materials.size());
  for (const auto& [k, n] : kinds) std::printf("            %d x %s\n", n, k.c_str());
  std::printf("textures:   %zu\n", s.textures.size());
  std::printf("animation:  %s\n", animationsSummary(s).c_str());
  std::printf("bounds:     %s to %s\n", vec(s.bounds.min).c_str(), vec(s.bounds.max).c_str());
  if (s.origin != glm::dvec3(0.0))  // far from the world origin: positions above are relative to it
    std::printf("origin:     (%.17g, %.17g, %.17g) (rebased in double; bounds and camera are relative to it)\n",
                s.origin.x, s.origin.y, s.origin.z);
}

void printCamera(const Scene& s, const Camera& c) {
  char view[64];
  if (c.orthographic()) std::snprintf(view, sizeof view, "orthographic, %g high", 2.0 * double(c.orthoHeight));
  else std::snprintf(view, sizeof view, "yfov %.1f deg", double(c.yfov) * 57.29578);
  std::printf("camera:     %s at %s looking %s, %s%s (%zu in file)\n",
              s.cameras.empty() ? "automatic" : ("'" + c.name + "'").c_str(), vec(c.position).c_str(),
              vec(c.forward).c_str(), view, c.aspect > 0 ? (", aspect " + std::to_string(c.aspect)).c_str() : "",
              s.cameras.size());
}

// The "bvh:" line(s); for a flat scene also collapses the 4-wide BVH the traversal reads and counts its
// nodes into `bytes` as the renderer uploads them.
void printBvh(const InfoBuild& b, GpuSceneBytes& bytes) {
  if (b.instanced) {
    std::printf("bvh:        two-level, %zu top-level + %zu mesh nodes, %u instance records (%zu KiB with the records), "
                "depth %d, built in %.1f ms\n", b.topNodes, b.allNodes - b.topNodes, b.g.instanceCount,
                b.g.nodes.size() * sizeof(gpu::BvhNode) / 1024, b.ibvh.depth, b.buildSeconds * 1e3);
    return;
  }
  const Bvh& bvh = b.bvh;
  std::printf("bvh:        %zu nodes (%zu KiB), %d leaves, depth %d, SAH cost %.2f, built in %.1f ms\n", bvh.nodes.size(),
              bvh.nodes.size() * sizeof(gpu::BvhNode) / 1024, bvh.leafCount, bvh.depth, bvh.sahCost, b.buildSeconds * 1e3);
  const auto tc = std::chrono::steady_clock::now();
  const BvhWide wide = packBvhWideNodes(bvh.nodes, b.shape.collapse);  // what the flat traversal reads
  const double collapseSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
  std::size_t slots = 0, leaves = 0;
  for (const gpu::BvhWideNode& n : wide.nodes)
    for (std::uint32_t ref : {n.child[0], n.child[1], n.child[2], n.child[3]})
      if (ref != gpu::kBvhEmptyRef) ++slots, leaves += (ref & gpu::kBvhLeafBit) != 0;
  std::printf("bvh 4-wide: %zu nodes (%zu KiB), %.2f children per node, %zu leaves, depth %d, stack need %d, "
              "collapsed in %.1f ms\n", wide.nodes.size(), wide.nodes.size() * sizeof(gpu::BvhWideNode) / 1024,
              double(slots) / double(wide.nodes.size()), leaves, wide.depth, wide.stackNeed, collapseSeconds * 1e3);
  bytes.nodes = wide.nodes.size() * sizeof(gpu::BvhWideNode) + sizeof(gpu::BvhNode);  // as the renderer uploads
}

// The "features:", "casters:" and "defines:" lines: what the shaders are compiled with for the scene.
void printFeatures(const Scene& s, const GpuScene& g) {
  const FeatureSet features = detectFeatures(s, g).only(FeatureKind::Scene);  // shader_features.cpp
  std::printf("features:   %s\n", features.describe().c_str());
  if (g.casters.empty()) std::printf("casters:    none (no glass or mirror object)\n");
  // Under the default settings (resolveManifold: beside light tracing, only where small lamps light a caster).
  const std::uint32_t aimed = resolveManifold(RenderSettings{}, g).casterProbability > 0.0f ? aimCasterMask(g) : 0u;
  for (size_t i = 0; i < g.casters.size(); ++i)
    std::printf("%s %s sphere at %s, radius %.3g; emitters subtend %.3g sr: %s, manifold auto %s\n",
                i == 0 ? "casters:   " : "           ", g.casters[i].refractive ? "glass " : "mirror",
                vec(glm::vec3(g.casters[i].sphere)).c_str(), g.casters[i].sphere.w, g.casters[i].emitterSolidAngle,
                (aimed & (1u << i)) != 0u ? "cone aimed at" : "cone not aimed at",
                g.casters[i].manifoldAuto ? "on (under --light-tracing off)" : !g.casters[i].smooth ? "off (rough)" : "off");
  if (lightTracingCompiled(RenderSettings{}, g))
    std::printf("caustics:   light tracing from the emissive triangles (the default; --manifold auto takes manifold NEE "
                "only under --light-tracing off)\n");
  std::string defines;
  for (const auto& d : features.defines()) defines += " " + d;
  for (const auto& d : g.instanceDefines()) defines += " " + d;  // the two-level traversal, as the renderer adds it
  std::printf("defines:   %s\n", defines.empty() ? " (none)" : defines.c_str());
}
}  // namespace

int cmdInfo(const std::vector<std::string>& args) {
  std::vector<OptionSpec> specs = {{"--camera", "", "N", "describe the scene's N-th camera (default 0)"}};
  for (OptionSpec& s : environmentOptionSpecs()) specs.push_back(std::move(s));
  for (OptionSpec& s : animationOptionSpecs()) specs.push_back(std::move(s));
  for (OptionSpec& s : sceneInputOptionSpecs()) specs.push_back(std::move(s));
  Options opts("caustica info SCENE [--camera N] [options]",
               "Prints triangles, emitters (count, total power), punctual lights, materials by kind, bounds, camera,\n"
               "animations (and the pose described), BVH statistics and the shader features the scene needs. Needs\n"
               "no GPU.",
               specs);
  if (!opts.parse(args)) return 0;
  if (opts.positional().empty()) throw Error("info needs a scene (a .gltf/.glb file or a bundled scene name)");
  const auto t0 = std::chrono::steady_clock::now();
  LoadedScene ls = loadSceneForCli(opts, true);
  const Scene& s = ls.scene;
  const double parseSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  InfoBuild b;
  buildAndPack(s, b);

  printContents(s, b);
  printCamera(s, ls.camera);
  GpuSceneBytes bytes = gpuSceneBytes(b.g);
  printBvh(b, bytes);
  std::printf("memory:     %s; %s\n", gpuBytesSummary(bytes, s.triangles.size()).c_str(),
              hostPeakSummary(s.triangles.size()).c_str());
  std::printf("load:       parse %.2f s, BVH %.2f s, pack %.2f s (upload and first sample: render's load line)\n",
              parseSeconds, b.buildSeconds, b.packSeconds);
  printFeatures(s, b.g);
  for (const auto& w : s.warnings) std::printf("warning:    %s\n", w.c_str());
  return 0;
}

}  // namespace caustica::cli
