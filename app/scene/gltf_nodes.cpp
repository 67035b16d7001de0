// gltf_nodes.cpp — the walk over the default scene's node tree: hierarchy checks, node transforms,
// cameras, and mesh primitives assembled into world-space triangles; SceneBuilder::build drives it.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "util/math_constants.h"
#include "scene/gltf_internal.h"

namespace caustica::gltf {

void SceneBuilder::build() {
  quantized_ = std::find(model_.extensionsUsed.begin(), model_.extensionsUsed.end(), "KHR_mesh_quantization") !=
               model_.extensionsUsed.end();
  for (std::size_t i = 0; i < model_.materials.size(); ++i) scene_.materials.push_back(convertMaterial(int(i)));
  keepUv_ = keepsTexcoords(scene_.materials);  // the default material added later reads none
  readAnimations();  // gltf_animation.cpp: the pose's node TRS and morph weights
  traverse();
  if (options_.keepInstances && options_.autoInstances) options_.keepInstances = instancingPays();
  checkTriangleCount();
  // Positions become float relative to the scene's centre, computed in double, so a scene far from
  // the world origin keeps the precision of one near it (docs/stability.md).
  origin_ = chooseOrigin();
  scene_.origin = origin_;
  for (const CameraInstance& c : cameraInstances_) addCamera(c.camera, c.world, model_.nodes[std::size_t(c.node)], c.at);
  for (const MeshInstance& m : meshInstances_) {
    if (options_.keepInstances) addInstance(m.mesh, m.xf, m.at, m.pose);
    else addMesh(m.mesh, m.xf, m.at, m.pose);
  }
  for (const CameraInstance& l : lightInstances_) addLight(l.camera, l.world, l.at);
  if (degenerate_ > 0) warn("skipped " + str(degenerate_) + " degenerate (zero-area) triangle(s)");
  if (badNormals_ > 0)
    warn(str(badNormals_) + " triangle(s) had zero or non-finite vertex normals; flat normals used for them");
  warnNotRendered();
  if (scene_.triangles.empty()) {
    std::string why = firstSkip_;
    if (why.empty() && degenerate_ > 0) why = "all " + str(degenerate_) + " triangles have zero area";
    if (why.empty()) why = "the default scene's nodes reference no mesh triangles";
    fail("the scene has no triangles to render (" + why + ")");
  }
  if (scene_.instances.empty()) {
    for (const Triangle& t : scene_.triangles)
      for (const glm::vec3& p : t.p) scene_.bounds.grow(p);
  } else {
    // The world-space vertices, as flattenInstances makes them (exact, not boxes of boxes).
    for (const Instance& in : scene_.instances) {
      const MeshRange& m = scene_.meshes[in.mesh];
      for (std::uint32_t i = m.firstTriangle; i < m.firstTriangle + m.triangleCount; ++i)
        for (const glm::vec3& p : scene_.triangles[i].p)
          scene_.bounds.grow(glm::vec3(glm::dvec3(in.world * glm::dvec4(glm::dvec3(p), 1.0)) - origin_));
    }
  }
}


namespace {
// Triangles a primitive declares (accessor counts; 0 for other modes or bad indices, reported later).
std::uint64_t primitiveTriangles(const tinygltf::Model& model, const tinygltf::Primitive& prim) {
  if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
      prim.mode != TINYGLTF_MODE_TRIANGLE_FAN)
    return 0;
  int source = prim.indices;
  if (source < 0) {
    const auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) return 0;
    source = pos->second;
  }
  if (source < 0 || std::size_t(source) >= model.accessors.size()) return 0;  // readAccessor reports it
  const std::uint64_t n = model.accessors[std::size_t(source)].count;
  return prim.mode == TINYGLTF_MODE_TRIANGLES ? n / 3 : (n >= 3 ? n - 2 : 0);
}
}  // namespace

std::uint64_t SceneBuilder::declaredTriangles(int mesh) const {
  if (mesh < 0 || std::size_t(mesh) >= model_.meshes.size()) return 0;
  std::uint64_t total = 0;
  for (const tinygltf::Primitive& prim : model_.meshes[std::size_t(mesh)].primitives)
    total = std::min(std::uint64_t(1) << 62, total + std::min(std::uint64_t(1) << 62, primitiveTriangles(model_, prim)));
  return total;
}

bool SceneBuilder::instancingPays() const {
  std::uint64_t stored = 0, placed = 0;
  std::set<int> seen;
  for (const MeshInstance& m : meshInstances_) {
    const std::uint64_t n = declaredTriangles(m.mesh);
    placed = std::min(std::uint64_t(1) << 62, placed + n);
    if (seen.insert(m.mesh).second) stored += n;
  }
  return placed > options_.maxTriangles || double(placed) > options_.autoInstanceFactor * double(stored);
}

