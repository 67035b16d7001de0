// shader_features_test.cpp — the shader-feature table (app/gpu/shader_features.h): rows well formed,
// documented, read by the shaders and covering every feature #ifdef of the shaders; what a scene
// needs (detection); what a variant compiles under each mode and setting. (That every combination
// compiles: tests/gpu/shader_library_test.cpp.)
#include <doctest/doctest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "accel/bvh.h"
#include "gpu/denoiser.h"
#include "gpu/scene_buffers.h"
#include "gpu/shader_features.h"
#include "gpu/shader_library.h"
#include "scene/assets.h"
#include "util/error.h"

using namespace caustica;

namespace {

// A square of two triangles, side 2 * r, with material `material` at height y.
void addSquare(Scene& s, float y, std::uint32_t material, float r = 1.0f) {
  s.triangles.push_back(makeTriangle({-r, y, -r}, {r, y, r}, {r, y, -r}, material));
  s.triangles.push_back(makeTriangle({-r, y, -r}, {-r, y, r}, {r, y, r}, material));
  s.bounds.grow(glm::vec3(-r, y, -r));
  s.bounds.grow(glm::vec3(r, y, r));
}

// The features detectFeatures finds in `s` (packed as the Renderer packs it).
FeatureSet detect(const Scene& s) { return detectFeatures(s, packScene(s, buildBvh(s.triangles))); }

FeatureSet rows(std::initializer_list<const char*> defines) {
  FeatureSet f;
  for (const char* d : defines) f.set(shaderFeatureIndex(d), true);
  return f;
}

FeatureSet everyRow() {
  FeatureSet f;
  for (std::size_t i = 0; i < shaderFeatureTable().size(); ++i) f.set(i, true);
  return f;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : " ") + x;
  return s;
}

// The CAUSTICA_* names tested by a preprocessor conditional (#if, #ifdef, #ifndef, #elif) in `source`.
std::set<std::string> conditionalNames(const std::string& source) {
  static const std::regex conditional(R"(^\s*#\s*(if|ifdef|ifndef|elif)\b(.*)$)");
  static const std::regex name(R"(CAUSTICA_[A-Z0-9_]+)");
  std::set<std::string> out;
  std::istringstream in(source);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_match(line, m, conditional)) continue;
    const std::string rest = m[2].str();
    for (std::sregex_iterator it(rest.begin(), rest.end(), name), end; it != end; ++it) out.insert(it->str());
  }
  return out;
}

}  // namespace

TEST_CASE("shader features: the rows are well formed") {
  const auto& table = shaderFeatureTable();
  REQUIRE(table.size() <= kMaxShaderFeatures);
  std::set<std::string> names, defines;
  for (std::size_t i = 0; i < table.size(); ++i) {
    const ShaderFeature& row = table[i];
    CAPTURE(row.define);
    CHECK(names.insert(row.name).second);
    CHECK(defines.insert(row.define).second);
    CHECK(std::regex_match(std::string(row.define), std::regex("CAUSTICA_[A-Z0-9_]+")));
    CHECK(std::regex_match(std::string(row.name), std::regex("[a-z0-9-]+")));  // one word in `info`'s list
    CHECK(std::string(row.summary).size() > 10);
    CHECK(std::string(row.when).size() > 10);
    CHECK(shaderFeatureIndex(row.define) == i);
    if (row.needs) CHECK(shaderFeatureIndex(row.needs) < i);  // variantFeatures decides rows in order
    if (row.kind == FeatureKind::Scene) {
      // The scene alone decides it (info lists it without settings), and --all-features compiles every
      // scene feature in: the unspecialised shader the specialisation bench compares against.
      const bool sceneAlone = row.settings == nullptr;
      CHECK(sceneAlone);
      CHECK(row.allFeatures == AllFeatures::Force);
    }
  }
  CHECK_THROWS_WITH_AS(shaderFeatureIndex("CAUSTICA_NOPE"), doctest::Contains("not in the shader-feature table"), Error);
}

