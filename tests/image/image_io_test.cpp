// image_io_test.cpp — linear outputs round-trip exactly (EXR float, PFM), PNG goes through the
// tone curve and sRGB encoding, and bad extensions are refused.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>

#include "util/error.h"
#include "image/image_io.h"

using namespace caustica;
namespace fs = std::filesystem;

namespace {
Image testImage() {
  Image img{5, 3, std::vector<float>(5 * 3 * 3)};
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x)
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = 0.001f * (x + 1) * std::pow(10.0f, float(y)) + 100.0f * c + 0.125f;
  img.at(0, 0, 0) = 12345.678f;  // linear output: no clamping
  return img;
}
}  // namespace

TEST_CASE("EXR and PFM keep linear float values, rows top first") {
  Image img = testImage();
  for (const char* ext : {".exr", ".pfm"}) {
    fs::path p = fs::temp_directory_path() / (std::string("caustica_io_test") + ext);
    writeImage(p.string(), img);
    Image back = readImage(p.string());
    REQUIRE(back.width == img.width);
    REQUIRE(back.height == img.height);
    for (size_t i = 0; i < img.rgb.size(); ++i) CHECK(back.rgb[i] == img.rgb[i]);
    fs::remove(p);
  }
}

TEST_CASE("tone mapping: clamp curve is the sRGB encoding of the clamped value; exposure scales") {
  ToneMapSettings clamp{0.0f, ToneCurve::Clamp};
  std::vector<float> rgb = {0.0f, 0.5f, 1.0f, 2.0f, -1.0f, NAN};
  auto out = tonemapImage(rgb, clamp);
  CHECK(out[0] == 0);
  CHECK(out[1] == 188);  // sRGB(0.5) = 0.7354 -> 187.5
  CHECK(out[2] == 255);
  CHECK(out[3] == 255);
  CHECK(out[4] == 0);
  CHECK(out[5] == 0);
  ToneMapSettings darker{-1.0f, ToneCurve::Clamp};
  CHECK(tonemapImage({1.0f, 1.0f, 1.0f}, darker)[0] == 188);
  // ACES is monotonic and maps large values below 1.
  ToneMapSettings aces{0.0f, ToneCurve::Aces};
  int last = -1;
  for (float v = 0.0f; v < 20.0f; v += 0.25f) {
    int b = tonemapImage({v, v, v}, aces)[0];
    CHECK(b >= last);
    last = b;
  }
}

TEST_CASE("only .png, .exr and .pfm are accepted, case-insensitively") {
  CHECK_NOTHROW(checkImageExtension("a/b.PNG"));
  CHECK_NOTHROW(checkImageExtension("x.exr"));
  CHECK_THROWS_WITH_AS(checkImageExtension("x.jpg"), doctest::Contains("x.jpg"), Error);
  CHECK_THROWS_AS(checkImageExtension("dir.png/file"), Error);
  CHECK_THROWS_AS(readImage("/nonexistent/file.exr"), Error);
}

TEST_CASE("PNG files are written") {
  fs::path p = fs::temp_directory_path() / "caustica_io_test.png";
  writeImage(p.string(), testImage());
  CHECK(fs::file_size(p) > 50);
  fs::remove(p);
}

TEST_CASE("EXR layers: named channel layers beside the image round-trip exactly (render --aov)") {
  Image img = testImage();
  img.alpha.assign(size_t(img.width) * img.height, 0.5f);
  ImageLayer albedo{"albedo", {"R", "G", "B"}, std::vector<float>(img.rgb.size())};
  ImageLayer depth{"depth", {"Z"}, std::vector<float>(size_t(img.width) * img.height)};
  for (size_t i = 0; i < albedo.data.size(); ++i) albedo.data[i] = 0.01f * float(i);
  for (size_t i = 0; i < depth.data.size(); ++i) depth.data[i] = 3.0f + float(i);
  const fs::path p = fs::temp_directory_path() / "caustica_io_layers.exr";
  writeExrLayers(p.string(), img, {albedo, depth});
  int w = 0, h = 0;
  const std::vector<ImageLayer> back = readExrLayers(p.string(), w, h);
  CHECK(w == img.width);
  CHECK(h == img.height);
  REQUIRE(back.size() == 3);
  for (const ImageLayer& l : back) {
    INFO("layer '", l.name, "'");
    if (l.name.empty()) {  // the image itself: A, B, G, R as the file sorts them
      REQUIRE(l.channels.size() == 4);
      for (size_t k = 0; k < 4; ++k)
        for (size_t i = 0; i < img.alpha.size(); ++i) {
          const std::string& c = l.channels[k];
          const float expected = c == "A" ? img.alpha[i] : img.rgb[i * 3 + (c == "R" ? 0 : c == "G" ? 1 : 2)];
          CHECK(l.data[i * 4 + k] == expected);
        }
    } else if (l.name == "albedo") {
      CHECK(l.channels == std::vector<std::string>{"B", "G", "R"});
      for (size_t i = 0; i < img.alpha.size(); ++i)
        for (int c = 0; c < 3; ++c) CHECK(l.data[i * 3 + size_t(2 - c)] == albedo.data[i * 3 + size_t(c)]);
    } else {
      CHECK(l.name == "depth");
      CHECK(l.data == depth.data);
    }
  }
  // The image itself reads back as before: the layers do not disturb readImage.
  Image rgb = readImage(p.string());
  for (size_t i = 0; i < img.rgb.size(); ++i) CHECK(rgb.rgb[i] == img.rgb[i]);
  CHECK_THROWS_AS(writeExrLayers(p.string(), img, {albedo, albedo}), Error);  // a repeated layer
  ImageLayer wrong = depth;
  wrong.data.pop_back();
  CHECK_THROWS_AS(writeExrLayers(p.string(), img, {wrong}), Error);
  fs::remove(p);
}