void SceneBuilder::checkTriangleCount() {
  // Saturating sums: a hostile file may declare counts near 2^53 on many instances.
  const std::uint64_t kSaturated = std::numeric_limits<std::uint64_t>::max() / 2;
  std::uint64_t total = 0;
  std::set<int> counted;  // keepInstances: each mesh's triangles are stored once
  if (options_.keepInstances && meshInstances_.size() > options_.maxTriangles)
    fail("the scene places " + str(meshInstances_.size()) + " mesh instances, more than the limit of " +
         str(options_.maxTriangles) + " (use --max-triangles to raise it)");
  for (const MeshInstance& m : meshInstances_) {
    if (m.mesh < 0 || std::size_t(m.mesh) >= model_.meshes.size()) continue;  // addMesh reports it
    if (options_.keepInstances && !counted.insert(m.mesh).second) continue;
    for (const tinygltf::Primitive& prim : model_.meshes[std::size_t(m.mesh)].primitives) {
      const std::uint64_t triangles = primitiveTriangles(model_, prim);
      total = std::min(kSaturated, total + std::min(kSaturated, triangles));
      if (total > options_.maxTriangles)
        fail(m.at + " (meshes[" + str(std::uint64_t(m.mesh)) + "]) brings the scene's declared triangles to " +
             (total == kSaturated ? std::string("an absurd number") : str(total)) + ", more than the limit of " +
             str(options_.maxTriangles) + " (use --max-triangles to raise it)");
    }
  }
  // One allocation for every triangle: growing the vector by doubling held the old and the new array
  // at once, 1.5x the triangles' 52 B at the peak. Only as many as the buffers can hold (a triangle
  // takes at least 3 index bytes), so a file that declares more than it has fails later, as before.
  std::uint64_t bytes = 0;
  for (const tinygltf::Buffer& b : model_.buffers) bytes += b.data.size();
  try {
    scene_.triangles.reserve(scene_.triangles.size() + static_cast<std::size_t>(std::min(total, bytes / 3)));
    if (keepUv_) scene_.texcoords.reserve(scene_.triangles.capacity());
  } catch (const std::exception&) {  // bad_alloc, length_error: grow as needed instead
  }
}

// ---- node hierarchy ----
glm::dmat4 SceneBuilder::localMatrix(const tinygltf::Node& node, const std::string& at) {
  if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major, as glTF
  glm::dmat4 m(1.0);
  if (node.translation.size() == 3)
    m = glm::translate(m, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4) {
    glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);  // (w, x, y, z)
    const double length = glm::length(q);
    if (!(length > 1e-12) || !std::isfinite(length)) {
      warn(at + ".rotation is not a unit quaternion (length " + num(length) + "); using no rotation");
    } else {
      m *= glm::mat4_cast(q / length);
    }
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

glm::dmat4 SceneBuilder::localMatrix(int nodeIndex, const std::string& at) {
  const auto it = animatedTrs_.find(nodeIndex);
  return it != animatedTrs_.end() ? trsMatrix(it->second) : localMatrix(model_.nodes[std::size_t(nodeIndex)], at);
}

// Rejects children out of range, nodes with two parents and cycles, so the walk below terminates.
std::vector<int> SceneBuilder::checkHierarchy() {
  const std::size_t n = model_.nodes.size();
  std::vector<int> parent(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    for (int child : model_.nodes[i].children) {
      const std::string at = "nodes[" + str(i) + "].children";
      if (child < 0 || std::size_t(child) >= n)
        fail(at + " lists node " + std::to_string(child) + ", but the file has " + str(n) + " nodes");
      if (std::size_t(child) == i) fail(at + " lists the node itself (a cycle in the node graph)");
      if (parent[std::size_t(child)] >= 0)
        fail("nodes[" + str(std::uint64_t(child)) + "] has two parents (nodes[" +
             str(std::uint64_t(parent[std::size_t(child)])) + "] and nodes[" + str(i) +
             "]); glTF node hierarchies must be trees");
      parent[std::size_t(child)] = int(i);
    }
  }
  // Every node has at most one parent, so following parents either reaches a root or loops.
  enum : char { kUnseen, kOnPath, kLeadsToRoot };
  std::vector<char> state(n, kUnseen);
  std::vector<std::size_t> path;
  for (std::size_t start = 0; start < n; ++start) {
    path.clear();
    for (std::size_t i = start; state[i] != kLeadsToRoot; i = std::size_t(parent[i])) {
      if (state[i] == kOnPath)
        fail("the node graph has a cycle through nodes[" + str(i) + "] (node hierarchies must be trees)");
      state[i] = kOnPath;
      path.push_back(i);
      if (parent[i] < 0) break;
    }
    for (std::size_t p : path) state[p] = kLeadsToRoot;
  }
  return parent;
}

void SceneBuilder::traverse() {
  const std::vector<int> parent = checkHierarchy();
  if (!model_.skins.empty()) computeNodeWorlds(parent);  // joints may lie anywhere in the tree
  std::vector<int> roots;
  if (model_.scenes.empty()) {
    for (std::size_t i = 0; i < parent.size(); ++i)
      if (parent[i] < 0) roots.push_back(int(i));
  } else {
    const int sceneIndex = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (std::size_t(sceneIndex) >= model_.scenes.size())
      fail("scene is " + str(std::uint64_t(sceneIndex)) + ", but the file has " + str(model_.scenes.size()) +
           " scenes");
    roots = model_.scenes[std::size_t(sceneIndex)].nodes;
    for (int r : roots)
      if (r < 0 || std::size_t(r) >= model_.nodes.size())
        fail("scenes[" + str(std::uint64_t(sceneIndex)) + "].nodes lists node " + std::to_string(r) +
             ", but the file has " + str(model_.nodes.size()) + " nodes");
  }
  // Depth-first, pre-order, children in file order; an explicit stack bounds native recursion.
  std::vector<bool> visited(model_.nodes.size(), false);
  std::vector<std::pair<int, glm::dmat4>> stack;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.emplace_back(*it, glm::dmat4(1.0));
  while (!stack.empty()) {
    const auto [index, parentWorld] = stack.back();
    stack.pop_back();
    const std::string at = "nodes[" + str(std::uint64_t(index)) + "]";
    if (visited[std::size_t(index)]) {
      warn(at + " is reached twice from the scene's root nodes; the second instance is skipped");
      continue;
    }
    visited[std::size_t(index)] = true;
    const tinygltf::Node& node = model_.nodes[std::size_t(index)];
    NodeTransform xf;
    xf.world = parentWorld * localMatrix(index, at);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(xf.world[c][r])) fail(at + ": its world transform is not finite");
    if (node.camera >= 0) cameraInstances_.push_back({node.camera, index, xf.world, at});
    if (const int light = nodeLight(node); light >= 0) lightInstances_.push_back({light, index, xf.world, at});
    if (node.mesh >= 0) {
      MeshPose pose;  // morph weights and skin (gltf_animation.cpp)
      if (std::size_t(node.mesh) < model_.meshes.size()) pose.weights = nodeWeights(index, node.mesh, at);
      pose.skin = node.skin;
      const std::vector<glm::dmat4> gpu = gpuInstances(node, at);
      if (gpu.empty()) placeMesh(node.mesh, xf.world, at, pose);
      for (std::size_t i = 0; i < gpu.size(); ++i)
        placeMesh(node.mesh, xf.world * gpu[i], at + " (EXT_mesh_gpu_instancing instance " + str(i) + ")", pose);
    }
    for (auto it = node.children.rbegin(); it != node.children.rend(); ++it) stack.emplace_back(*it, xf.world);
  }
}