TEST_CASE("shader features: every row is documented in docs/shader-features.md, and every feature there is a row") {
  std::ifstream in(sourceDir() + "/docs/shader-features.md");
  REQUIRE(in);
  std::set<std::string> documented;  // defines in the first two columns of a table line: | name | `DEFINE` |
  static const std::regex line(R"(^\|\s*([a-z0-9-]+)\s*\|\s*`(CAUSTICA_[A-Z0-9_]+)`\s*\|.*)");
  std::set<std::string> lines;
  for (std::string l; std::getline(in, l);) {
    std::smatch m;
    if (!std::regex_match(l, m, line)) continue;
    documented.insert(m[2].str());
    lines.insert(m[1].str() + " " + m[2].str());
  }
  std::set<std::string> inTable;
  for (const ShaderFeature& row : shaderFeatureTable()) {
    CAPTURE(row.define);
    CHECK(lines.count(std::string(row.name) + " " + row.define) == 1);  // its name and define on one line
    inTable.insert(row.define);
  }
  for (const std::string& d : documented) {
    CAPTURE(d);
    CHECK(inTable.count(d) == 1);
  }
}

TEST_CASE("shader features: every row is read by a shader that compiles it, and every feature #ifdef of the shaders is a row") {
  ShaderLibrary library;
  // Names the data sets, not the table: the storage layout's (SceneBufferLayout::defines, here for a
  // split layout holding every TriShade block), the instanced traversal's (GpuScene::instanceDefines)
  // and the denoiser's stages (denoiseStageDefines).
  SceneBufferLayout layout;
  layout.shade.texcoords = layout.shade.colors = layout.shade.tangents = true;
  for (SplitArray* a : {&layout.nodes, &layout.triGeom, &layout.triShade}) {
    a->parts = 2;
    a->bindings = {7};
  }
  GpuScene instanced;
  instanced.instanceCount = 1;
  std::set<std::string> known;
  for (const std::vector<std::string>& list : {layout.defines(), instanced.instanceDefines()})
    for (const std::string& d : list) known.insert(d.substr(0, d.find('=')));
  for (const char* stage : denoiseStageDefines()) known.insert(stage);  // denoise.comp's stage selectors
  // And names the sources #define themselves (gpu_layout.h's constants, whitted.comp's occluder filter).
  static const std::regex defined(R"(#\s*define\s+(CAUSTICA_[A-Z0-9_]+))");
  for (const EmbeddedShader& s : embeddedShaders()) {
    const std::string text = s.source;
    for (std::sregex_iterator it(text.begin(), text.end(), defined), end; it != end; ++it) known.insert((*it)[1].str());
  }

  std::set<std::string> readByEntry;  // the rows' defines some entry shader that compiles them tests
  for (const RenderModeSpec& mode : renderModes()) {
    if (!mode.entryShader) continue;
    const std::set<std::string> tested = conditionalNames(library.expand(mode.entryShader, {}).source);
    const FeatureSet compiled = modeFeatureRows(mode.mode);
    for (const std::string& d : compiled.defines())
      if (tested.count(d)) readByEntry.insert(d);
  }
  for (const ShaderFeature& row : shaderFeatureTable()) {
    CAPTURE(row.define);
    CHECK(readByEntry.count(row.define) == 1);
    known.insert(row.define);
  }
  for (const EmbeddedShader& s : embeddedShaders()) {
    if (std::string(s.path).rfind("tests/", 0) == 0) continue;  // test entry shaders set their own
    for (const std::string& name : conditionalNames(s.source)) {
      INFO(std::string(s.path), ": #if on ", name, ": a feature #ifdef without a row in shader_features.cpp");
      CHECK(known.count(name) == 1);
    }
  }
}

