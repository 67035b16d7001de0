// gltf_internal.h — what the glTF loader's files (gltf_*.cpp) share: the limits on hostile input,
// message helpers, the JSON check, image decoding and SceneBuilder (tinygltf model -> Scene).
// Private to app/scene; the public API is loadScene / autoCamera in scene/scene.h.
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

// Third-party headers of the loader (JSON check, image decoding, tinygltf), their warnings silenced.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wshadow"
#include <nlohmann/json.hpp>
#include <stb_image.h>
#include <tiny_gltf.h>
#pragma GCC diagnostic pop

#include "util/error.h"
#include "scene/animation.h"
#include "scene/scene.h"

namespace caustica::gltf {

// ---- limits that keep hostile files from exhausting the stack or memory ------------------------
constexpr int kMaxJsonDepth = 64;                       // nesting of JSON arrays/objects
constexpr std::uint64_t kMaxIndex = 0x7fffffff;         // any glTF index (tinygltf stores int)
constexpr std::uint64_t kMaxByteCount = 1ull << 53;     // byte lengths/offsets (exact in a double)
constexpr std::uint64_t kMaxZeroElements = 1ull << 22;  // elements of an accessor without bufferView
constexpr std::uint64_t kMaxDecoded = 1ull << 28;       // accessor elements decoded for the whole scene
constexpr int kMaxTextureSide = 16384;                  // texels
constexpr std::int64_t kMaxTexturePixels = 1ll << 26;   // texels in one texture (256 MiB as RGBA8)
constexpr std::size_t kMaxMessage = 300;                // characters kept from a third-party message

// ---- messages (gltf_loader.cpp) ------------------------------------------------------------------
// A third-party message (tinygltf, nlohmann, stb) as one printable line: lines joined with "; ",
// control and non-ASCII bytes replaced, and the length bounded.
std::string oneLine(const std::string& text);
inline std::string str(std::uint64_t v) { return std::to_string(v); }
std::string num(double v);

// A byte count for messages: "1280 MiB", "1.5 MiB"; under 1 MiB "2048 bytes".
std::string mib(std::uint64_t bytes);

// ---- file references (gltf_loader.cpp) -----------------------------------------------------------
// Where external files (buffers, images) may come from: the scene's folder unless the options allow more.
struct FileAccess {
  std::string baseDir;             // the scene file's folder as given ("" = the current directory)
  std::filesystem::path folder;    // the same, absolute with symlinks resolved
  bool allowOutside = false;       // LoadOptions::allowOutsidePaths
};
// True when `file` (a path as the system would open it) resolves, symlinks followed, to a path inside
// access.folder (compared component by component), or when access.allowOutside.
bool insideFolder(const FileAccess& access, const std::filesystem::path& file);
// True when the percent-decoded relative URI `reference` is allowed: it is not absolute, does not
// climb out with '..' (both decided without touching the file system) and resolves inside the folder.
bool referenceAllowed(const FileAccess& access, const std::string& reference);

// ---- JSON structure check (gltf_json_check.cpp) --------------------------------------------------
// True for the extensions caustica implements (KHR_materials_*).
bool isSupportedExtension(const std::string& name);
// Rejects JSON nested deeper than kMaxJsonDepth, invalid JSON and documents whose structure tinygltf
// would not check (types, indices, byte ranges, buffer sources), external references that lead
// outside access.folder and buffers whose byteLengths add up to more than options.maxBufferBytes.
// binary: jsonText is a GLB's JSON chunk. Throws Error("PATH: ...").
// What the document holds that tinygltf cannot load as it stands (compressed geometry).
struct JsonFacts {
  std::vector<std::size_t> fallbackBuffers;  // buffers EXT_meshopt_compression marks as fallback (no data needed)
  struct DracoIndices {
    std::size_t mesh, primitive;
    int accessor;
  };
  std::vector<DracoIndices> dracoIndices;  // KHR_draco_mesh_compression primitives' indices accessors
  bool needsRewrite() const { return !fallbackBuffers.empty() || !dracoIndices.empty(); }
};
JsonFacts checkJson(const std::string& path, const std::string& jsonText, const FileAccess& access, bool binary,
                    const LoadOptions& options);

// ---- compressed geometry (gltf_compression.cpp) --------------------------------------------------
// The JSON text as tinygltf can load it: each EXT_meshopt_compression fallback buffer replaced by a
// one-byte placeholder (tinygltf would look for data such a buffer need not have; decodeMeshoptViews
// decodes its views from their compressed source), and the indices of Draco primitives left out
// (tinygltf refuses an indices accessor without a bufferView; restoreDracoIndices puts them back).
std::string tinygltfJson(const std::string& jsonText, const JsonFacts& facts);
void restoreDracoIndices(tinygltf::Model& model, const JsonFacts& facts);
// EXT_meshopt_compression: decodes every compressed buffer view (the meshopt vertex and index codecs
// and the octahedral, quaternion and exponential filters) into a buffer of its own and points the view
// at it. Refuses corrupt data, views of a fallback buffer that are not compressed, and decoded bytes
// beyond options.maxBufferBytes. Throws Error("PATH: ...").
void decodeMeshoptViews(const std::string& path, tinygltf::Model& model, const std::vector<std::size_t>& fallback,
                        const LoadOptions& options);

// The object of extension `name` in an extensions map, or nullptr (absent, or not an object).
inline const tinygltf::Value* extension(const tinygltf::ExtensionMap& map, const char* name) {
  const auto it = map.find(name);
  return it == map.end() || !it->second.IsObject() ? nullptr : &it->second;
}

// ---- byte access (gltf_accessors.cpp) ------------------------------------------------------------
// True when `count` elements of `elem` bytes, `stride` bytes apart, starting at `offset`, lie inside
// `length` bytes. Written without products that could overflow.
bool rangeFits(std::uint64_t offset, std::uint64_t stride, std::uint64_t count, std::uint64_t elem,
               std::uint64_t length);
// A little-endian 32-bit unsigned integer.
std::uint32_t readU32(const unsigned char* p);

// A component type with its normalized flag: one legal storage of an attribute.
struct Format {
  int componentType;
  bool normalized;
};
using Formats = std::vector<Format>;
// The storages glTF allows for a vertex attribute: FLOAT; TEXCOORD_n and COLOR_n also normalized
// unsigned byte and short. With KHR_mesh_quantization (`quantized`) also integer and normalized
// POSITION and TEXCOORD of every 8- and 16-bit type, and normalized byte and short NORMAL and TANGENT.
enum class VertexAttribute { Position, Normal, Tangent, Texcoord, Color };
const Formats& attributeFormats(VertexAttribute attribute, bool quantized);
extern const Formats kIndexFormats;
constexpr std::size_t kAnyCount = ~std::size_t(0);  // readAttribute: no vertex count to match (POSITION itself)
// "normalized UNSIGNED_BYTE", "FLOAT", ...
std::string formatName(int componentType, bool normalized);
// A stored integer component as glTF normalizes it (byte / 127 clamped to -1, ubyte / 255, ...);
// FLOAT and UNSIGNED_INT values unchanged.
double normalizedValue(double raw, int componentType);

// ---- image decoding (gltf_materials.cpp) ---------------------------------------------------------
// Decodes every image to 8-bit RGBA with stb_image. A failure is recorded rather than returned, so
// an unused broken image does not stop loading; using it is an error (SceneBuilder::texture).
struct ImageLog {
  std::map<int, std::string> failures;  // image index -> reason
  std::uint64_t budget = 0;             // LoadOptions::maxTextureBytes
  std::uint64_t declared = 0;           // RGBA8 bytes of the images met so far, by their headers
  std::string overBudget;               // set when an image would exceed the budget: loading fails
};

// tinygltf's image-loader callback; `user` is the ImageLog. An image whose header's size would take
// the decoded total over the budget is not decoded: it sets overBudget and returns false.
bool decodeImage(tinygltf::Image* image, int index, std::string*, std::string*, int, int, const unsigned char* bytes,
                 int size, void* user);

// ---- glTF model -> Scene -------------------------------------------------------------------------
struct NodeTransform {
  glm::dmat4 world{1.0};
  glm::dmat3 normal{1.0};  // inverse transpose of the upper 3x3
  bool flip = false;       // negative determinant: glTF then defines clockwise fronts
};

// How one mesh placement is posed (gltf_animation.cpp): its morph-target weights and its skin.
struct MeshPose {
  std::vector<double> weights;  // one per morph target of the mesh; empty or all zero: the base shape
  int skin = -1;                // skins[] index: vertices placed by their joints, the node's transform ignored
  bool posed() const {
    if (skin >= 0) return true;
    for (double w : weights)
      if (w != 0.0) return true;
    return false;
  }
};

// Converts a loaded tinygltf model into `scene`: materials, the default scene's node tree posed at
// `pose` (animations, morph weights, skins), cameras and world-space triangles. Its member functions
// are defined in gltf_nodes.cpp (build, the node walk, meshes, cameras), gltf_animation.cpp
// (animations, morph targets, skins), gltf_materials.cpp (materials, textures) and gltf_accessors.cpp
// (accessors).
class SceneBuilder {
 public:
  SceneBuilder(const std::string& path, const tinygltf::Model& model, const ImageLog& images,
               const LoadOptions& options, const ScenePose& pose, Scene& scene)
      : path_(path), model_(model), images_(images), options_(options), pose_(pose), scene_(scene) {}

