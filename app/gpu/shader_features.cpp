// shader_features.cpp — the shader-feature table (shader_features.h says what each column decides)
// and the two questions asked of it: what a scene needs, and what one shader variant compiles.
#include "gpu/shader_features.h"

#include <algorithm>
#include <cmath>

#include "util/error.h"

namespace caustica {

namespace {
bool isGlass(const Material& m) { return m.transmission > 0.0f && m.metallic < 1.0f; }
bool isDispersive(const Material& m) { return isGlass(m) && m.dispersion > 0.0f; }
bool misHasLights(const SceneView& v) { return v.gpu.emitterCount > 0 || v.gpu.environment.width > 0; }
// COLOR_0's alpha reaches the opacity: vertex colours and a used BLEND or MASK material.
bool hasVertexAlpha(const SceneView& v) {
  if (v.scene.colors.empty()) return false;
  for (std::size_t m = 0; m < v.scene.materials.size(); ++m)
    if (v.usedMaterials[m] && v.scene.materials[m].alphaFromVertices) return true;
  return false;
}
}  // namespace

const std::vector<ShaderFeature>& shaderFeatureTable() {
  using K = FeatureKind;
  using A = AllFeatures;
  static const std::vector<ShaderFeature> table = {
      // ---- the scene's materials and lights (FeatureKind::Scene) ----
      {"mirror", "CAUSTICA_MIRROR", K::Scene, "metal: specular reflection (glsl/lib/materials.glsl)",
       "a material with metallic > 0", [](const Material& m) { return m.metallic > 0.0f; }, nullptr, nullptr,
       nullptr, A::Force},
      {"glass", "CAUSTICA_GLASS", K::Scene, "dielectric reflection and refraction, total internal reflection",
       "a material with transmission > 0 that is not all metal", isGlass, nullptr, nullptr, nullptr, A::Force},
      {"volume", "CAUSTICA_VOLUME", K::Scene, "Beer-Lambert absorption inside glass",
       "a glass material with a finite attenuation distance and an attenuation colour below 1",
       [](const Material& m) {
         return isGlass(m) && std::isfinite(m.attenuationDistance) && m.attenuationDistance > 0.0f &&
                glm::any(glm::lessThan(m.attenuationColor, glm::vec3(1.0f)));
       },
       nullptr, nullptr, nullptr, A::Force},
      {"dispersion", "CAUSTICA_DISPERSION", K::Scene, "wavelength-dependent index of refraction (KHR_materials_dispersion)",
       "a glass material with dispersion > 0", isDispersive, nullptr, nullptr, nullptr, A::Force},
      {"textures", "CAUSTICA_TEXTURES", K::Scene, "base-colour, emissive, metallic-roughness and normal textures",
       "a material that reads a texture", [](const Material& m) { return m.readsTextures(); }, nullptr, nullptr,
       nullptr, A::Force},
      {"opacity", "CAUSTICA_OPACITY", K::Scene, "alpha pass-through (BLEND and MASK)",
       "a material with base-colour alpha < 1 or alpha from its texture, or a BLEND or MASK material in a "
       "scene with vertex colours (their alpha)",
       [](const Material& m) { return m.baseColor.a < 1.0f || m.alphaFromTexture; }, hasVertexAlpha, nullptr,
       nullptr, A::Force},
      {"vertex-colors", "CAUSTICA_VERTEX_COLORS", K::Scene,
       "COLOR_0 multiplies the base colour (and in BLEND and MASK the opacity); tri_shade.glsl's colour block",
       "a primitive with COLOR_0", nullptr, [](const SceneView& v) { return !v.scene.colors.empty(); }, nullptr,
       nullptr, A::Force},
      {"environment", "CAUSTICA_ENV", K::Scene, "the environment light and background (glsl/lib/environment.glsl)",
       "an environment that emits, or a background other than it (--env, --background)", nullptr,
       [](const SceneView& v) {
         return v.scene.environment.emits() || v.scene.background.kind != Background::Kind::Environment;
       },
       nullptr, nullptr, A::Force},
      {"punctual", "CAUSTICA_PUNCTUAL", K::Scene, "next-event estimation of KHR_lights_punctual lights",
       "a punctual light", nullptr, [](const SceneView& v) { return v.gpu.punctual.count.x > 0; }, nullptr, nullptr,
       A::Force},
      {"spot-emitters", "CAUSTICA_SPOT_EMITTERS", K::Scene, "the spot cone of --light-radius spheres made from spot lights",
       "--light-radius with a spot light", nullptr,
       [](const SceneView& v) {
         for (const SpotEmitter& e : v.scene.spotEmitters)
           if (e.material < v.usedMaterials.size() && v.usedMaterials[e.material]) return true;
         return false;
       },
       nullptr, nullptr, A::Force},
      {"ggx", "CAUSTICA_GGX", K::Scene,
       "GGX lobes: rough metal, rough glass, specular layer over diffuse; folds away the lobes a scene lacks",
       "a rough metal or glass, a diffuse material with a specular layer (hasRoughLobe), a clear coat or a sheen",
       [](const Material& m) { return hasRoughLobe(m) || m.hasClearcoat() || m.hasSheen(); }, nullptr, nullptr,
       nullptr, A::Force},
      {"clearcoat", "CAUSTICA_CLEARCOAT", K::Scene,
       "the clear-coat layer (KHR_materials_clearcoat): a white mirror or GGX lobe on the coat's normal over the material",
       "a material with clearcoat > 0", [](const Material& m) { return m.hasClearcoat(); }, nullptr, nullptr, nullptr,
       A::Force},
      {"sheen", "CAUSTICA_SHEEN", K::Scene, "the sheen layer (KHR_materials_sheen): the Charlie sheen lobe over the base",
       "a material with a sheen colour above 0", [](const Material& m) { return m.hasSheen(); }, nullptr, nullptr,
       nullptr, A::Force},
      {"factor-textures", "CAUSTICA_FACTOR_TEXTURES", K::Scene,
       "the textures of KHR_materials_specular (specular, specular colour) and KHR_materials_transmission",
       "a material with a specular, specular-colour or transmission texture",
       [](const Material& m) { return m.hasFactorTextures(); }, nullptr, nullptr, nullptr, A::Force},
      // ---- what the image holds (FeatureKind::Image) ----
      {"transparent", "CAUSTICA_TRANSPARENT", K::Image, "the coverage image: alpha (glsl/lib/coverage.glsl)",
       "--background transparent in a mode that tracks coverage", nullptr,
       [](const SceneView& v) { return v.scene.background.kind == Background::Kind::Transparent; },
       [](const RenderSettings& s) { return renderModeSpec(s.mode).tracksCoverage; }, nullptr, A::Keep},
      // ---- the path tracer's estimators (FeatureKind::Integrator) ----
      {"mis", "CAUSTICA_MIS", K::Integrator, "next-event estimation with multiple importance sampling (else naive)",
       "--integrator mis and an emitter or an environment map", nullptr, misHasLights,
       [](const RenderSettings& s) { return s.integrator == Integrator::Mis; }, nullptr, A::Keep},
      {"casters", "CAUSTICA_CASTERS", K::Integrator, "diffuse bounces also aim at glass and mirror objects",
       "mis, a caustic caster to aim at (aimCasterMask: glass, or a mirror no large lamp lights) and "
       "--caster-probability > 0; beside light tracing only under small lamps, an environment map or punctual "
       "lights (resolveManifold)", nullptr,
       [](const SceneView& v) { return aimCasterMask(v.gpu) != 0u; },
       [](const RenderSettings& s) { return s.casterProbability > 0.0f; }, "CAUSTICA_MIS", A::Keep},
      {"guiding", "CAUSTICA_GUIDING", K::Integrator,
       "caster guiding: aimed bounces follow a direction lobe fitted to the caustic photons of a guide photon "
       "pass (glsl/lib/casters.glsl), at the first diffuse vertex where its cell has them",
       "casters, --guide-probability > 0 and a smooth caster the emitters look small from (as --manifold auto "
       "chooses: guideCasterMask)", nullptr,
       [](const SceneView& v) { return guideCasterMask(v.gpu) != 0u; },
       [](const RenderSettings& s) { return s.guideProbability > 0.0f; }, "CAUSTICA_CASTERS", A::Keep},
      {"manifold", "CAUSTICA_MANIFOLD", K::Integrator,
       "manifold next-event estimation: light joined to the first diffuse vertex through one glass or mirror "
       "caster (glsl/lib/path_manifold.glsl), after a caustic photon pass",
       "mis, a caustic caster, an emissive triangle and --manifold on, or --manifold auto (the default; "
       "resolveManifold) under --light-tracing off and a caster the emitters look small from "
       "(manifoldAutoEligible)", nullptr,
       [](const SceneView& v) { return !v.gpu.casters.empty() && v.gpu.emitterCount > 0; },
       [](const RenderSettings& s) { return s.manifold == ManifoldMode::On; }, "CAUSTICA_MIS", A::Keep},
      {"light-tracing", "CAUSTICA_LIGHT_TRACE", K::Integrator,
       "light tracing of caustics: light subpaths through glass and mirror objects splat the Lambertian points "
       "the camera sees (glsl/light_trace.comp), and eye paths leave those paths to them",
       "mis, a caustic caster, an emissive triangle, --light-tracing on (the default) and --manifold off or "
       "auto (the default: light tracing goes before manifold NEE, resolveManifold)", nullptr,
       [](const SceneView& v) { return !v.gpu.casters.empty() && v.gpu.emitterCount > 0; },
       [](const RenderSettings& s) { return s.lightTracing && s.manifold != ManifoldMode::On; }, "CAUSTICA_MIS", A::Keep},
      {"no-emitters", "CAUSTICA_NO_EMITTERS", K::Integrator,
       "leaves the emitter estimate and the emitter-hit pdf out of mis rather than run them masked on every "
       "bounce (llvmpipe runs every branch)",
       "mis without an emissive triangle (not under --all-features)", nullptr,
       [](const SceneView& v) { return v.gpu.emitterCount == 0; }, nullptr, "CAUSTICA_MIS", A::Drop},
      {"spectral", "CAUSTICA_SPECTRAL", K::Integrator, "dispersion by hero wavelengths (else one RGB channel per path)",
       "--dispersion spectral and a dispersive glass", isDispersive, nullptr,
       [](const RenderSettings& s) { return s.dispersion == DispersionMode::Spectral; }, nullptr, A::Keep},
      // ---- what the path tracer records beside the image (FeatureKind::Output) ----
      {"feature-buffers", "CAUSTICA_AOV", K::Output,
       "the denoiser's feature buffers: albedo, normal and distance of the first non-specular hit, the luminance "
       "moment (glsl/lib/feature_buffers.glsl)",
       "the renderer keeps feature buffers: render --denoise or --aov, the viewer's denoiser (Renderer::setFeatureBuffers)",
       nullptr, nullptr, nullptr, nullptr, A::Keep},
  };
  return table;
}

const char* featureKindName(FeatureKind k) {
  return k == FeatureKind::Scene ? "scene" : k == FeatureKind::Image ? "image" : k == FeatureKind::Integrator ? "integrator" : "output";
}

std::size_t shaderFeatureIndex(const std::string& define) {
  const auto& table = shaderFeatureTable();
  for (std::size_t i = 0; i < table.size(); ++i)
    if (define == table[i].define) return i;
  throw Error("internal: " + define + " is not in the shader-feature table (shader_features.cpp)");
}

FeatureSet FeatureSet::only(FeatureKind kind) const {
  FeatureSet out;
  const auto& table = shaderFeatureTable();
  for (std::size_t i = 0; i < table.size(); ++i) out.set(i, test(i) && table[i].kind == kind);
  return out;
}

std::vector<std::string> FeatureSet::defines() const {
  std::vector<std::string> out;
  const auto& table = shaderFeatureTable();
  for (std::size_t i = 0; i < table.size(); ++i)
    if (test(i)) out.push_back(table[i].define);
  return out;
}

std::string FeatureSet::describe() const {
  std::string s;
  const auto& table = shaderFeatureTable();
  for (std::size_t i = 0; i < table.size(); ++i)
    if (test(i) && table[i].kind == FeatureKind::Scene) s += (s.empty() ? "" : " ") + std::string(table[i].name);
  return s.empty() ? "diffuse only" : s;
}

FeatureSet detectFeatures(const Scene& scene, const GpuScene& gpu) {
  const std::vector<bool> used = usedMaterials(scene);
  const SceneView view{scene, gpu, used};
  FeatureSet f;
  const auto& table = shaderFeatureTable();
  for (std::size_t i = 0; i < table.size(); ++i) {
    const ShaderFeature& row = table[i];
    bool on = !row.material && !row.scene && row.kind != FeatureKind::Output;  // output rows: the Renderer's
    for (std::size_t m = 0; m < scene.materials.size() && row.material && !on; ++m)
      on = used[m] && row.material(scene.materials[m]);
    if (!on && row.scene) on = row.scene(view);
    f.set(i, on);
  }
  return f;
}

namespace {
bool modeCompiles(const RenderModeSpec& mode, FeatureKind kind) {
  return mode.entryShader && ((kind != FeatureKind::Integrator && kind != FeatureKind::Output) || mode.pathTracer);
}
}  // namespace

FeatureSet variantFeatures(const FeatureSet& scene, const RenderSettings& settings, bool featureBuffers) {
  const RenderModeSpec& mode = renderModeSpec(settings.mode);
  const bool all = settings.allFeatures && mode.pathTracer;
  FeatureSet f;
  const auto& table = shaderFeatureTable();
  for (std::size_t i = 0; i < table.size(); ++i) {
    const ShaderFeature& row = table[i];
    if (!modeCompiles(mode, row.kind)) continue;
    bool on = row.kind == FeatureKind::Output ? featureBuffers : scene.test(i) && (!row.settings || row.settings(settings));
    if (all && row.allFeatures != AllFeatures::Keep) on = row.allFeatures == AllFeatures::Force;
    if (on && row.needs) on = f.has(row.needs);
    f.set(i, on);
  }
  return f;
}

std::uint32_t manifoldCasterMask(ManifoldMode m, const GpuScene& g) {
  std::uint32_t mask = 0;
  const std::size_t n = std::min<std::size_t>(g.casters.size(), CAUSTICA_MAX_CASTERS);
  for (std::size_t i = 0; i < n; ++i)
    if (m == ManifoldMode::On || (m == ManifoldMode::Auto && g.casters[i].manifoldAuto)) mask |= 1u << i;
  return g.emitterCount > 0 ? mask : 0u;
}

std::uint32_t guideCasterMask(const GpuScene& g) { return manifoldCasterMask(ManifoldMode::Auto, g); }

std::uint32_t aimCasterMask(const GpuScene& g) {
  std::uint32_t mask = 0;
  const std::size_t n = std::min<std::size_t>(g.casters.size(), CAUSTICA_MAX_CASTERS);
  for (std::size_t i = 0; i < n; ++i)  // emitterSolidAngle: 0 without emissive triangles
    if (g.casters[i].refractive || g.casters[i].emitterSolidAngle < kManifoldAutoSolidAngle) mask |= 1u << i;
  return mask;
}

bool lightTracingCompiled(const RenderSettings& s, const GpuScene& g) {
  return s.lightTracing && s.integrator == Integrator::Mis && renderModeSpec(s.mode).pathTracer &&
         s.manifold != ManifoldMode::On && !g.casters.empty() && g.emitterCount > 0;
}

RenderSettings resolveManifold(RenderSettings s, const GpuScene& g) {
  // Beside light tracing eye paths aim at casters only where light tracing does not take the caustic (a first
  // diffuse vertex reached through glass or a mirror: path_scatter.glsl), and that pays only under small
  // lamps (the casters guiding takes), the environment or punctual lights: mirror-caustic's reflection of its
  // caustic had 17x the image's relMSE without it; under cornell-glass's large lamp it cost 9 %.
  if (lightTracingCompiled(s, g) && guideCasterMask(g) == 0u && g.environmentParams.size.x == 0 && g.punctual.count.x == 0)
    s.casterProbability = 0.0f;
  if (s.manifold == ManifoldMode::Auto) {
    // Light tracing first: it measured ahead of manifold NEE under small lamps too (docs/path-tracer.md).
    if (lightTracingCompiled(s, g)) s.manifold = ManifoldMode::Off;
    else s.manifold = manifoldCasterMask(ManifoldMode::Auto, g) != 0 ? ManifoldMode::On : ManifoldMode::Off;
  }
  return s;
}

FeatureSet modeFeatureRows(RenderMode m) {
  const RenderModeSpec& mode = renderModeSpec(m);
  FeatureSet f;
  const auto& table = shaderFeatureTable();
  for (std::size_t i = 0; i < table.size(); ++i) f.set(i, modeCompiles(mode, table[i].kind));
  return f;
}

}  // namespace caustica