TEST_CASE("shader features: detection from the materials some triangle uses and from the scene's lights") {
  Scene s;
  Material white, glass, mirror;
  glass.transmission = 1.0f;
  glass.dispersion = 0.5f;
  glass.attenuationColor = glm::vec3(0.5f, 1.0f, 0.25f);
  glass.attenuationDistance = 2.0f;
  mirror.metallic = 1.0f;
  s.materials = {white, glass, mirror};
  addSquare(s, 0.0f, 0);
  CHECK(detect(s).describe() == "diffuse only");
  CHECK(detect(s).only(FeatureKind::Scene).defines().empty());
  addSquare(s, 1.0f, 1, 0.1f);  // the mirror stays unused: no triangle has it
  CHECK(detect(s).describe() == "glass volume dispersion");
  CHECK(joined(detect(s).only(FeatureKind::Scene).defines()) == "CAUSTICA_GLASS CAUSTICA_VOLUME CAUSTICA_DISPERSION");
  CHECK(detect(s).has("CAUSTICA_SPECTRAL"));  // its scene side: a dispersive glass (the setting decides the rest)
  CHECK_FALSE(detect(s).has("CAUSTICA_MIS"));  // nothing emits
  s.materials[1].attenuationColor = glm::vec3(1.0f);  // no absorption, whatever the distance
  CHECK(detect(s).describe() == "glass dispersion");

  Material plastic;  // a specular layer over a textured, cut-out diffuse base
  plastic.specularF90 = 0.5f;
  plastic.baseColorTexture = 0;
  plastic.alphaFromTexture = true;
  Texture t;
  t.width = t.height = 1;
  t.rgba = {1, 2, 3, 4};
  s.textures = {t};
  s.materials.push_back(plastic);
  addSquare(s, 2.0f, 3);
  CHECK(detect(s).describe() == "glass dispersion textures opacity ggx");

  Material light;
  light.emission = glm::vec3(4.0f);
  s.materials.push_back(light);
  addSquare(s, 3.0f, 4);
  CHECK(detect(s).has("CAUSTICA_MIS"));
  CHECK_FALSE(detect(s).has("CAUSTICA_NO_EMITTERS"));
  CHECK(detect(s).has("CAUSTICA_CASTERS"));  // the small glass square is a caustic caster
  CHECK(detect(s).has("CAUSTICA_MANIFOLD"));  // a caster and an emitter: manifold NEE's scene side

  s.background = parseBackground("0.2");
  CHECK(detect(s).has("CAUSTICA_ENV"));
  CHECK_FALSE(detect(s).has("CAUSTICA_TRANSPARENT"));
  s.background = parseBackground("transparent");
  CHECK(detect(s).has("CAUSTICA_TRANSPARENT"));
  PunctualLight p;
  s.punctualLights = {p};
  CHECK(detect(s).has("CAUSTICA_PUNCTUAL"));
  CHECK_FALSE(detect(s).has("CAUSTICA_SPOT_EMITTERS"));
  s.spotEmitters = {SpotEmitter{4}};  // the light's material: used
  CHECK(detect(s).has("CAUSTICA_SPOT_EMITTERS"));
  CHECK(detect(s).describe() == "glass dispersion textures opacity environment punctual spot-emitters ggx");
}

TEST_CASE("shader features: caster aiming takes glass, and a mirror unless a large lamp lights it") {
  // aimCasterMask: under a large lamp a mirror's reflection of it is found by cosine sampling about as often
  // as by aiming at the mirror's cone (docs/path-tracer.md), so a scene whose only caster is such a mirror
  // does not compile caster aiming; under a small lamp, or with no emissive triangle, the mirror is aimed at.
  Material mirror, light;
  mirror.metallic = 1.0f;
  light.emission = glm::vec3(4.0f);
  for (float lamp : {1.0f, 0.01f}) {
    CAPTURE(lamp);
    Scene s;
    s.materials = {mirror, light};
    addSquare(s, 1.0f, 0, 0.1f);   // the mirror, above
    addSquare(s, 0.0f, 1, lamp);   // the lamp, facing up at it
    const GpuScene g = packScene(s, buildBvh(s.triangles));
    REQUIRE(g.casters.size() == 1);
    CHECK(aimCasterMask(g) == (lamp < 0.1f ? 1u : 0u));
    CHECK(detectFeatures(s, g).has("CAUSTICA_CASTERS") == (lamp < 0.1f));
    s.materials[0].transmission = 1.0f;  // glass instead: aimed at under either lamp
    s.materials[0].metallic = 0.0f;
    const GpuScene glass = packScene(s, buildBvh(s.triangles));
    CHECK(aimCasterMask(glass) == 1u);
    CHECK(detectFeatures(s, glass).has("CAUSTICA_CASTERS"));
  }
  Scene dark;  // a mirror without emissive triangles (lit by the sun, the environment or punctual lights)
  dark.materials = {mirror, Material{}};
  addSquare(dark, 1.0f, 0, 0.1f);
  addSquare(dark, 0.0f, 1);  // a floor: the mirror is a small object of the scene
  const GpuScene g = packScene(dark, buildBvh(dark.triangles));
  REQUIRE(g.casters.size() == 1);
  CHECK(aimCasterMask(g) == 1u);
}

