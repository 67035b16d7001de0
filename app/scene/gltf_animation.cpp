// gltf_animation.cpp — glTF animations, morph targets and skins (docs/animation.md): the animations'
// samplers read and checked, the chosen one(s) sampled at the pose's time into node TRS and morph
// weights, morph targets blended and skinned meshes placed by their joints, all on the CPU at load.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "scene/gltf_internal.h"

namespace caustica::gltf {

namespace {

const std::initializer_list<Format> kFloat = {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}};
// Rotations and weights may also be stored as normalised integers (glTF 3.11, animation samplers).
const std::initializer_list<Format> kFloatOrNormalized = {
    {TINYGLTF_COMPONENT_TYPE_FLOAT, false},        {TINYGLTF_COMPONENT_TYPE_BYTE, true},
    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true}, {TINYGLTF_COMPONENT_TYPE_SHORT, true},
    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true}};

// Morph targets a mesh's primitives have (the most of any primitive: they must all have the same).
std::size_t targetCount(const tinygltf::Model& model, int mesh) {
  if (mesh < 0 || std::size_t(mesh) >= model.meshes.size()) return 0;
  std::size_t n = 0;
  for (const tinygltf::Primitive& p : model.meshes[std::size_t(mesh)].primitives) n = std::max(n, p.targets.size());
  return n;
}

// The node's own TRS (static), its rotation normalised as localMatrix does.
NodeTrs staticTrs(const tinygltf::Node& node) {
  NodeTrs t;
  if (node.translation.size() == 3) t.translation = glm::dvec3(node.translation[0], node.translation[1], node.translation[2]);
  if (node.rotation.size() == 4) {
    const glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
    const double length = glm::length(q);
    if (length > 1e-12 && std::isfinite(length)) t.rotation = q / length;
  }
  if (node.scale.size() == 3) t.scale = glm::dvec3(node.scale[0], node.scale[1], node.scale[2]);
  return t;
}

}  // namespace

void SceneBuilder::readAnimations() {
  const std::size_t count = model_.animations.size();
  if (count == 0) {
    if (!pose_.animation.empty() && pose_.animation != "all")
      fail("--animation " + oneLine(pose_.animation) + ": the file has no animations");
    return;
  }
  const std::vector<bool> played = chooseAnimations();
  scene_.animationTime = pose_.time;
  std::map<int, std::vector<double>> times;  // input accessor -> key times (samplers often share them)
  std::set<int> warnedMatrix;
  for (std::size_t a = 0; a < count; ++a) {
    const tinygltf::Animation& anim = model_.animations[a];
    const std::string aat = "animations[" + str(a) + "]";
    AnimationInfo info;
    info.name = oneLine(anim.name);
    info.start = std::numeric_limits<double>::infinity();
    info.end = -std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < anim.channels.size(); ++c) {
      const tinygltf::AnimationChannel& ch = anim.channels[c];
      const std::string cat = aat + ".channels[" + str(c) + "]";
      if (ch.sampler < 0 || std::size_t(ch.sampler) >= anim.samplers.size())
        fail(cat + ".sampler is " + std::to_string(ch.sampler) + ", but " + aat + " has " + str(anim.samplers.size()) +
             " samplers");
      if (ch.target_node < 0) continue;  // no target (e.g. KHR_animation_pointer): nothing this file moves
      if (std::size_t(ch.target_node) >= model_.nodes.size())
        fail(cat + ".target.node is " + std::to_string(ch.target_node) + ", but the file has " + str(model_.nodes.size()) +
             " nodes");
      const bool isWeights = ch.target_path == "weights";
      if (ch.target_path != "translation" && ch.target_path != "rotation" && ch.target_path != "scale" && !isWeights) {
        warn(cat + ".target.path '" + oneLine(ch.target_path) + "' is not supported; the channel is ignored");
        continue;
      }
      const tinygltf::AnimationSampler& sm = anim.samplers[std::size_t(ch.sampler)];
      const std::string sat = aat + ".samplers[" + str(std::uint64_t(ch.sampler)) + "]";
      KeyframeCurve curve = curveKeys(sm, sat, times);
      info.start = std::min(info.start, curve.times.front());
      info.end = std::max(info.end, curve.times.back());
      ++info.channels;
      if (isWeights) info.weights = true;
      for (const tinygltf::Skin& skin : model_.skins)
        if (std::find(skin.joints.begin(), skin.joints.end(), ch.target_node) != skin.joints.end()) info.skins = true;
      if (!played[a]) continue;
      // The played animation: outputs read, checked against the key count, sampled at the pose's time.
      if (!readCurveValues(ch, sm, cat, sat, curve)) continue;
      applyAnimatedValue(ch, sat, sampleCurve(curve, pose_.time), warnedMatrix);
    }
    if (info.channels == 0) info.start = info.end = 0.0;
    scene_.animations.push_back(info);
    if (played[a]) scene_.animationsPlayed.push_back(int(a));
  }
}

