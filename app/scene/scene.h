// scene.h — the renderer's in-memory scene: world-space triangles, materials after the glTF
// material contract (docs/materials.md), textures and cameras. Loaded from glTF 2.0 by gltf_loader.cpp.
#pragma once
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/animation.h"
#include "scene/environment.h"
#include "scene/punctual_lights.h"
#include "shading/oct_normal.h"

namespace caustica {

// A base-colour or emissive texture, decoded to 8-bit RGBA (values as stored: sRGB-encoded colour).
struct Texture {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  // width * height * 4 bytes, row 0 = first row of the image (glTF uv v=0)
  bool repeatS = true, repeatT = true;      // glTF wrap: REPEAT (or MIRRORED_REPEAT with mirror*) else CLAMP
  bool mirrorS = false, mirrorT = false;    // MIRRORED_REPEAT
  bool nearest = false;                     // magFilter NEAREST
  // KHR_texture_transform of the reference that uses this entry: texture coordinates become
  // (dot(uvRow0, (u, v, 1)), dot(uvRow1, (u, v, 1))) before the lookup. A transformed reference gets
  // its own entry, which shares the texels of entry `pixelSource` (its rgba is then empty).
  glm::vec3 uvRow0{1.0f, 0.0f, 0.0f};
  glm::vec3 uvRow1{0.0f, 1.0f, 0.0f};
  int pixelSource = -1;
};

// Material after the contract in docs/materials.md. All colours linear.
struct Material {
  std::string name;
  glm::vec4 baseColor{1.0f};          // rgb: baseColorFactor, a: baseColorFactor.a (BLEND, MASK) or 1 (OPAQUE)
  int baseColorTexture = -1;          // index into Scene::textures, -1 = none
  float metallic = 0.0f;              // metal weight in [0,1]
  float roughness = 0.0f;             // glTF roughness in [0,1]; GGX alpha = roughness^2 (docs/materials.md). The glTF
                                      // loader always sets it (glTF's default is 1); 0 keeps C++-built metals and glass smooth
  int metallicRoughnessTexture = -1;  // index into Scene::textures (linear: B = metallic, G = roughness), -1 = none
  int normalTexture = -1;             // index into Scene::textures (linear, tangent space), -1 = none
  float normalScale = 1.0f;           // normalTexture.scale: scales the map's x and y
  // Dielectric specular layer over the diffuse base (glTF fresnel_mix): reflectance at normal and grazing
  // incidence. The glTF loader sets glTF's F0 = ((ior-1)/(ior+1))^2 (times KHR_materials_specular) and
  // F90 = specularFactor; F90 = 0 (the default of this struct) means a purely Lambertian base.
  glm::vec3 specularF0{0.0f};
  float specularF90 = 0.0f;
  int texCoord = 0;                   // the UV set (TEXCOORD_0 or TEXCOORD_1) every texture of the material reads
  bool alphaFromTexture = false;      // BLEND or MASK with a base-colour texture: its alpha multiplies baseColor.a
  bool alphaFromVertices = false;     // BLEND or MASK: COLOR_0's alpha multiplies baseColor.a (vertex colours)
  float alphaCutoff = -1.0f;          // alphaMode MASK: opaque where alpha >= cutoff, else absent; < 0: not MASK
  // MASK: baseColorFactor's alpha. Without a texture baseColor.a holds it already thresholded (0 or 1);
  // with vertex colours the threshold is taken per hit, of maskAlpha x COLOR_0's alpha.
  float maskAlpha = 1.0f;
  float transmission = 0.0f;          // KHR_materials_transmission: dielectric weight in [0,1]
  float ior = 1.5f;                   // KHR_materials_ior, at 587.6 nm
  float dispersion = 0.0f;            // KHR_materials_dispersion (20 / Abbe number), 0 = none
  glm::vec3 attenuationColor{1.0f};   // KHR_materials_volume
  float attenuationDistance = std::numeric_limits<float>::infinity();  // scene units; inf = no absorption
  glm::vec3 emission{0.0f};           // emissiveFactor * emissive_strength: emitted radiance (linear)
  int emissiveTexture = -1;           // index into Scene::textures, -1 = none
  bool doubleSided = false;
  // Textures of the factors above (indices into Scene::textures, -1 = none; linear unless said):
  // KHR_materials_transmission's transmissionTexture (R multiplies transmission) and
  // KHR_materials_specular's specularTexture (A multiplies specularFactor) and specularColorTexture
  // (RGB, sRGB, multiplies specularColorFactor). With either specular texture the GPU rebuilds F0 and
  // F90 per hit from the factors as written: specularColorFactor and specularFactor.
  int transmissionTexture = -1;
  int specularTexture = -1;
  int specularColorTexture = -1;
  glm::vec3 specularColorFactor{1.0f};
  float specularFactor = 1.0f;
  // KHR_materials_clearcoat: a GGX reflection of index 1.5 layered over the whole material, weighted
  // by clearcoat x its Schlick Fresnel (docs/materials.md). clearcoat = 0: no layer.
  float clearcoat = 0.0f;                // clearcoatFactor in [0, 1] (x clearcoatTexture R)
  float clearcoatRoughness = 0.0f;       // clearcoatRoughnessFactor (x clearcoatRoughnessTexture G); GGX alpha = r^2
  int clearcoatTexture = -1;
  int clearcoatRoughnessTexture = -1;
  int clearcoatNormalTexture = -1;       // the layer's own normal map (none: the interpolated normal)
  float clearcoatNormalScale = 1.0f;
  // KHR_materials_sheen: the Charlie sheen layered over the base (under the coat). Black: no layer.
  glm::vec3 sheenColor{0.0f};            // sheenColorFactor (linear; x sheenColorTexture RGB, sRGB)
  float sheenRoughness = 0.0f;           // sheenRoughnessFactor (x sheenRoughnessTexture A)
  int sheenColorTexture = -1;
  int sheenRoughnessTexture = -1;
  // KHR_materials_unlit: the loader has made the material an emitter of its base colour that reflects
  // nothing (emission = base colour factor, emissiveTexture = baseColorTexture, base colour black).
  bool unlit = false;

