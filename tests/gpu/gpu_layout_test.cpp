// gpu_layout_test.cpp — docs/architecture.md ("One layout for C++ and GLSL") quotes the sizes, bindings and
// units of glsl/shared/gpu_layout.h in a table; this test reads that table and holds every number to the code.
#include <doctest/doctest.h>

#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>

#include "scene/assets.h"
#include "shared/gpu_layout.h"

using namespace caustica;

namespace {

// Every name the table must quote, with its value in the code: a struct is its size in bytes.
const std::map<std::string, long long>& layoutFacts() {
  static const std::map<std::string, long long> facts = {
      {"BvhNode", sizeof(gpu::BvhNode)},
      {"BvhWideNode", sizeof(gpu::BvhWideNode)},
      {"TriGeom", sizeof(gpu::TriGeom)},
      {"kTriShadeWords", gpu::kTriShadeWords},
      {"kTriShadeWordsTextured", gpu::kTriShadeWordsTextured},
      {"Material", sizeof(gpu::Material)},
      {"LightNode", sizeof(gpu::LightNode)},
      {"TexInfo", sizeof(gpu::TexInfo)},
      {"InstanceRecord", sizeof(gpu::InstanceRecord)},
      {"InstanceShade", sizeof(gpu::InstanceShade)},
      {"Counters", sizeof(gpu::Counters)},
      {"FrameParams", sizeof(gpu::FrameParams)},
      {"CasterParams", sizeof(gpu::CasterParams)},
      {"PointLights", sizeof(gpu::PointLights)},
      {"EnvironmentParams", sizeof(gpu::EnvironmentParams)},
      {"PunctualParams", sizeof(gpu::PunctualParams)},
      {"CAUSTICA_BINDING_NODES", CAUSTICA_BINDING_NODES},
      {"CAUSTICA_BINDING_TRIGEOM", CAUSTICA_BINDING_TRIGEOM},
      {"CAUSTICA_BINDING_TRISHADE", CAUSTICA_BINDING_TRISHADE},
      {"CAUSTICA_BINDING_MATERIALS", CAUSTICA_BINDING_MATERIALS},
      {"CAUSTICA_BINDING_EMITTERS", CAUSTICA_BINDING_EMITTERS},
      {"CAUSTICA_BINDING_TEXELS", CAUSTICA_BINDING_TEXELS},
      {"CAUSTICA_BINDING_COUNTERS", CAUSTICA_BINDING_COUNTERS},
      {"CAUSTICA_BINDING_SPLIT_FIRST", CAUSTICA_BINDING_SPLIT_FIRST},
      {"CAUSTICA_BINDING_FRAME", CAUSTICA_BINDING_FRAME},
      {"CAUSTICA_BINDING_CASTERS", CAUSTICA_BINDING_CASTERS},
      {"CAUSTICA_BINDING_POINT_LIGHTS", CAUSTICA_BINDING_POINT_LIGHTS},
      {"CAUSTICA_BINDING_ENVIRONMENT", CAUSTICA_BINDING_ENVIRONMENT},
      {"CAUSTICA_BINDING_PUNCTUAL", CAUSTICA_BINDING_PUNCTUAL},
      {"CAUSTICA_TEXUNIT_ENV_MAP", CAUSTICA_TEXUNIT_ENV_MAP},
      {"CAUSTICA_TEXUNIT_ENV_MARGINAL", CAUSTICA_TEXUNIT_ENV_MARGINAL},
      {"CAUSTICA_TEXUNIT_BVH_NODES", CAUSTICA_TEXUNIT_BVH_NODES},
      {"CAUSTICA_TEXUNIT_TRI_GEOM", CAUSTICA_TEXUNIT_TRI_GEOM},
      {"CAUSTICA_TEXUNIT_MATERIALS", CAUSTICA_TEXUNIT_MATERIALS},
      {"CAUSTICA_TEXUNIT_LIGHT_NODES", CAUSTICA_TEXUNIT_LIGHT_NODES},
      {"CAUSTICA_TEXUNIT_BVH_WIDE", CAUSTICA_TEXUNIT_BVH_WIDE},
      {"CAUSTICA_TEXUNIT_TEXELS", CAUSTICA_TEXUNIT_TEXELS},
      {"CAUSTICA_TEXUNIT_TEX_INFO", CAUSTICA_TEXUNIT_TEX_INFO},
      {"CAUSTICA_TEXUNIT_TRI_SHADE", CAUSTICA_TEXUNIT_TRI_SHADE},
      {"CAUSTICA_IMAGE_ACCUM", CAUSTICA_IMAGE_ACCUM},
      {"CAUSTICA_IMAGE_COMP", CAUSTICA_IMAGE_COMP},
      {"CAUSTICA_IMAGE_DISPLAY", CAUSTICA_IMAGE_DISPLAY},
      {"CAUSTICA_IMAGE_HALF", CAUSTICA_IMAGE_HALF},
      {"CAUSTICA_IMAGE_TILES", CAUSTICA_IMAGE_TILES},
      {"CAUSTICA_IMAGE_COVERAGE", CAUSTICA_IMAGE_COVERAGE},
      {"CAUSTICA_IMAGE_ALBEDO", CAUSTICA_IMAGE_ALBEDO},
      {"CAUSTICA_IMAGE_NORMAL", CAUSTICA_IMAGE_NORMAL},
      {"CAUSTICA_WORKGROUP_X", CAUSTICA_WORKGROUP_X},
      {"CAUSTICA_WORKGROUP_Y", CAUSTICA_WORKGROUP_Y},
      {"CAUSTICA_BVH_STACK", CAUSTICA_BVH_STACK},
      {"CAUSTICA_BVH_WIDE_STACK", CAUSTICA_BVH_WIDE_STACK},
      {"CAUSTICA_MAX_SPLIT_PARTS", CAUSTICA_MAX_SPLIT_PARTS},
      {"CAUSTICA_MAX_CASTERS", CAUSTICA_MAX_CASTERS},
      {"CAUSTICA_MAX_POINT_LIGHTS", CAUSTICA_MAX_POINT_LIGHTS},
      {"CAUSTICA_MAX_PUNCTUAL", CAUSTICA_MAX_PUNCTUAL},
  };
  return facts;
}

// The rows "| `NAME` | NUMBER | ..." between the table's markers in docs/architecture.md.
std::map<std::string, long long> quotedFacts(const std::string& path) {
  std::ifstream f(path);
  REQUIRE_MESSAGE(f.good(), "cannot read " << path);
  const std::regex row(R"(^\| `(\w+)` \| (\d+) \|)");
  std::map<std::string, long long> quoted;
  bool inside = false;
  for (std::string line; std::getline(f, line);) {
    if (line.find("<!-- gpu_layout_test: begin -->") != std::string::npos) inside = true;
    if (line.find("<!-- gpu_layout_test: end -->") != std::string::npos) inside = false;
    std::smatch m;
    if (inside && std::regex_search(line, m, row)) quoted[m[1]] = std::stoll(m[2]);
  }
  return quoted;
}

}  // namespace

TEST_CASE("docs/architecture.md quotes gpu_layout.h's sizes, bindings and units as the code has them") {
  const std::string doc = sourceDir() + "/docs/architecture.md";
  const std::map<std::string, long long> quoted = quotedFacts(doc);
  for (const auto& [name, value] : layoutFacts()) {
    INFO(doc << ": `" << name << "`");
    const auto it = quoted.find(name);
    CHECK_MESSAGE(it != quoted.end(), "missing from the table");
    if (it != quoted.end()) CHECK(it->second == value);
  }
  for (const auto& [name, value] : quoted) {
    INFO(doc << ": `" << name << "` | " << value);
    CHECK_MESSAGE(layoutFacts().count(name) == 1, "quoted but not known to this test: add it to layoutFacts()");
  }
}
