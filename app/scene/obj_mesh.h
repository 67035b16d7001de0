// obj_mesh.h — a minimal Wavefront OBJ reader for test and benchmark meshes (the Stanford bunny):
// `v` and `f` lines only. Scenes themselves are glTF (scene.h).
#pragma once
#include <string>
#include <vector>

#include "scene/scene.h"

namespace caustica {

// Triangles of `v x y z` / `f a b c ...` lines (polygons fan-triangulated; v/vt/vn and negative
// indices accepted; material 0, normals and texture coordinates zero). Throws Error naming the file
// and line on unreadable files or bad indices.
std::vector<Triangle> loadObjTriangles(const std::string& path);

}  // namespace caustica