  void build();

 private:
  [[noreturn]] void fail(const std::string& what) const { throw Error(path_ + ": " + what); }
  // Counts n more decoded accessor elements (accessors, Draco, meshopt) against kMaxDecoded.
  void countDecoded(std::uint64_t n);
  void warn(const std::string& what) { scene_.warnings.push_back(path_ + ": " + what); }

  void skip(const std::string& what) {
    if (firstSkip_.empty()) firstSkip_ = what;
    warn(what);
  }

  // Everything the file holds that caustica does not render, as one warning line (gltf_unsupported.cpp);
  // notRendered adds an entry found elsewhere (a material's textures).
  void warnNotRendered();
  void notRendered(const std::string& what);
  std::vector<std::string> notRendered_;

  // ---- materials (gltf_materials.cpp) ----
  double unit(double v, const std::string& what);
  Material convertMaterial(int index);
  // convertMaterial's steps, in order (gltf_materials.cpp): base colour, metal/roughness, normal map and
  // opacity; emission; transmission, ior and volume (`ignored` collects what is not rendered);
  // the dielectric specular layer; clear coat; sheen; the one UV set the material's textures read.
  void convertBasePbr(const tinygltf::Material& m, const std::string& at, Material& out);
  void convertEmission(const tinygltf::Material& m, const std::string& at, Material& out);
  void convertTransmission(const tinygltf::Material& m, const std::string& at, Material& out, std::string& ignored);
  void convertSpecular(const tinygltf::Material& m, const std::string& at, Material& out);
  void convertClearcoat(const tinygltf::Material& m, const std::string& at, Material& out);
  void convertSheen(const tinygltf::Material& m, const std::string& at, Material& out);
  void chooseMaterialTexCoord(const std::string& at, Material& out);
  std::set<int> materialTexCoords_;  // UV sets the textures of the material being converted name
  int texture(const tinygltf::TextureInfo& info, const std::string& at);
  int texture(const tinygltf::NormalTextureInfo& info, const std::string& at);
  // The texture an extension object names under `key` (a textureInfo, KHR_texture_transform included),
  // as texture() does for core references; -1 when absent.
  int extTexture(const tinygltf::Value* ext, const char* key, const std::string& at);
  std::uint32_t defaultMaterial(const std::string& at);