  bool isEmissive() const { return emission.r > 0.0f || emission.g > 0.0f || emission.b > 0.0f; }
  bool hasClearcoat() const { return clearcoat > 0.0f; }
  bool hasSheen() const { return sheenColor.r > 0.0f || sheenColor.g > 0.0f || sheenColor.b > 0.0f; }
  // Whether a texture scales transmission or the specular layer (CAUSTICA_FACTOR_TEXTURES).
  bool hasFactorTextures() const { return transmissionTexture >= 0 || specularTexture >= 0 || specularColorTexture >= 0; }
  // Whether any texture of the material is read (then its triangles need texture coordinates).
  bool readsTextures() const {
    return baseColorTexture >= 0 || emissiveTexture >= 0 || metallicRoughnessTexture >= 0 || normalTexture >= 0 ||
           hasFactorTextures() ||
           (hasClearcoat() && (clearcoatTexture >= 0 || clearcoatRoughnessTexture >= 0 || clearcoatNormalTexture >= 0)) ||
           (hasSheen() && (sheenColorTexture >= 0 || sheenRoughnessTexture >= 0));
  }
};

// One world-space triangle, 52 bytes: the scene model is the biggest thing the host holds for a big
// mesh (docs/big-scenes.md). Winding counter-clockwise seen from the front (glTF convention); the
// geometric normal is normalize(cross(p1 - p0, p2 - p0)). The shading normals are kept as the
// octahedral words the GPU reads (shading/oct_normal.h: within 4.3e-5 rad of the unit normal given);
// texture coordinates are not here but in Scene::texcoords, kept only where a texture reads them.
struct Triangle {
  glm::vec3 p[3];
  std::uint32_t normalWord[3] = {kOctNoNormal, kOctNoNormal, kOctNoNormal};  // octEncode'd unit shading normals
  std::uint32_t material = 0;