// Which animations play. By default: every one when no two animate the same property of a node
// (exporters such as COLLADA2GLTF write one animation per node of one motion), else the first (the
// file holds alternative motions: Walk, Run, ...). "all": every one; else one by name or index.
std::vector<bool> SceneBuilder::chooseAnimations() {
  const std::size_t count = model_.animations.size();
  std::vector<bool> played(count, false);
  if (pose_.animation.empty()) {
    std::set<std::pair<int, std::string>> targets;
    bool disjoint = true;
    for (const tinygltf::Animation& anim : model_.animations) {
      std::set<std::pair<int, std::string>> own;
      for (const tinygltf::AnimationChannel& ch : anim.channels)
        if (ch.target_node >= 0) own.emplace(ch.target_node, ch.target_path);
      for (const auto& t : own) disjoint = disjoint && targets.insert(t).second;
    }
    if (disjoint) played.assign(count, true);
    else played[0] = true;
  } else if (pose_.animation == "all") {
    played.assign(count, true);
  } else {
    char* end = nullptr;
    const long index = std::strtol(pose_.animation.c_str(), &end, 10);
    int found = -1;
    if (*end == '\0' && index >= 0 && std::size_t(index) < count) found = int(index);
    for (std::size_t i = 0; i < count && found < 0; ++i)
      if (model_.animations[i].name == pose_.animation) found = int(i);
    if (found < 0) {
      std::string list;
      for (std::size_t i = 0; i < count && i < 20; ++i)
        list += (list.empty() ? "" : ", ") + str(i) + (model_.animations[i].name.empty() ? "" : " '" + oneLine(model_.animations[i].name) + "'");
      fail("--animation " + oneLine(pose_.animation) + ": no such animation (the file has " + str(count) + ": " + list +
           (count > 20 ? ", ..." : "") + "; or 'all')");
    }
    played[std::size_t(found)] = true;
  }
  return played;
}

// A sampler's interpolation and key times (read and checked once per input accessor: `times` caches them).
KeyframeCurve SceneBuilder::curveKeys(const tinygltf::AnimationSampler& sm, const std::string& sat,
                                      std::map<int, std::vector<double>>& times) {
  KeyframeCurve curve;
  if (sm.interpolation == "LINEAR" || sm.interpolation.empty()) curve.interpolation = Interpolation::Linear;
  else if (sm.interpolation == "STEP") curve.interpolation = Interpolation::Step;
  else if (sm.interpolation == "CUBICSPLINE") curve.interpolation = Interpolation::CubicSpline;
  else fail(sat + ".interpolation '" + oneLine(sm.interpolation) + "' is not LINEAR, STEP or CUBICSPLINE");
  auto cached = times.find(sm.input);
  if (cached == times.end()) {
    std::vector<double> t = readAccessor(sm.input, TINYGLTF_TYPE_SCALAR, kFloat, sat + ".input");
    if (t.empty()) fail(sat + ".input has no key times");
    for (std::size_t k = 0; k < t.size(); ++k) {
      if (!std::isfinite(t[k])) fail(sat + ".input: key time " + str(k) + " is not finite");
      if (k > 0 && !(t[k] > t[k - 1]))
        fail(sat + ".input: key times must increase (key " + str(k) + " is " + num(t[k]) + ", after " + num(t[k - 1]) + ")");
    }
    cached = times.emplace(sm.input, std::move(t)).first;
  }
  curve.times = cached->second;
  return curve;
}