// Light tracing (docs/path-tracer.md): compiled where a caster and an emissive triangle meet manifold NEE
// not on (--manifold off, or auto: light tracing goes first), never beside manifold NEE or naive; caster
// aiming stays compiled beside it under small lamps (it aims where the light tracer does not take the
// caustic). Auto takes manifold NEE only with --light-tracing off.
TEST_CASE("shader features: light tracing before manifold NEE under auto, never beside it; caster aiming beside it under small lamps") {
  Material glass, light;
  glass.transmission = 1.0f;
  light.emission = glm::vec3(4.0f);
  for (float lamp : {1.0f, 0.01f}) {  // a large lamp: auto finds no caster; a small one: auto takes the glass
    CAPTURE(lamp);
    Scene s;
    s.materials = {glass, light};
    addSquare(s, 1.0f, 0, 0.1f);
    addSquare(s, 0.0f, 1, lamp);
    const GpuScene g = packScene(s, buildBvh(s.triangles));
    const FeatureSet scene = detectFeatures(s, g);
    REQUIRE(scene.has("CAUSTICA_LIGHT_TRACE"));  // the scene's test: a caster and an emitter
    RenderSettings rs;
    const FeatureSet byDefault = variantFeatures(scene, resolveManifold(rs, g));
    CHECK(byDefault.has("CAUSTICA_LIGHT_TRACE"));
    CHECK_FALSE(byDefault.has("CAUSTICA_MANIFOLD"));
    CHECK(byDefault.has("CAUSTICA_CASTERS") == (lamp < 0.1f));  // beside it, aiming only under small lamps
    rs.manifold = ManifoldMode::Off;
    const FeatureSet off = variantFeatures(scene, resolveManifold(rs, g));
    CHECK(off.defines() == byDefault.defines());
    rs.manifold = ManifoldMode::On;
    const FeatureSet on = variantFeatures(scene, resolveManifold(rs, g));
    CHECK_FALSE(on.has("CAUSTICA_LIGHT_TRACE"));
    CHECK(on.has("CAUSTICA_MANIFOLD"));
    rs.manifold = ManifoldMode::Auto;
    rs.lightTracing = false;
    const FeatureSet eyeAuto = variantFeatures(scene, resolveManifold(rs, g));
    CHECK_FALSE(eyeAuto.has("CAUSTICA_LIGHT_TRACE"));
    CHECK(eyeAuto.has("CAUSTICA_MANIFOLD") == (lamp < 0.1f));
    CHECK(eyeAuto.has("CAUSTICA_CASTERS"));
    rs.lightTracing = true;
    rs.integrator = Integrator::Naive;
    CHECK_FALSE(variantFeatures(scene, resolveManifold(rs, g)).has("CAUSTICA_LIGHT_TRACE"));
  }
  Scene dark;  // glass without an emissive triangle: nothing to trace from
  dark.materials = {glass, Material{}};
  addSquare(dark, 1.0f, 0, 0.1f);
  addSquare(dark, 0.0f, 1);
  CHECK_FALSE(detect(dark).has("CAUSTICA_LIGHT_TRACE"));
}