  // Corner k's unit shading normal, (0, 0, 0) when it has none (flat normals are stored as normals).
  glm::vec3 normal(int k) const { return octDecode(normalWord[k]); }
  void setNormal(int k, const glm::vec3& n) { normalWord[k] = octEncode(n); }
};
static_assert(sizeof(Triangle) == 52, "Triangle: 3 positions, 3 normal words, material");

// A triangle's texture coordinates: the material's UV set (TEXCOORD_0 or TEXCOORD_1, Material::texCoord).
struct TriangleUv {
  glm::vec2 uv[3]{glm::vec2(0.0f), glm::vec2(0.0f), glm::vec2(0.0f)};
};

// A triangle's vertex colours: COLOR_0 (linear RGB, and alpha), which multiplies its material's base
// colour and opacity (glTF 3.7.2.1). White where a primitive has none.
struct TriangleColors {
  glm::vec4 color[3]{glm::vec4(1.0f), glm::vec4(1.0f), glm::vec4(1.0f)};
};

// A triangle's vertex tangents (the file's TANGENT, world space): xyz unit, w the bitangent's sign
// (bitangent = cross(normal, xyz) * w); (0, 0, 0, 0) where the primitive has none (the normal map then
// takes the triangle's dp/du).
struct TriangleTangents {
  glm::vec4 tangent[3]{glm::vec4(0.0f), glm::vec4(0.0f), glm::vec4(0.0f)};
};

// A triangle with positions only: no normals, texture coordinates zero (OBJ meshes, tests, benchmarks).
inline Triangle makeTriangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, std::uint32_t material = 0) {
  Triangle t{};
  t.p[0] = a;
  t.p[1] = b;
  t.p[2] = c;
  t.material = material;
  return t;
}

// Pinhole or orthographic camera. Looks down -Z of its node in glTF; here stored in world space.
struct Camera {
  std::string name;
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // unit
  glm::vec3 up{0.0f, 1.0f, 0.0f};        // unit, orthogonal to forward
  float yfov = 0.7f;                      // vertical field of view, radians (pinhole)
  float aspect = 0.0f;                    // width / height from the file; 0 = take it from the image
  // Orthographic (glTF's ymag): half the image's height in scene units; rays leave the image plane
  // through `position` along `forward`, the width following the image's aspect. 0: a pinhole camera.
  float orthoHeight = 0.0f;
  bool orthographic() const { return orthoHeight > 0.0f; }
};

struct Bounds {
  glm::vec3 min{std::numeric_limits<float>::infinity()};
  glm::vec3 max{-std::numeric_limits<float>::infinity()};
  void grow(const glm::vec3& p) { min = glm::min(min, p); max = glm::max(max, p); }
  bool empty() const { return min.x > max.x; }
};

// Instancing (docs/instancing.md). A mesh stored once, in its own (object) space:
// Scene::triangles[firstTriangle, firstTriangle + triangleCount), in the file's winding.
struct MeshRange {
  std::uint32_t firstTriangle = 0;
  std::uint32_t triangleCount = 0;
  int gltfMesh = -1;  // index into the file's meshes, -1 when not from glTF
};

// One placement of a MeshRange. `world` maps object space to glTF world space (double, not rebased:
// a world position becomes float as vec3(dvec3(world * p) - Scene::origin), as the loader does).
struct Instance {
  std::uint32_t mesh = 0;  // index into Scene::meshes
  glm::dmat4 world{1.0};
};

