// gltf_unsupported.cpp — what a file holds that caustica does not render, named in ONE warning line
// ("FILE: not rendered: ..."), so nothing is dropped in silence: extensions, animations, skins, morph
// targets, vertex attributes, material textures and scenes other than the default. One entry per
// feature below: a feature that becomes supported removes its entry here and nowhere else.
#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "scene/gltf_internal.h"

namespace caustica::gltf {
namespace {

std::string joined(const std::set<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// Vertex attributes caustica reads (TANGENT where a normal map uses it; TEXCOORD_1 where a
// material's textures name it).
bool renderedAttribute(const std::string& name) {
  return name == "POSITION" || name == "NORMAL" || name == "TANGENT" || name == "TEXCOORD_0" ||
         name == "TEXCOORD_1" || name == "COLOR_0";
}

}  // namespace

void SceneBuilder::notRendered(const std::string& what) { notRendered_.push_back(what); }

void SceneBuilder::warnNotRendered() {
  std::vector<std::string> entries;
  // Extensions the file uses that caustica does not implement.
  std::set<std::string> extensions;
  for (const std::string& ext : model_.extensionsUsed)
    if (!isSupportedExtension(ext)) extensions.insert(oneLine(ext));
  if (!extensions.empty()) entries.push_back("extension(s) " + joined(extensions));
  // Animations: the scene is drawn as its nodes stand.
  if (!model_.animations.empty())
    entries.push_back("animations (" + str(model_.animations.size()) + "; the nodes are drawn as they stand)");
  // Skins: meshes are drawn in their bind pose.
  if (!model_.skins.empty()) entries.push_back("skins (" + str(model_.skins.size()) + "; meshes drawn in their bind pose)");
  // Morph targets: the base shape is drawn.
  std::set<std::string> morphed;
  for (std::size_t m = 0; m < model_.meshes.size(); ++m)
    for (const tinygltf::Primitive& prim : model_.meshes[m].primitives)
      if (!prim.targets.empty()) morphed.insert("meshes[" + str(m) + "]");
  if (!morphed.empty()) entries.push_back("morph targets of " + joined(morphed) + " (the base shape is drawn)");
  // Vertex attributes without a meaning here (COLOR_1, TEXCOORD_2, JOINTS_0, WEIGHTS_0, _CUSTOM...).
  std::set<std::string> attributes;
  for (const tinygltf::Mesh& mesh : model_.meshes)
    for (const tinygltf::Primitive& prim : mesh.primitives)
      for (const auto& a : prim.attributes)
        if (!renderedAttribute(a.first)) attributes.insert(oneLine(a.first));
  if (!attributes.empty()) entries.push_back("vertex attribute(s) " + joined(attributes));
  // Scenes other than the default one.
  if (model_.scenes.size() > 1)
    entries.push_back(str(model_.scenes.size() - 1) + " scene(s) besides the default one, scenes[" +
                      str(std::uint64_t(std::max(model_.defaultScene, 0))) + "]");
  // Material properties met while converting the materials (convertMaterial), and the like.
  entries.insert(entries.end(), notRendered_.begin(), notRendered_.end());
  if (entries.empty()) return;
  std::string line;
  for (const std::string& e : entries) line += (line.empty() ? "" : "; ") + e;
  warn("not rendered: " + line);
}

}  // namespace caustica::gltf