void SceneBuilder::placeMesh(int mesh, const glm::dmat4& world, const std::string& at, const MeshPose& pose) {
  if (pose.skin >= 0) {  // placed by its joints: the node's own transform is ignored (glTF 3.7.3.3)
    meshInstances_.push_back({mesh, NodeTransform{}, at, pose});
    return;
  }
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(world[c][r])) fail(at + ": its world transform is not finite");
  const glm::dmat3 m3(world);
  const double det = glm::determinant(m3);
  if (!(std::abs(det) > 1e-300) || !std::isfinite(det)) {
    skip(at + ": its transform is singular (scale 0?); its mesh is skipped");
    return;
  }
  NodeTransform xf;
  xf.world = world;
  xf.normal = glm::transpose(glm::inverse(m3));
  xf.flip = det < 0.0;
  meshInstances_.push_back({mesh, xf, at, pose});
}

// EXT_mesh_gpu_instancing: TRANSLATION (VEC3 float), ROTATION (VEC4 float or normalized
// byte/short quaternion, x y z w) and SCALE (VEC3 float) accessors of equal count; each instance's
// local matrix T * R * S is applied after the node's own world transform.
std::vector<glm::dmat4> SceneBuilder::gpuInstances(const tinygltf::Node& node, const std::string& at) {
  const auto it = node.extensions.find("EXT_mesh_gpu_instancing");
  if (it == node.extensions.end() || !it->second.IsObject()) return {};
  const std::string eat = at + ".extensions.EXT_mesh_gpu_instancing";
  const tinygltf::Value& attributes = it->second.Get("attributes");
  if (!attributes.IsObject()) fail(eat + " has no attributes object");
  auto accessorOf = [&](const char* name) -> int {
    const tinygltf::Value& v = attributes.Get(name);
    if (!v.IsNumber() && !v.IsInt()) return -1;
    return v.GetNumberAsInt();
  };
  const int ti = accessorOf("TRANSLATION"), ri = accessorOf("ROTATION"), si = accessorOf("SCALE");
  if (ti < 0 && ri < 0 && si < 0) fail(eat + ".attributes has none of TRANSLATION, ROTATION, SCALE");
  std::vector<double> t, r, s;
  if (ti >= 0) t = readAccessor(ti, TINYGLTF_TYPE_VEC3, {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}}, eat + " TRANSLATION");
  if (ri >= 0)
    r = readAccessor(ri, TINYGLTF_TYPE_VEC4,
                     {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}, {TINYGLTF_COMPONENT_TYPE_BYTE, true},
                      {TINYGLTF_COMPONENT_TYPE_SHORT, true}},
                     eat + " ROTATION");
  if (si >= 0) s = readAccessor(si, TINYGLTF_TYPE_VEC3, {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}}, eat + " SCALE");
  std::size_t count = ti >= 0 ? t.size() / 3 : ri >= 0 ? r.size() / 4 : s.size() / 3;
  if ((ti >= 0 && t.size() / 3 != count) || (ri >= 0 && r.size() / 4 != count) || (si >= 0 && s.size() / 3 != count))
    fail(eat + ": TRANSLATION, ROTATION and SCALE have different counts");
  if (count > options_.maxTriangles)
    fail(eat + " declares " + str(count) + " instances, more than the limit of " + str(options_.maxTriangles));
  std::vector<glm::dmat4> out;
  out.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    glm::dmat4 m(1.0);
    if (ti >= 0) m = glm::translate(m, glm::dvec3(t[3 * i], t[3 * i + 1], t[3 * i + 2]));
    if (ri >= 0) {
      const glm::dquat q(r[4 * i + 3], r[4 * i], r[4 * i + 1], r[4 * i + 2]);
      const double length = glm::length(q);
      if (!(length > 1e-12) || !std::isfinite(length))
        fail(eat + ": ROTATION of instance " + str(i) + " is not a unit quaternion");
      m *= glm::mat4_cast(q / length);
    }
    if (si >= 0) m = glm::scale(m, glm::dvec3(s[3 * i], s[3 * i + 1], s[3 * i + 2]));
    out.push_back(m);
  }
  if (out.empty()) warn(eat + " places no instances; the node's mesh is drawn once");
  return out;
}

