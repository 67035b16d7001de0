// obj_mesh.cpp — minimal OBJ reader (positions and faces).
#include "scene/obj_mesh.h"

#include <fstream>
#include <sstream>

#include "util/error.h"

namespace caustica {

std::vector<Triangle> loadObjTriangles(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open");
  std::vector<glm::vec3> verts;
  std::vector<Triangle> tris;
  std::string line;
  for (int lineNo = 1; std::getline(in, line); ++lineNo) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "v") {
      glm::vec3 p;
      if (!(ls >> p.x >> p.y >> p.z)) throw Error(path + ":" + std::to_string(lineNo) + ": bad vertex");
      verts.push_back(p);
    } else if (tag == "f") {
      std::vector<long> idx;
      std::string tok;
      while (ls >> tok) {
        long i = std::strtol(tok.c_str(), nullptr, 10);
        long k = i < 0 ? static_cast<long>(verts.size()) + i : i - 1;
        if (i == 0 || k < 0 || k >= static_cast<long>(verts.size()))
          throw Error(path + ":" + std::to_string(lineNo) + ": face index " + tok + " out of range");
        idx.push_back(k);
      }
      for (size_t k = 2; k < idx.size(); ++k) {
        tris.push_back(makeTriangle(verts[idx[0]], verts[idx[k - 1]], verts[idx[k]]));
      }
    }
  }
  return tris;
}

}  // namespace caustica