// The channel's output values, checked against the key count; false when the channel is ignored
// (weights of a node without morph targets: warned).
bool SceneBuilder::readCurveValues(const tinygltf::AnimationChannel& ch, const tinygltf::AnimationSampler& sm,
                                   const std::string& cat, const std::string& sat, KeyframeCurve& curve) {
  const tinygltf::Node& node = model_.nodes[std::size_t(ch.target_node)];
  const bool isWeights = ch.target_path == "weights";
  const std::string nat = "nodes[" + str(std::uint64_t(ch.target_node)) + "]";
  if (isWeights) {
    curve.components = targetCount(model_, node.mesh);
    if (curve.components == 0) {
      warn(cat + " animates the morph weights of " + nat + ", which has no mesh with morph targets; ignored");
      return false;
    }
    curve.values = readAccessor(sm.output, TINYGLTF_TYPE_SCALAR, kFloatOrNormalized, sat + ".output");
  } else if (ch.target_path == "rotation") {
    curve.components = 4;
    curve.rotation = true;
    curve.values = readAccessor(sm.output, TINYGLTF_TYPE_VEC4, kFloatOrNormalized, sat + ".output");
  } else {
    curve.components = 3;
    curve.values = readAccessor(sm.output, TINYGLTF_TYPE_VEC3, kFloat, sat + ".output");
  }
  const std::size_t perKey = curve.components * (curve.interpolation == Interpolation::CubicSpline ? 3 : 1);
  if (curve.values.size() != curve.times.size() * perKey)
    fail(sat + ".output has " + str(curve.values.size() / (isWeights ? 1 : curve.components)) + " elements; " +
         str(curve.times.size()) + " keys of " + interpolationName(curve.interpolation) + " need " +
         str(curve.times.size() * perKey / (isWeights ? 1 : curve.components)) +
         (isWeights ? " (" + str(curve.components) + " morph weights a key)" : ""));
  for (std::size_t i = 0; i < curve.values.size(); ++i)
    if (!std::isfinite(curve.values[i])) fail(sat + ".output: value " + str(i) + " is not finite");
  return true;
}

// The channel's value at the pose's time `v` into animatedWeights_ or the node's TRS in animatedTrs_
// (a node with a matrix keeps it: warned once a node).
void SceneBuilder::applyAnimatedValue(const tinygltf::AnimationChannel& ch, const std::string& sat,
                                      const std::vector<double>& v, std::set<int>& warnedMatrix) {
  const tinygltf::Node& node = model_.nodes[std::size_t(ch.target_node)];
  const std::string nat = "nodes[" + str(std::uint64_t(ch.target_node)) + "]";
  if (ch.target_path == "weights") {
    animatedWeights_[ch.target_node] = v;
    return;
  }
  if (node.matrix.size() == 16) {
    if (warnedMatrix.insert(ch.target_node).second)
      warn(nat + " has a matrix and is animated (glTF allows only TRS on animated nodes); the animation of it is ignored");
    return;
  }
  auto it = animatedTrs_.find(ch.target_node);
  if (it == animatedTrs_.end()) it = animatedTrs_.emplace(ch.target_node, staticTrs(node)).first;
  if (ch.target_path == "translation") {
    it->second.translation = glm::dvec3(v[0], v[1], v[2]);
  } else if (ch.target_path == "scale") {
    it->second.scale = glm::dvec3(v[0], v[1], v[2]);
  } else {
    const glm::dquat q(v[3], v[0], v[1], v[2]);
    const double length = glm::length(q);
    if (!(length > 1e-12)) fail(sat + ": the rotation at t = " + num(pose_.time) + " s is not a unit quaternion");
    it->second.rotation = q / length;
  }
}

std::vector<double> SceneBuilder::nodeWeights(int nodeIndex, int mesh, const std::string& at) {
  const std::size_t n = targetCount(model_, mesh);
  if (n == 0) return {};
  std::vector<double> w;
  if (auto it = animatedWeights_.find(nodeIndex); it != animatedWeights_.end()) w = it->second;
  else if (!model_.nodes[std::size_t(nodeIndex)].weights.empty()) w = model_.nodes[std::size_t(nodeIndex)].weights;
  else w = model_.meshes[std::size_t(mesh)].weights;
  if (!w.empty() && w.size() != n)
    warn(at + ": " + str(w.size()) + " morph weights for " + str(n) + " morph targets; the missing ones are 0");
  w.resize(n, 0.0);
  for (double& x : w)
    if (!std::isfinite(x)) fail(at + ": a morph weight is not finite");
  return w;
}