glm::dvec3 SceneBuilder::chooseOrigin() const {
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  auto grow = [&](const glm::dvec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  };
  bool anyBox = false;
  for (const MeshInstance& m : meshInstances_) {
    if (m.mesh < 0 || std::size_t(m.mesh) >= model_.meshes.size()) continue;  // addMesh reports it
    bool boxed = false;
    for (const tinygltf::Primitive& prim : model_.meshes[std::size_t(m.mesh)].primitives) {
      const auto pos = prim.attributes.find("POSITION");
      if (pos == prim.attributes.end() || pos->second < 0 || std::size_t(pos->second) >= model_.accessors.size()) continue;
      const tinygltf::Accessor& a = model_.accessors[std::size_t(pos->second)];
      if (a.minValues.size() != 3 || a.maxValues.size() != 3) continue;
      bool finite = true;
      for (int k = 0; k < 3; ++k) finite = finite && std::isfinite(a.minValues[k]) && std::isfinite(a.maxValues[k]);
      if (!finite) continue;
      for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec4 local((corner & 1) ? a.maxValues[0] : a.minValues[0], (corner & 2) ? a.maxValues[1] : a.minValues[1],
                               (corner & 4) ? a.maxValues[2] : a.minValues[2], 1.0);
        grow(glm::dvec3(m.xf.world * local));
      }
      boxed = true;
    }
    if (boxed) anyBox = true;
    else grow(glm::dvec3(m.xf.world[3]));  // no usable min/max: the node's own origin
  }
  // Without any min/max (which glTF requires of POSITION) the size is unknown: keep world coordinates.
  if (!anyBox || !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) return glm::dvec3(0.0);
  const glm::dvec3 centre = 0.5 * (lo + hi);
  if (!(std::isfinite(centre.x) && std::isfinite(centre.y) && std::isfinite(centre.z))) return glm::dvec3(0.0);
  // Only a scene farther from the world origin than its own size loses float precision worth
  // recovering; others keep their glTF coordinates exactly.
  const glm::dvec3 extent = hi - lo;
  const double size = std::max(extent.x, std::max(extent.y, extent.z));
  const double distance = std::max(std::abs(centre.x), std::max(std::abs(centre.y), std::abs(centre.z)));
  return distance > size ? centre : glm::dvec3(0.0);
}