struct Scene {
  std::string path;                  // file it was loaded from
  // World-space triangles, or (when `instances` is not empty) the meshes' object-space triangles.
  std::vector<Triangle> triangles;
  // Texture coordinates of triangles[i] at texcoords[i]; empty when no material reads a texture (24 B per
  // triangle saved), else exactly as long as `triangles`. Read them with triangleUv().
  std::vector<TriangleUv> texcoords;
  // Vertex colours of triangles[i] at colors[i]: empty unless some primitive has COLOR_0 (48 B per
  // triangle), else exactly as long as `triangles`. Read them with triangleColor().
  std::vector<TriangleColors> colors;
  // Vertex tangents of triangles[i] at tangents[i]: empty unless some normal-mapped primitive has
  // TANGENT, else exactly as long as `triangles`. Read them with triangleTangent().
  std::vector<TriangleTangents> tangents;
  // Empty unless loaded with LoadOptions::keepInstances: then every triangle belongs to exactly one
  // mesh and the scene is the union of its instances (flattenInstances makes it world space).
  std::vector<MeshRange> meshes;
  std::vector<Instance> instances;
  std::vector<Material> materials;   // never empty after loading (a default diffuse is added if needed)
  std::vector<Texture> textures;
  std::vector<Camera> cameras;       // perspective cameras in the default scene's node-visit order (may be empty)
  std::vector<std::string> warnings; // things skipped or approximated, each naming the file
  std::vector<PunctualLight> punctualLights;  // KHR_lights_punctual instances (punctual_lights.h)
  std::vector<SpotEmitter> spotEmitters;      // materials of spot lights made spheres by --light-radius
  Bounds bounds;
  // World-space position (glTF units, double) of this scene's float origin: for a scene farther from
  // the world origin than its own size, the loader subtracts its centre from every position and
  // camera before converting to float, so it keeps full float precision; 0 for other scenes.
  glm::dvec3 origin{0.0};
  // Light from infinity and what escaping camera rays see (scene/environment.h, docs/lighting.md).
  // Set from the command line (--env, --background), not from the file.
  Environment environment;
  Background background;
  // glTF animations (docs/animation.md): every animation of the file, and the ones the scene was posed
  // with (indices into `animations`; empty when the file has none) at animationTime seconds.
  std::vector<AnimationInfo> animations;
  std::vector<int> animationsPlayed;
  double animationTime = 0.0;
};

// Corner k's texture coordinates of triangle i; (0, 0) in a scene that keeps none.
inline glm::vec2 triangleUv(const Scene& s, std::size_t i, int k) {
  return s.texcoords.empty() ? glm::vec2(0.0f) : s.texcoords[i].uv[k];
}
// Corner k's vertex colour (linear RGBA) of triangle i; white in a scene without vertex colours.
inline glm::vec4 triangleColor(const Scene& s, std::size_t i, int k) {
  return s.colors.empty() ? glm::vec4(1.0f) : s.colors[i].color[k];
}
// Corner k's tangent of triangle i (xyz, sign w); zero in a scene without tangents.
inline glm::vec4 triangleTangent(const Scene& s, std::size_t i, int k) {
  return s.tangents.empty() ? glm::vec4(0.0f) : s.tangents[i].tangent[k];
}
// Whether a scene with these materials keeps texture coordinates (Scene::texcoords).
inline bool keepsTexcoords(const std::vector<Material>& materials) {
  for (const Material& m : materials)
    if (m.readsTextures()) return true;
  return false;
}

// Whether anything in the scene emits light: an emissive material on a triangle, a punctual light or
// an environment that emits.
inline bool sceneHasLights(const Scene& s) {
  if (!s.punctualLights.empty()) return true;
  for (const Triangle& t : s.triangles)
    if (t.material < s.materials.size() && s.materials[t.material].isEmissive()) return true;
  return s.environment.emits();
}