  // ---- animation (gltf_animation.cpp) ----
  // Reads every animation (for Scene::animations) and samples the chosen one(s) at pose_.time into
  // animatedTrs_ and animatedWeights_; names the chosen ones in Scene::animationsPlayed.
  void readAnimations();
  // readAnimations' steps, in order (gltf_animation.cpp).
  std::vector<bool> chooseAnimations();
  KeyframeCurve curveKeys(const tinygltf::AnimationSampler& sm, const std::string& sat,
                          std::map<int, std::vector<double>>& times);
  bool readCurveValues(const tinygltf::AnimationChannel& ch, const tinygltf::AnimationSampler& sm, const std::string& cat,
                       const std::string& sat, KeyframeCurve& curve);
  void applyAnimatedValue(const tinygltf::AnimationChannel& ch, const std::string& sat, const std::vector<double>& v,
                          std::set<int>& warnedMatrix);
  // The node's morph-target weights at the pose (animated, else node.weights, else mesh.weights).
  std::vector<double> nodeWeights(int nodeIndex, int mesh, const std::string& at);
  // World matrices of every node (needed by skins, whose joints may lie anywhere in the tree).
  void computeNodeWorlds(const std::vector<int>& parent);
  // skin's joint matrices world(joint) * inverseBindMatrix at the pose (cached per skin).
  const std::vector<glm::dmat4>& jointMatrices(int skin, const std::string& at);
  // Positions and normals of one primitive morphed by pose.weights (targets read and checked here).
  void morphPrimitive(const tinygltf::Primitive& prim, const MeshPose& pose, std::size_t vertexCount,
                      std::vector<double>& positions, std::vector<double>& normals, const std::string& at);
  // Positions and normals of one primitive placed by its skin (world space); mirrored[v]: the vertex's
  // skin matrix has a negative determinant.
  void skinPrimitive(const tinygltf::Primitive& prim, int skin, std::size_t vertexCount, std::vector<double>& positions,
                     std::vector<double>& normals, std::vector<bool>& mirrored, const std::string& at);
  std::map<int, NodeTrs> animatedTrs_;                 // node -> its TRS at the pose (animated nodes only)
  std::map<int, std::vector<double>> animatedWeights_;  // node -> its morph weights at the pose
  std::vector<glm::dmat4> nodeWorld_;                   // computeNodeWorlds
  std::map<int, std::vector<glm::dmat4>> jointMatrices_;
  std::set<std::string> warnedMorphAttributes_;