void SceneBuilder::addCamera(int index, const glm::dmat4& world, const tinygltf::Node& node,
                             const std::string& at) {
  if (std::size_t(index) >= model_.cameras.size())
    fail(at + ".camera is " + str(std::uint64_t(index)) + ", but the file has " + str(model_.cameras.size()) +
         " cameras");
  const tinygltf::Camera& cam = model_.cameras[std::size_t(index)];
  const std::string cat = "cameras[" + str(std::uint64_t(index)) + "]";
  const bool orthographic = cam.type == "orthographic";
  const double yfov = orthographic ? 0.7 : cam.perspective.yfov;
  if (!orthographic && !(yfov > 0.0 && yfov < kPiD))
    fail(cat + ".perspective.yfov is " + num(yfov) + "; it must be an angle in radians between 0 and pi");
  // glTF's xmag and ymag are half the view's width and height (checkJson: finite, not 0; their sign
  // carries no meaning here).
  const double ymag = orthographic ? std::abs(cam.orthographic.ymag) : 0.0;
  const double xmag = orthographic ? std::abs(cam.orthographic.xmag) : 0.0;
  const glm::dmat3 m3(world);
  const glm::dvec3 position = glm::dvec3(world * glm::dvec4(0.0, 0.0, 0.0, 1.0)) - origin_;
  const glm::dvec3 f = m3 * glm::dvec3(0.0, 0.0, -1.0);
  const glm::dvec3 u = m3 * glm::dvec3(0.0, 1.0, 0.0);
  const double fl = glm::length(f);
  const glm::dvec3 forward = f / fl;
  const glm::dvec3 upOrtho = u - glm::dot(u, forward) * forward;
  const double ul = glm::length(upOrtho);
  if (!(fl > 1e-12) || !(ul > 1e-9 * std::max(1.0, glm::length(u))) || !std::isfinite(fl) || !std::isfinite(ul)) {
    warn(at + ": camera transform is degenerate (zero scale, or up parallel to forward); camera skipped");
    return;
  }
  Camera out;
  out.name = !cam.name.empty() ? cam.name : !node.name.empty() ? node.name : cat;
  out.position = glm::vec3(position);
  out.forward = glm::vec3(forward);
  out.up = glm::vec3(upOrtho / ul);
  out.yfov = float(yfov);
  out.aspect = cam.perspective.aspectRatio > 0.0 ? float(cam.perspective.aspectRatio) : 0.0f;
  if (orthographic) {
    // The node's scale does not scale the view (glTF 3.10.3: camera transforms exclude scale).
    out.orthoHeight = float(ymag);
    out.aspect = float(xmag / ymag);
    if (!std::isfinite(out.orthoHeight) || !std::isfinite(out.aspect) || !(out.orthoHeight > 0.0f))
      fail(cat + ".orthographic: xmag and ymag must be finite and not 0");
  }
  scene_.cameras.push_back(out);
}

// ---- meshes ----
void SceneBuilder::addInstance(int meshIndex, const NodeTransform& xf, const std::string& nodeAt, const MeshPose& pose) {
  // A posed mesh (morphed or skinned) is its own stored mesh, once per placement.
  auto found = pose.posed() ? storedMeshes_.end() : storedMeshes_.find(meshIndex);
  std::uint32_t stored = found == storedMeshes_.end() ? 0u : found->second;
  if (found == storedMeshes_.end()) {
    // Object space: identity transform and no rebasing (the instance carries both).
    const std::size_t first = scene_.triangles.size();
    const glm::dvec3 origin = origin_;
    origin_ = glm::dvec3(0.0);
    addMesh(meshIndex, NodeTransform{}, nodeAt, pose);
    origin_ = origin;
    MeshRange range;
    range.firstTriangle = std::uint32_t(first);
    range.triangleCount = std::uint32_t(scene_.triangles.size() - first);
    range.gltfMesh = meshIndex;
    stored = std::uint32_t(scene_.meshes.size());
    if (!pose.posed()) storedMeshes_.emplace(meshIndex, stored);
    scene_.meshes.push_back(range);
  }
  if (scene_.meshes[stored].triangleCount == 0) return;  // nothing to place
  scene_.instances.push_back({stored, xf.world});
}

void SceneBuilder::addMesh(int meshIndex, const NodeTransform& xf, const std::string& nodeAt, const MeshPose& pose) {
  if (std::size_t(meshIndex) >= model_.meshes.size())
    fail(nodeAt + ".mesh is " + str(std::uint64_t(meshIndex)) + ", but the file has " + str(model_.meshes.size()) +
         " meshes");
  const tinygltf::Mesh& mesh = model_.meshes[std::size_t(meshIndex)];
  for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
    addPrimitive(mesh.primitives[p], xf, "meshes[" + str(std::uint64_t(meshIndex)) + "].primitives[" + str(p) + "]",
                 pose);
}

// A primitive's vertex data as addPrimitive's steps read it: 3 doubles a vertex for positions and normals
// (model space, or world space once skinned), 2 for uvs, colorComponents for colors, 4 for tangents.
struct SceneBuilder::PrimitiveVertices {
  std::size_t count = 0;
  std::vector<double> positions;
  std::vector<double> normals;
  std::vector<bool> mirrored;              // mirrored[v]: vertex v's skin matrix mirrors
  std::vector<std::uint32_t> normalWords;  // world-space octahedral normal a vertex; kOctNoNormal: none
  std::vector<double> uvs;
  std::vector<double> colors;
  int colorComponents = 0;
  std::vector<double> tangents;
};