// The layers cost nothing where no triangle uses them: a coat, a sheen or a factor texture switches
// its row on only through a material some triangle has (the shader reads the layer texels only then).
TEST_CASE("shader features: clear coat, sheen and factor textures only from a material some triangle uses") {
  Scene s;
  Material plain, coated, velvet, textured;
  plain.specularF90 = 1.0f;
  coated.clearcoat = 0.5f;
  velvet.sheenColor = glm::vec3(0.0f, 0.2f, 0.0f);
  textured.specularF90 = 1.0f;
  textured.transmissionTexture = 0;
  Texture t;
  t.width = t.height = 1;
  t.rgba = {255, 255, 255, 255};
  s.textures = {t};
  s.materials = {plain, coated, velvet, textured};
  addSquare(s, 0.0f, 0);
  const FeatureSet none = detect(s);
  CHECK(none.describe() == "ggx");
  for (const char* d : {"CAUSTICA_CLEARCOAT", "CAUSTICA_SHEEN", "CAUSTICA_FACTOR_TEXTURES"}) CHECK_FALSE(none.has(d));
  addSquare(s, 1.0f, 1);
  CHECK(detect(s).describe() == "ggx clearcoat");
  addSquare(s, 2.0f, 2);
  CHECK(detect(s).describe() == "ggx clearcoat sheen");
  addSquare(s, 3.0f, 3);
  CHECK(detect(s).describe() == "textures ggx clearcoat sheen factor-textures");
  // The bundled scenes without the extensions compile none of it; cornell-layers compiles both layers.
  for (const char* name : {"cornell-box", "cornell-glass", "cornell-materials", "cornell-textured", "sun-glass"}) {
    CAPTURE(std::string(name));
    const Scene b = loadScene(sourceDir() + "/assets/scenes/" + name + ".gltf");
    const FeatureSet f = detect(b);
    for (const char* d : {"CAUSTICA_CLEARCOAT", "CAUSTICA_SHEEN", "CAUSTICA_FACTOR_TEXTURES"}) CHECK_FALSE(f.has(d));
  }
  const FeatureSet layers = detect(loadScene(sourceDir() + "/assets/scenes/cornell-layers.gltf"));
  CHECK(layers.has("CAUSTICA_CLEARCOAT"));
  CHECK(layers.has("CAUSTICA_SHEEN"));
  CHECK_FALSE(layers.has("CAUSTICA_FACTOR_TEXTURES"));
}

TEST_CASE("shader features: an environment map alone turns mis on without the emitter estimate") {
  Scene s;
  s.materials = {Material{}};
  addSquare(s, 0.0f, 0);
  s.environment = uniformEnvironment(glm::vec3(1.0f));
  const FeatureSet f = detect(s);
  CHECK(f.has("CAUSTICA_ENV"));
  CHECK(f.has("CAUSTICA_MIS"));
  CHECK(f.has("CAUSTICA_NO_EMITTERS"));
  CHECK(joined(variantFeatures(f, RenderSettings{}).defines()) == "CAUSTICA_ENV CAUSTICA_MIS CAUSTICA_NO_EMITTERS");
}

