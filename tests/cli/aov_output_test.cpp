// aov_output_test.cpp — `render --aov`: the list is parsed with clear errors, the files beside a PNG or
// PFM are named as documented, and an EXR output carries the feature images as layers. No GL.
#include <doctest/doctest.h>

#include <filesystem>

#include "cli/aov_output.h"
#include "util/error.h"

using namespace caustica;
using namespace caustica::cli;
namespace fs = std::filesystem;

TEST_CASE("--aov: the list, its errors and where the files go") {
  CHECK(parseAovList("albedo,normal") == std::vector<Aov>{Aov::Albedo, Aov::Normal});
  CHECK(parseAovList("raw,albedo,raw").size() == 2);
  CHECK(parseAovList("all").size() == 5);
  CHECK_FALSE(aovsNeedFeatures(parseAovList("raw")));
  CHECK(aovsNeedFeatures(parseAovList("raw,depth")));
  CHECK_THROWS_WITH_AS(parseAovList("albedo,nromal"), doctest::Contains("unknown feature buffer 'nromal'"), Error);
  CHECK_THROWS_AS(parseAovList(""), Error);
  CHECK(aovFiles("out/img.png", parseAovList("albedo,raw")) == std::vector<std::string>{"out/img.albedo.pfm", "out/img.raw.png"});
  CHECK(aovFiles("img.pfm", parseAovList("variance")) == std::vector<std::string>{"img.variance.pfm"});
  CHECK(aovFiles("img.exr", parseAovList("all")).empty());  // layers of the EXR itself
}

TEST_CASE("--aov: an EXR output holds the feature images as layers, the means of the sums") {
  AccumulationState st;
  st.width = 2;
  st.height = 1;
  st.accum = {2, 4, 6, 2, 1, 1, 1, 1};      // means (1, 2, 3) and (1, 1, 1)
  st.albedo = {1, 1.2f, 1.4f, 20, 0.5f, 0.5f, 0.5f, 1};
  st.normal = {0, 2, 0, 6, 0, 0, 1, 4};     // normal (0, 1, 0), distance 3; (0, 0, 1), 4
  Image raw{2, 1, {1, 2, 3, 1, 1, 1}, {}};
  const fs::path p = fs::temp_directory_path() / "caustica_aov_test.exr";
  writeImageWithAovs(p.string(), raw, {}, parseAovList("albedo,normal,depth,raw"), raw, st);
  int w = 0, h = 0;
  const std::vector<ImageLayer> layers = readExrLayers(p.string(), w, h);
  std::vector<std::string> names;
  for (const ImageLayer& l : layers) names.push_back(l.name);
  CHECK(names == std::vector<std::string>{"", "albedo", "depth", "normal", "raw"});  // sorted by channel name
  for (const ImageLayer& l : layers) {
    if (l.name == "albedo") CHECK(l.data == std::vector<float>{0.7f, 0.6f, 0.5f, 0.5f, 0.5f, 0.5f});  // B, G, R
    if (l.name == "depth") CHECK(l.data == std::vector<float>{3.0f, 4.0f});
    if (l.name == "normal") CHECK(l.data == std::vector<float>{0, 1, 0, 0, 0, 1});  // X, Y, Z
  }
  CHECK_THROWS_AS(writeImageWithAovs(p.string(), raw, {}, parseAovList("albedo"), raw, AccumulationState{}), Error);
  fs::remove(p);
}