void SceneBuilder::addPrimitive(const tinygltf::Primitive& prim, const NodeTransform& xf, const std::string& at,
                                const MeshPose& pose) {
  if (!acceptPrimitive(prim, at)) return;
  // KHR_draco_mesh_compression: the attributes it lists and the indices come from the Draco data;
  // readAttribute takes them from there while draco_ is set.
  DracoPrimitive draco;
  const bool compressed = prim.extensions.count("KHR_draco_mesh_compression") > 0;
  if (compressed) {
    if (prim.mode != TINYGLTF_MODE_TRIANGLES)
      fail(at + ": a KHR_draco_mesh_compression primitive must have mode TRIANGLES (4), not " + std::to_string(prim.mode));
    draco = decodeDraco(prim, at);
  }
  draco_ = compressed ? &draco : nullptr;
  struct ResetDraco {
    const DracoPrimitive*& p;
    ~ResetDraco() { p = nullptr; }
  } resetDraco{draco_};
  PrimitiveVertices v;
  readVertices(prim, xf, pose, at, v);
  const std::vector<std::uint32_t> indices = readIndices(prim, compressed ? &draco : nullptr, v.count, at);
  const std::uint32_t material = primitiveMaterial(prim, at);
  readSurfaceAttributes(prim, material, pose, at, v);
  const std::size_t triangles = countTriangles(prim, indices.size(), at);
  addTriangles(prim, indices, triangles, v, material, xf, at);
}

// Whether the primitive can be added: triangles (list, strip or fan) with a POSITION; else it is
// skipped, and said so.
bool SceneBuilder::acceptPrimitive(const tinygltf::Primitive& prim, const std::string& at) {
  static const char* const kModeNames[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
  if (prim.mode >= 0 && prim.mode <= 3) {
    skip(at + ": mode " + kModeNames[prim.mode] + " is not supported (triangles only); primitive skipped");
    return false;
  }
  if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
      prim.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
    skip(at + ": mode " + std::to_string(prim.mode) + " is not a valid primitive mode; primitive skipped");
    return false;
  }
  if (prim.attributes.find("POSITION") == prim.attributes.end()) {
    skip(at + " has no POSITION attribute; primitive skipped");
    return false;
  }
  return true;
}

// POSITION and NORMAL, posed, and each vertex's world-space normal word.
void SceneBuilder::readVertices(const tinygltf::Primitive& prim, const NodeTransform& xf, const MeshPose& pose,
                                const std::string& at, PrimitiveVertices& v) {
  std::vector<double>& positions = v.positions;
  std::vector<double>& normals = v.normals;
  positions = readAttribute(prim, "POSITION", TINYGLTF_TYPE_VEC3, attributeFormats(VertexAttribute::Position, quantized_),
                            kAnyCount, at);
  const std::size_t vertexCount = positions.size() / 3;
  v.count = vertexCount;
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (!std::isfinite(positions[i]))
      fail(at + ": POSITION of vertex " + str(i / 3) + " is " + (std::isnan(positions[i]) ? "NaN" : "infinite"));
  normals =
      readAttribute(prim, "NORMAL", TINYGLTF_TYPE_VEC3, attributeFormats(VertexAttribute::Normal, quantized_), vertexCount, at);
  // The pose (gltf_animation.cpp): morph targets blended, then skinned meshes placed by their joints
  // (world space; xf is then the identity).
  if (pose.posed()) {
    morphPrimitive(prim, pose, vertexCount, positions, normals, at);
    if (pose.skin >= 0) skinPrimitive(prim, pose.skin, vertexCount, positions, normals, v.mirrored, at);
    for (std::size_t i = 0; i < positions.size(); ++i)
      if (!std::isfinite(positions[i])) fail(at + ": a posed vertex position is not finite");
  }
  // Each vertex's world-space normal as its octahedral word (Triangle::normalWord), encoded once per
  // vertex rather than once per corner (a closed mesh has ~6 corners per vertex); kOctNoNormal marks
  // a zero or non-finite one (octEncode never gives it for a unit vector).
  std::vector<std::uint32_t>& normalWords = v.normalWords;
  normalWords.resize(normals.empty() ? 0 : vertexCount);
  for (std::size_t i = 0; i < normalWords.size(); ++i) {
    const glm::dvec3 nw = xf.normal * glm::dvec3(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
    const double len = glm::length(nw);
    normalWords[i] = !(len > 1e-20) || !std::isfinite(len) ? kOctNoNormal : octEncode(glm::vec3(nw / len));
  }
}

// The primitive's vertex indices (from the Draco data when `draco` is given), each checked against the
// vertex count; 0, 1, 2, ... without an index accessor.
std::vector<std::uint32_t> SceneBuilder::readIndices(const tinygltf::Primitive& prim, DracoPrimitive* draco,
                                                     std::size_t vertexCount, const std::string& at) {
  std::vector<std::uint32_t> indices;
  if (draco || prim.indices >= 0) {
    std::vector<double> raw;
    if (draco) {
      if (prim.indices >= 0)  // the accessor still declares the index type
        checkedAccessor(prim.indices, TINYGLTF_TYPE_SCALAR, kIndexFormats, at + " indices");
      raw = std::move(draco->indices);
    } else {
      raw = readAccessor(prim.indices, TINYGLTF_TYPE_SCALAR, kIndexFormats, at + " indices");
    }
    indices.reserve(raw.size());
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] >= double(vertexCount))
        fail(at + ": index " + str(std::uint64_t(raw[i])) + " (entry " + str(i) + ") is out of range: POSITION has " +
             str(vertexCount) + " vertices");
      indices.push_back(std::uint32_t(raw[i]));
    }
  } else {
    indices.resize(vertexCount);
    for (std::size_t i = 0; i < vertexCount; ++i) indices[i] = std::uint32_t(i);
  }
  return indices;
}

