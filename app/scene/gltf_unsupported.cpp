// gltf_unsupported.cpp — what a file holds that caustica does not render, named in ONE warning line
// ("FILE: not rendered: ..."), so nothing is dropped in silence: extensions, vertex attributes,
// material textures and scenes other than the default. One entry per feature below: a feature that
// becomes supported removes its entry here and nowhere else (animations, skins and morph targets did:
// gltf_animation.cpp poses them).
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
// material's textures name it; JOINTS_n and WEIGHTS_n where a skin poses the mesh).
bool renderedAttribute(const std::string& name) {
  return name == "POSITION" || name == "NORMAL" || name == "TANGENT" || name == "TEXCOORD_0" ||
         name == "TEXCOORD_1" || name == "COLOR_0" || name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0;
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
  // Vertex attributes without a meaning here (COLOR_1, TEXCOORD_2, _CUSTOM...).
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