TEST_CASE("shader features: a variant compiles the rows its mode reads, its settings ask for and their needs allow") {
  RenderSettings path;
  const FeatureSet lit = rows({"CAUSTICA_GLASS", "CAUSTICA_DISPERSION", "CAUSTICA_MIS", "CAUSTICA_CASTERS", "CAUSTICA_SPECTRAL"});
  CHECK(joined(variantFeatures(lit, path).defines()) == "CAUSTICA_GLASS CAUSTICA_DISPERSION CAUSTICA_MIS CAUSTICA_CASTERS");
  RenderSettings s = path;
  s.dispersion = DispersionMode::Spectral;
  CHECK(variantFeatures(lit, s).has("CAUSTICA_SPECTRAL"));
  s.casterProbability = 0.0f;
  CHECK_FALSE(variantFeatures(lit, s).has("CAUSTICA_CASTERS"));
  s = path;
  s.integrator = Integrator::Naive;  // no mis: no casters, no no-emitter variant (both need it)
  CHECK(joined(variantFeatures(everyRow(), s).defines()) ==
        "CAUSTICA_MIRROR CAUSTICA_GLASS CAUSTICA_VOLUME CAUSTICA_DISPERSION CAUSTICA_TEXTURES CAUSTICA_OPACITY "
        "CAUSTICA_VERTEX_COLORS CAUSTICA_ENV CAUSTICA_PUNCTUAL CAUSTICA_SPOT_EMITTERS CAUSTICA_GGX CAUSTICA_CLEARCOAT "
        "CAUSTICA_SHEEN CAUSTICA_FACTOR_TEXTURES CAUSTICA_TRANSPARENT");

  s = path;
  // Manifold NEE only when asked and only where the scene has a caster and an emitter: a scene without
  // casters compiles the same variant with --manifold on as off (it pays nothing).
  s = path;
  s.manifold = ManifoldMode::On;
  CHECK(variantFeatures(rows({"CAUSTICA_MIS"}), s) == variantFeatures(rows({"CAUSTICA_MIS"}), path));
  const FeatureSet caustic = rows({"CAUSTICA_GLASS", "CAUSTICA_MIS", "CAUSTICA_CASTERS", "CAUSTICA_MANIFOLD"});
  CHECK(joined(variantFeatures(caustic, s).defines()) == "CAUSTICA_GLASS CAUSTICA_MIS CAUSTICA_CASTERS CAUSTICA_MANIFOLD");
  // Auto is decided per scene by resolveManifold before the table is asked; unresolved it reads as off.
  CHECK_FALSE(variantFeatures(caustic, path).has("CAUSTICA_MANIFOLD"));
  s.integrator = Integrator::Naive;
  CHECK_FALSE(variantFeatures(caustic, s).has("CAUSTICA_MANIFOLD"));  // needs mis

  s.mode = RenderMode::Whitted;  // scene and image rows only; --all-features is the path tracer's
  s.allFeatures = true;
  s.dispersion = DispersionMode::Spectral;
  FeatureSet transparentGlass = lit;
  transparentGlass.set(shaderFeatureIndex("CAUSTICA_TRANSPARENT"), true);
  CHECK(joined(variantFeatures(transparentGlass, s).defines()) == "CAUSTICA_GLASS CAUSTICA_DISPERSION CAUSTICA_TRANSPARENT");
  s.mode = RenderMode::Raster;  // no compute variant
  CHECK(variantFeatures(everyRow(), s).defines().empty());
  s.mode = RenderMode::Path;
  CHECK(variantFeatures(transparentGlass, s).has("CAUSTICA_TRANSPARENT"));
}

TEST_CASE("shader features: --all-features compiles every scene row in, drops the no-emitter variant, keeps the rest") {
  RenderSettings all;
  all.allFeatures = true;
  const FeatureSet envOnly = rows({"CAUSTICA_ENV", "CAUSTICA_MIS", "CAUSTICA_NO_EMITTERS"});
  const FeatureSet f = variantFeatures(envOnly, all);
  for (const ShaderFeature& row : shaderFeatureTable()) {
    CAPTURE(row.define);
    const bool expected = row.kind == FeatureKind::Scene || std::string(row.define) == "CAUSTICA_MIS";
    CHECK(f.has(row.define) == expected);
  }
  all.dispersion = DispersionMode::Spectral;  // spectral needs a dispersive glass in the scene, forced or not
  CHECK_FALSE(variantFeatures(envOnly, all).has("CAUSTICA_SPECTRAL"));
  CHECK(variantFeatures(rows({"CAUSTICA_SPECTRAL"}), all).has("CAUSTICA_SPECTRAL"));
}

TEST_CASE("shader features: the output rows (the denoiser's feature buffers) follow the renderer, in the path tracer only") {
  RenderSettings path, whitted;
  whitted.mode = RenderMode::Whitted;
  const FeatureSet none = rows({});
  CHECK_FALSE(variantFeatures(none, path).has("CAUSTICA_AOV"));
  CHECK(variantFeatures(none, path, true).has("CAUSTICA_AOV"));
  CHECK_FALSE(variantFeatures(none, whitted, true).has("CAUSTICA_AOV"));  // whitted.comp records no features
  Scene s;
  CHECK_FALSE(detect(s).has("CAUSTICA_AOV"));  // never the scene's
}