// The primitive's material index, or the default material when it names none.
std::uint32_t SceneBuilder::primitiveMaterial(const tinygltf::Primitive& prim, const std::string& at) {
  if (prim.material >= 0) {
    if (std::size_t(prim.material) >= model_.materials.size())
      fail(at + ".material is " + str(std::uint64_t(prim.material)) + ", but the file has " +
           str(model_.materials.size()) + " materials");
    return std::uint32_t(prim.material);
  }
  return defaultMaterial(at);
}

// The UVs, COLOR_0 and TANGENT the material uses.
void SceneBuilder::readSurfaceAttributes(const tinygltf::Primitive& prim, std::uint32_t material, const MeshPose& pose,
                                         const std::string& at, PrimitiveVertices& v) {
  const std::size_t vertexCount = v.count;
  // The UV set the material's textures read (TEXCOORD_0 unless they all name TEXCOORD_1).
  const std::string uvName = scene_.materials[material].texCoord == 1 && prim.attributes.count("TEXCOORD_1")
                                 ? "TEXCOORD_1" : "TEXCOORD_0";
  if (scene_.materials[material].texCoord == 1 && uvName != "TEXCOORD_1")
    warn(at + ": its material's textures read TEXCOORD_1, which the primitive lacks; TEXCOORD_0 is used");
  v.uvs =
      readAttribute(prim, uvName.c_str(), TINYGLTF_TYPE_VEC2, attributeFormats(VertexAttribute::Texcoord, quantized_), vertexCount, at);
  for (std::size_t i = 0; i < v.uvs.size(); ++i)
    if (!std::isfinite(v.uvs[i])) fail(at + ": " + uvName + " of vertex " + str(i / 2) + " is not finite");
  // COLOR_0 (VEC3 or VEC4: float, normalized unsigned byte or short) multiplies the base colour and,
  // its alpha, the opacity; kept per triangle only once some primitive has it.
  if (const auto c = prim.attributes.find("COLOR_0"); c != prim.attributes.end()) {
    const int type = c->second >= 0 && std::size_t(c->second) < model_.accessors.size() &&
                             model_.accessors[std::size_t(c->second)].type == TINYGLTF_TYPE_VEC3
                         ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4;
    v.colorComponents = type == TINYGLTF_TYPE_VEC3 ? 3 : 4;
    v.colors = readAttribute(prim, "COLOR_0", type, attributeFormats(VertexAttribute::Color, quantized_), vertexCount, at);
    for (std::size_t i = 0; i < v.colors.size(); ++i)
      if (!std::isfinite(v.colors[i]))
        fail(at + ": COLOR_0 of vertex " + str(i / std::size_t(v.colorComponents)) + " is not finite");
    if (!keepColors_) scene_.colors.resize(scene_.triangles.size());  // white before the first
    keepColors_ = true;
  }
  // TANGENT (VEC4: xyz and the bitangent's sign) orients the material's normal map, when it has one.
  // A skinned or morphed pose moves the surface under the file's tangents, which are not posed: the
  // normal map then takes the posed triangle's dp/du.
  const bool posedShape = pose.posed() && (pose.skin >= 0 || !prim.targets.empty());
  if (scene_.materials[material].normalTexture >= 0 && prim.attributes.count("TANGENT") && !posedShape) {
    v.tangents = readAttribute(prim, "TANGENT", TINYGLTF_TYPE_VEC4, attributeFormats(VertexAttribute::Tangent, quantized_),
                               vertexCount, at);
    if (!keepTangents_) scene_.tangents.resize(scene_.triangles.size());  // none before the first
    keepTangents_ = true;
  }
}