  // ---- node hierarchy (gltf_nodes.cpp) ----
  glm::dmat4 localMatrix(const tinygltf::Node& node, const std::string& at);
  glm::dmat4 localMatrix(int nodeIndex, const std::string& at);  // with the animation's TRS, if any
  std::vector<int> checkHierarchy();
  void traverse();  // fills cameraInstances_ and meshInstances_
  // Refuses a scene whose mesh instances declare more than options_.maxTriangles triangles (from
  // accessor counts), before any accessor is decoded.
  void checkTriangleCount();  // also reserves the triangles
  // Triangles mesh `mesh`'s primitives declare (accessor counts; 0 for a bad index).
  std::uint64_t declaredTriangles(int mesh) const;
  // LoadOptions::autoInstances: whether keeping the instances pays, from the declared counts.
  bool instancingPays() const;
  // The world-space point (scene units, double) that becomes the float origin: for a scene farther
  // from the world origin than its size, the centre of the meshes' bounds from their POSITION
  // accessors' min/max (node origins where those are missing); else 0.
  glm::dvec3 chooseOrigin() const;
  void addCamera(int index, const glm::dmat4& world, const tinygltf::Node& node, const std::string& at);
  // KHR_lights_punctual (gltf_lights.cpp): the light a node places, if any (-1 = none), and its instance.
  int nodeLight(const tinygltf::Node& node) const;
  void addLight(int index, const glm::dmat4& world, const std::string& at);

  // ---- accessors (gltf_accessors.cpp) ----
  // KHR_draco_mesh_compression: a primitive's decoded attributes (glTF names) and indices, each as
  // readAccessor would return them from uncompressed data (gltf_compression.cpp).
  struct DracoPrimitive {
    std::map<std::string, std::vector<double>> attributes;
    std::vector<double> indices;
    bool indexed = false;
  };
  DracoPrimitive decodeDraco(const tinygltf::Primitive& prim, const std::string& at);
  const DracoPrimitive* draco_ = nullptr;  // the primitive being assembled, when Draco-compressed
  bool quantized_ = false;                 // KHR_mesh_quantization is used: attributeFormats' wider list
  // The accessor's type and (componentType, normalized) checked against the legal ones for `use`.
  const tinygltf::Accessor& checkedAccessor(int index, int type, const Formats& allowed,
                                            const std::string& use) const;

  struct ViewBytes {
    const unsigned char* data = nullptr;
    std::uint64_t length = 0;
    std::uint64_t stride = 0;  // 0 = tightly packed
  };

  ViewBytes bufferView(int index, const std::string& at) const;
  std::vector<double> readAccessor(int index, int type, const Formats& allowed, const std::string& use);
  std::vector<double> readAttribute(const tinygltf::Primitive& prim, const char* name, int type,
                                    const Formats& allowed, std::size_t vertexCount,
                                    const std::string& at);