// What loadScene accepts from a scene file it does not trust (docs/untrusted-input.md). Each limit
// is checked before the memory it guards is spent; the defaults suit scenes up to a few GiB of GPU memory.
struct LoadOptions {
  // External files (buffers, images) must lie inside the scene file's folder, symlinks followed;
  // true also lets them lead elsewhere (absolute paths, '..', symlinks out).
  bool allowOutsidePaths = false;
  std::uint64_t maxTextureBytes = 1ull << 30;  // decoded RGBA8 texels of all images together
  std::uint64_t maxBufferBytes = 1ull << 30;   // sum of the buffers' declared byteLength
  std::uint64_t maxTriangles = 1ull << 24;     // triangles in the scene (GPU buffers: 112 B each)
  // Keep each glTF mesh once in object space and its node (and EXT_mesh_gpu_instancing) placements
  // as Scene::instances, instead of baking them into world-space copies. maxTriangles then bounds
  // the stored (object-space) triangles, not the instanced ones.
  bool keepInstances = false;
  // With keepInstances: keep them only where that pays, decided from the accessors' declared counts
  // before anything is decoded: when all instances together declare more than maxTriangles or more
  // than autoInstanceFactor x the stored meshes' triangles. Otherwise the scene loads flattened, exactly
  // as without keepInstances (`--instances auto`, docs/instancing.md).
  bool autoInstances = false;
  double autoInstanceFactor = 4.0;  // instanced traversal costs ~1.4x flattened (docs/instancing.md)
};

// Bakes an instanced scene (Scene::instances not empty) into world-space triangles, exactly as the
// loader would have without keepInstances (same order, winding, normals; zero-area triangles
// dropped), and empties meshes and instances. Does nothing to a scene without instances.
void flattenInstances(Scene& scene);

// Where a triangle of flattenedSubset came from.
struct InstancedTriangle {
  std::uint32_t instance = 0;  // Scene::instances index
  std::uint32_t triangle = 0;  // Scene::triangles index (object space)
};
// The world-space triangles (as flattenInstances makes them) of every instance whose material has
// materialWanted[material], in a scene with the materials, lights, bounds and origin but no textures:
// what the host-side passes over emitters and specular objects (light groups, caustic casters, the
// emitter sphere, the light tree) need from an instanced scene without flattening all of it. `source`,
// when given, receives one InstancedTriangle per triangle.
Scene flattenedSubset(const Scene& scene, const std::vector<bool>& materialWanted,
                      std::vector<InstancedTriangle>* source = nullptr);
// How many triangles flattenedSubset(scene, materialWanted) would make (zero-area ones included).
std::uint64_t placedTriangles(const Scene& scene, const std::vector<bool>& materialWanted);
// How many triangles the instances place in all (what flattenInstances makes, zero-area ones included).
std::uint64_t instancedTriangleCount(const Scene& scene);

// Loads a .gltf or .glb file posed at `pose` (its animations, morph-target weights and skins at that
// time; docs/animation.md). Throws caustica::Error("FILE: what is wrong") on any bad input.
Scene loadScene(const std::string& path, const LoadOptions& options, const ScenePose& pose);
// The same at time 0 of the default animation(s) (ScenePose{}), if the file has any.
Scene loadScene(const std::string& path, const LoadOptions& options);
// The same with the default LoadOptions.
Scene loadScene(const std::string& path);

// A scene file read once and posed at many times (render --frames): the parsed and checked document and
// its decoded images are kept; sceneAt builds the Scene exactly as loadScene(path, options, pose) would.
class SceneFile {
 public:
  SceneFile(const std::string& path, const LoadOptions& options);  // throws Error as loadScene does
  ~SceneFile();
  SceneFile(SceneFile&&) noexcept;
  SceneFile& operator=(SceneFile&&) noexcept;
  Scene sceneAt(const ScenePose& pose) const;
  const std::string& path() const;

 private:
  struct Document;
  std::unique_ptr<Document> doc_;
};

// A camera that frames the scene bounds (used when the file has none), looking down -Z.
Camera autoCamera(const Bounds& bounds);

}  // namespace caustica