void SceneBuilder::computeNodeWorlds(const std::vector<int>& parent) {
  const std::size_t n = model_.nodes.size();
  const std::size_t warnings = scene_.warnings.size();  // the node walk reports bad rotations once
  nodeWorld_.assign(n, glm::dmat4(1.0));
  std::vector<char> done(n, 0);
  std::vector<int> chain;
  for (std::size_t start = 0; start < n; ++start) {
    chain.clear();
    for (int i = int(start); i >= 0 && !done[std::size_t(i)]; i = parent[std::size_t(i)]) chain.push_back(i);
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {  // root side first (the hierarchy is a checked tree)
      const int i = *it;
      const int p = parent[std::size_t(i)];
      nodeWorld_[std::size_t(i)] = (p >= 0 ? nodeWorld_[std::size_t(p)] : glm::dmat4(1.0)) *
                                   localMatrix(i, "nodes[" + str(std::uint64_t(i)) + "]");
      done[std::size_t(i)] = 1;
    }
  }
  scene_.warnings.resize(warnings);
}

const std::vector<glm::dmat4>& SceneBuilder::jointMatrices(int skinIndex, const std::string& at) {
  if (auto it = jointMatrices_.find(skinIndex); it != jointMatrices_.end()) return it->second;
  if (std::size_t(skinIndex) >= model_.skins.size())
    fail(at + ".skin is " + str(std::uint64_t(skinIndex)) + ", but the file has " + str(model_.skins.size()) + " skins");
  const tinygltf::Skin& skin = model_.skins[std::size_t(skinIndex)];
  const std::string sat = "skins[" + str(std::uint64_t(skinIndex)) + "]";
  if (skin.joints.empty()) fail(sat + " has no joints");
  std::vector<double> ibm;
  if (skin.inverseBindMatrices >= 0) {
    ibm = readAccessor(skin.inverseBindMatrices, TINYGLTF_TYPE_MAT4, kFloat, sat + ".inverseBindMatrices");
    if (ibm.size() != skin.joints.size() * 16)
      fail(sat + ".inverseBindMatrices has " + str(ibm.size() / 16) + " matrices for " + str(skin.joints.size()) + " joints");
  }
  std::vector<glm::dmat4> m(skin.joints.size());
  for (std::size_t j = 0; j < skin.joints.size(); ++j) {
    const int joint = skin.joints[j];
    if (joint < 0 || std::size_t(joint) >= model_.nodes.size())
      fail(sat + ".joints[" + str(j) + "] is " + std::to_string(joint) + ", but the file has " + str(model_.nodes.size()) + " nodes");
    const glm::dmat4 inverseBind = ibm.empty() ? glm::dmat4(1.0) : glm::make_mat4(ibm.data() + 16 * j);
    m[j] = nodeWorld_[std::size_t(joint)] * inverseBind;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!std::isfinite(m[j][c][r])) fail(sat + ": the matrix of joint " + str(j) + " is not finite");
  }
  return jointMatrices_.emplace(skinIndex, std::move(m)).first->second;
}