  // ---- meshes (gltf_nodes.cpp) ----
  void addMesh(int meshIndex, const NodeTransform& xf, const std::string& nodeAt, const MeshPose& pose = {});
  // keepInstances: the mesh's triangles once in object space (on first use; a posed mesh once per
  // placement), then an Instance.
  void addInstance(int meshIndex, const NodeTransform& xf, const std::string& nodeAt, const MeshPose& pose = {});
  // EXT_mesh_gpu_instancing on a node: one local TRS matrix per instance (empty without the extension).
  std::vector<glm::dmat4> gpuInstances(const tinygltf::Node& node, const std::string& at);
  // A mesh placement (node world transform) as a MeshInstance, or skipped when singular.
  void placeMesh(int mesh, const glm::dmat4& world, const std::string& at, const MeshPose& pose = {});
  void addPrimitive(const tinygltf::Primitive& prim, const NodeTransform& xf, const std::string& at,
                    const MeshPose& pose = {});
  // addPrimitive's steps, in order (gltf_nodes.cpp).
  struct PrimitiveVertices;
  bool acceptPrimitive(const tinygltf::Primitive& prim, const std::string& at);
  void readVertices(const tinygltf::Primitive& prim, const NodeTransform& xf, const MeshPose& pose,
                    const std::string& at, PrimitiveVertices& v);
  std::vector<std::uint32_t> readIndices(const tinygltf::Primitive& prim, DracoPrimitive* draco, std::size_t vertexCount,
                                         const std::string& at);
  std::uint32_t primitiveMaterial(const tinygltf::Primitive& prim, const std::string& at);
  void readSurfaceAttributes(const tinygltf::Primitive& prim, std::uint32_t material, const MeshPose& pose,
                             const std::string& at, PrimitiveVertices& v);
  std::size_t countTriangles(const tinygltf::Primitive& prim, std::size_t indexCount, const std::string& at);
  void addTriangles(const tinygltf::Primitive& prim, const std::vector<std::uint32_t>& indices, std::size_t triangles,
                    const PrimitiveVertices& v, std::uint32_t material, const NodeTransform& xf, const std::string& at);

  const std::string& path_;
  const tinygltf::Model& model_;
  const ImageLog& images_;
  LoadOptions options_;  // a copy: autoInstances settles keepInstances in build()
  ScenePose pose_;
  Scene& scene_;
  std::map<int, int> textureMap_;  // glTF texture index -> Scene::textures index (-1: ignored)
  // Transformed references (KHR_texture_transform): glTF texture index and rows -> Scene::textures index.
  std::map<std::pair<int, std::vector<float>>, int> transformMap_;
  int defaultMaterial_ = -1;
  bool keepUv_ = false;          // some material reads a texture: Scene::texcoords kept (keepsTexcoords)
  bool keepColors_ = false;      // some primitive so far has COLOR_0: Scene::colors kept
  bool keepTangents_ = false;    // some normal-mapped primitive so far has TANGENT: Scene::tangents kept
  std::size_t degenerate_ = 0;   // zero-area triangles dropped
  std::size_t badNormals_ = 0;   // triangles whose vertex normals were unusable
  std::size_t candidates_ = 0;   // triangles assembled so far, degenerate ones included
  std::uint64_t decoded_ = 0;    // accessor elements decoded so far
  std::string firstSkip_;  // first reason a primitive was skipped, quoted when nothing is left
  // Instances met in the node walk, converted once the origin is known.
  struct CameraInstance {
    int camera = -1, node = -1;
    glm::dmat4 world{1.0};
    std::string at;
  };
  struct MeshInstance {
    int mesh = -1;
    NodeTransform xf;
    std::string at;
    MeshPose pose;
  };
  std::vector<CameraInstance> cameraInstances_;
  std::vector<MeshInstance> meshInstances_;
  std::vector<CameraInstance> lightInstances_;  // same fields: `camera` holds the light index
  bool warnedRange_ = false;
  glm::dvec3 origin_{0.0};  // subtracted from every world position before it becomes float
  std::map<int, std::uint32_t> storedMeshes_;  // keepInstances: glTF mesh -> Scene::meshes index
};

}  // namespace caustica::gltf