// The number of triangles `indexCount` indices make in the primitive's mode, counted against --max-triangles.
std::size_t SceneBuilder::countTriangles(const tinygltf::Primitive& prim, std::size_t indexCount, const std::string& at) {
  const std::size_t n = indexCount;
  std::size_t triangles = 0;
  if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
    triangles = n / 3;
    if (n % 3 != 0)
      warn(at + ": " + str(n) + " indices are not a multiple of 3; the last " + str(n % 3) + " are ignored");
  } else if (n >= 3) {
    triangles = n - 2;
  }
  candidates_ += triangles;  // counted before degenerate ones are dropped, so work stays bounded
  if (candidates_ > options_.maxTriangles)
    fail("the scene has more than " + str(options_.maxTriangles) + " triangles (use --max-triangles to raise the limit)");
  return triangles;
}

// The primitive's triangles in world space (relative to origin_), with their UVs, colours and tangents;
// degenerate ones dropped, flat normals where a corner has none.
void SceneBuilder::addTriangles(const tinygltf::Primitive& prim, const std::vector<std::uint32_t>& indices,
                                std::size_t triangles, const PrimitiveVertices& v, std::uint32_t material,
                                const NodeTransform& xf, const std::string& at) {
  const std::vector<double>& positions = v.positions;
  const std::vector<double>& uvs = v.uvs;
  const std::vector<double>& colors = v.colors;
  const std::vector<double>& tangents = v.tangents;
  const auto tangentAt = [&](std::size_t i) -> glm::vec4 {  // world space; 0 where unusable
    const glm::dvec3 t = glm::dmat3(xf.world) * glm::dvec3(tangents[4 * i], tangents[4 * i + 1], tangents[4 * i + 2]);
    const double len = glm::length(t);
    if (!(len > 1e-20) || !std::isfinite(len) || !std::isfinite(tangents[4 * i + 3])) return glm::vec4(0.0f);
    // A mirroring transform turns cross(normal, tangent) around: the sign follows the determinant.
    const float w = (tangents[4 * i + 3] < 0.0) != xf.flip ? -1.0f : 1.0f;
    return glm::vec4(glm::vec3(t / len), w);
  };
  // Corner triples in glTF's counter-clockwise order for each mode (glTF 3.7.2.1).
  auto corner = [&](std::size_t t, int k) -> std::uint32_t {
    if (prim.mode == TINYGLTF_MODE_TRIANGLES) return indices[3 * t + std::size_t(k)];
    if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      const std::size_t odd = t % 2;
      const std::size_t offset[3] = {0, 1 + odd, 2 - odd};
      return indices[t + offset[k]];
    }
    return k == 2 ? indices[0] : indices[t + 1 + std::size_t(k)];  // fan: (i+1, i+2, 0)
  };
  for (std::size_t t = 0; t < triangles; ++t) {
    std::uint32_t c[3] = {corner(t, 0), corner(t, 1), corner(t, 2)};
    // A negative determinant (the node's, or the skin's at the first corner): restore counter-clockwise fronts.
    if (xf.flip != (!v.mirrored.empty() && v.mirrored[c[0]])) std::swap(c[1], c[2]);
    Triangle tri;
    TriangleUv uv;
    TriangleColors color;
    TriangleTangents tangent;
    tri.material = material;
    bool finite = true;
    for (int k = 0; k < 3; ++k) {
      const std::size_t i = c[k];
      const glm::dvec4 p = xf.world * glm::dvec4(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2], 1.0);
      tri.p[k] = glm::vec3(glm::dvec3(p) - origin_);
      finite = finite && std::isfinite(tri.p[k].x) && std::isfinite(tri.p[k].y) && std::isfinite(tri.p[k].z);
      uv.uv[k] = uvs.empty() ? glm::vec2(0.0f) : glm::vec2(float(uvs[2 * i]), float(uvs[2 * i + 1]));
      if (!colors.empty()) {
        const std::size_t cn = std::size_t(v.colorComponents);
        color.color[k] = glm::vec4(float(colors[cn * i]), float(colors[cn * i + 1]), float(colors[cn * i + 2]),
                                   cn == 4 ? float(colors[cn * i + 3]) : 1.0f);
      }
      if (!tangents.empty()) tangent.tangent[k] = tangentAt(i);
    }
    if (!finite) fail(at + ": a vertex position overflows a float after the node transform");
    const glm::vec3 cross = glm::cross(tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]);
    const float area2 = glm::length(cross);
    if (!(area2 > 0.0f) || !std::isfinite(area2)) {
      ++degenerate_;
      continue;
    }
    bool smooth = !v.normalWords.empty();
    for (int k = 0; k < 3 && smooth; ++k) {
      tri.normalWord[k] = v.normalWords[c[k]];
      if (tri.normalWord[k] == kOctNoNormal) {
        smooth = false;
        ++badNormals_;
      }
    }
    if (!smooth) {
      tri.setNormal(0, cross / area2);  // flat
      tri.normalWord[1] = tri.normalWord[2] = tri.normalWord[0];
    }
    scene_.triangles.push_back(tri);
    if (keepUv_) scene_.texcoords.push_back(uv);
    if (keepColors_) scene_.colors.push_back(color);
    if (keepTangents_) scene_.tangents.push_back(tangent);
  }
}

}  // namespace caustica::gltf