void SceneBuilder::morphPrimitive(const tinygltf::Primitive& prim, const MeshPose& pose, std::size_t vertexCount,
                                  std::vector<double>& positions, std::vector<double>& normals, const std::string& at) {
  if (prim.targets.empty()) return;
  std::vector<MorphTarget> targets(prim.targets.size());
  for (std::size_t k = 0; k < prim.targets.size() && k < pose.weights.size(); ++k) {
    if (pose.weights[k] == 0.0) continue;  // not read: adds nothing
    const std::string tat = at + ".targets[" + str(k) + "]";
    for (const auto& [name, accessor] : prim.targets[k]) {
      if (name == "POSITION" || name == "NORMAL") {
        std::vector<double> d = readAccessor(accessor, TINYGLTF_TYPE_VEC3,
                                             {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}, {TINYGLTF_COMPONENT_TYPE_BYTE, true},
                                              {TINYGLTF_COMPONENT_TYPE_SHORT, true}},
                                             tat + " " + name);
        if (d.size() != vertexCount * 3)
          fail(tat + ": " + name + " has " + str(d.size() / 3) + " elements but POSITION has " + str(vertexCount));
        for (double x : d)
          if (!std::isfinite(x)) fail(tat + ": " + name + " is not finite");
        (name == "POSITION" ? targets[k].positions : targets[k].normals) = std::move(d);
      } else if (name != "TANGENT" && warnedMorphAttributes_.insert(name).second) {
        warn(tat + ": morph targets of " + oneLine(name) + " are not supported; ignored");
      }
    }
  }
  positions = morph(positions, targets, pose.weights, false);
  if (!normals.empty()) normals = morph(normals, targets, pose.weights, true);  // normalised where encoded
}

void SceneBuilder::skinPrimitive(const tinygltf::Primitive& prim, int skin, std::size_t vertexCount,
                                 std::vector<double>& positions, std::vector<double>& normals, std::vector<bool>& mirrored,
                                 const std::string& at) {
  const std::vector<glm::dmat4>& joints = jointMatrices(skin, at);
  // JOINTS_n / WEIGHTS_n sets of four influences, n = 0, 1, ...
  std::vector<std::vector<double>> jointSets, weightSets;
  for (int set = 0;; ++set) {
    const std::string j = "JOINTS_" + std::to_string(set), w = "WEIGHTS_" + std::to_string(set);
    if (!prim.attributes.count(j) || !prim.attributes.count(w)) {
      if (set == 0)
        fail(at + ": its mesh is skinned (skins[" + str(std::uint64_t(skin)) + "]) but has no JOINTS_0 and WEIGHTS_0");
      break;
    }
    jointSets.push_back(readAttribute(prim, j.c_str(), TINYGLTF_TYPE_VEC4,
                                      {{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, false}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false}},
                                      vertexCount, at));
    weightSets.push_back(readAttribute(prim, w.c_str(), TINYGLTF_TYPE_VEC4,
                                       {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true},
                                        {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true}},
                                       vertexCount, at));
  }
  const std::size_t influences = 4 * jointSets.size();
  std::vector<double> jv(influences), wv(influences);
  mirrored.assign(vertexCount, false);
  for (std::size_t v = 0; v < vertexCount; ++v) {
    for (std::size_t s = 0; s < jointSets.size(); ++s)
      for (std::size_t i = 0; i < 4; ++i) {
        jv[4 * s + i] = jointSets[s][4 * v + i];
        wv[4 * s + i] = weightSets[s][4 * v + i];
        if (wv[4 * s + i] != 0.0 && jv[4 * s + i] >= double(joints.size()))
          fail(at + ": vertex " + str(v) + " names joint " + str(std::uint64_t(jv[4 * s + i])) + ", but skins[" +
               str(std::uint64_t(skin)) + "] has " + str(joints.size()) + " joints");
        if (!(wv[4 * s + i] >= 0.0)) fail(at + ": vertex " + str(v) + " has a negative or NaN joint weight");
      }
    const glm::dmat4 m = skinMatrix(jv.data(), wv.data(), influences, joints);
    const glm::dvec4 p = m * glm::dvec4(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2], 1.0);
    positions[3 * v] = p.x;
    positions[3 * v + 1] = p.y;
    positions[3 * v + 2] = p.z;
    const glm::dmat3 m3(m);
    const double det = glm::determinant(m3);
    mirrored[v] = det < 0.0;
    if (!normals.empty()) {
      // Normals by the inverse transpose (its scale does not matter: normalised when encoded).
      const glm::dvec3 n = std::abs(det) > 0.0 ? glm::transpose(glm::inverse(m3)) * glm::dvec3(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2])
                                               : glm::dvec3(0.0);
      normals[3 * v] = n.x;
      normals[3 * v + 1] = n.y;
      normals[3 * v + 2] = n.z;
    }
  }
}

}  // namespace caustica::gltf
