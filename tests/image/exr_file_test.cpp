// exr_file_test.cpp — EXR through OpenEXR: named layers round-trip (float exactly, half to the nearest
// half), every compression reads back (lossless ones exactly, PXR24/B44/DWA within their precision),
// multi-part and layered files, luminance-only files, display windows, and clean errors.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfTiledOutputFile.h>
#include <half.h>

#include "image/exr_file.h"
#include "image/image_io.h"
#include "util/error.h"

using namespace caustica;
namespace fs = std::filesystem;

namespace {

std::string tempPath(const std::string& name) { return (fs::temp_directory_path() / ("caustica_exr_" + name)).string(); }

// A smooth HDR test pattern: value of channel c at (x, y), 0.01 .. ~50.
float pattern(int x, int y, int c) {
  return 0.01f + 0.5f * (1.0f + std::sin(0.21f * float(x) + 0.9f * float(c))) * std::exp(0.06f * float(y + c));
}

// Writes R, G, B (and optionally other channels) of `pattern` with OpenEXR itself, in `type` and `compression`.
void writePattern(const std::string& path, int w, int h, Imf::Compression compression, Imf::PixelType type,
                  const std::vector<std::string>& names = {"R", "G", "B"}) {
  Imf::Header header(w, h);
  header.compression() = compression;
  std::vector<std::vector<float>> f(names.size(), std::vector<float>(std::size_t(w * h)));
  std::vector<std::vector<half>> hv(names.size(), std::vector<half>(std::size_t(w * h)));
  Imf::FrameBuffer frame;
  for (std::size_t c = 0; c < names.size(); ++c) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        f[c][std::size_t(y * w + x)] = pattern(x, y, int(c));
        hv[c][std::size_t(y * w + x)] = half(pattern(x, y, int(c)));
      }
    header.channels().insert(names[c], Imf::Channel(type));
    char* base = type == Imf::HALF ? reinterpret_cast<char*>(hv[c].data()) : reinterpret_cast<char*>(f[c].data());
    const std::size_t size = type == Imf::HALF ? 2 : 4;
    frame.insert(names[c], Imf::Slice(type, base, size, size * std::size_t(w)));
  }
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(h);
}

}  // namespace

TEST_CASE("EXR: named layers round-trip, float exactly and half to the nearest half") {
  const int w = 7, h = 5;
  ImageLayer main{"", {"R", "G", "B", "A"}, {}, false};
  ImageLayer albedo{"albedo", {"R", "G", "B"}, {}, true};
  ImageLayer normal{"normal", {"X", "Y", "Z"}, {}, false};
  for (int i = 0; i < w * h; ++i) {
    for (int c = 0; c < 4; ++c) main.data.push_back(1000.0f * float(i) + 0.1234567f * float(c) + 1e-7f);
    for (int c = 0; c < 3; ++c) albedo.data.push_back(0.001f * float(i * 3 + c));
    for (int c = 0; c < 3; ++c) normal.data.push_back(-1.0f + 0.01f * float(i + c));
  }
  const std::string path = tempPath("layers.exr");
  writeExrLayers(path, w, h, {main, albedo, normal});
  int rw = 0, rh = 0;
  const std::vector<ImageLayer> back = readExrLayers(path, rw, rh);
  CHECK(rw == w);
  CHECK(rh == h);
  REQUIRE(back.size() == 3);
  for (const ImageLayer& l : back) {
    const ImageLayer& src = l.name.empty() ? main : l.name == "albedo" ? albedo : normal;
    REQUIRE(l.data.size() == src.data.size());
    // Channels come back in the file's alphabetical order: map by name.
    for (std::size_t c = 0; c < l.channels.size(); ++c) {
      std::size_t s = 0;
      while (src.channels[s] != l.channels[c]) ++s;
      int off = 0;
      for (int i = 0; i < w * h; ++i) {
        const float want = src.half ? float(half(src.data[std::size_t(i) * src.channels.size() + s]))
                                    : src.data[std::size_t(i) * src.channels.size() + s];
        off += l.data[std::size_t(i) * l.channels.size() + c] != want;
      }
      CHECK_MESSAGE(off == 0, l.name << "." << l.channels[c]);
    }
  }
  CHECK(colorLayer(back)->name.empty());
  const Image img = readImage(path);  // the main layer, with its alpha
  REQUIRE(img.alpha.size() == std::size_t(w * h));
  CHECK(img.rgb[3 * 4 + 1] == main.data[4 * 4 + 1]);
  CHECK(img.alpha[6] == main.data[6 * 4 + 3]);
  fs::remove(path);
}

TEST_CASE("EXR: an image with AOV layers (writeExrLayers of image_io.h) reads back as the image and its layers") {
  Image img{4, 2, std::vector<float>(4 * 2 * 3), std::vector<float>(4 * 2, 0.5f)};
  for (std::size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = 0.25f * float(i);
  ImageLayer depth{"depth", {"Z"}, std::vector<float>(8, 3.0f)};
  const std::string path = tempPath("aov.exr");
  writeExrLayers(path, img, {depth});
  const Image back = readImage(path);
  CHECK(back.rgb == img.rgb);
  CHECK(back.alpha == img.alpha);
  int w = 0, h = 0;
  const std::vector<ImageLayer> layers = readExrLayers(path, w, h);
  REQUIRE(layers.size() == 2);
  CHECK(layers[1].name == "depth");
  CHECK(layers[1].data == depth.data);
  CHECK_THROWS_WITH_AS(writeExrLayers(path, img, {ImageLayer{"", {"Z"}, depth.data}}), doctest::Contains("unnamed"), Error);
  CHECK_THROWS_WITH_AS(writeExrLayers(path, img, {ImageLayer{"d", {"Z"}, {1.0f}}}), doctest::Contains("holds 1 values"),
                       Error);
  fs::remove(path);
}

TEST_CASE("EXR: every compression reads back (lossless exactly, lossy within its precision)") {
  struct Case {
    Imf::Compression compression;
    const char* name;
    double tolerance;  // mean relative error allowed (0: exact)
  };
  // PXR24 keeps 24 of float's 32 bits (exact for half); B44 stores 4x4 blocks of half in 14 bytes;
  // DWA quantises DCT coefficients (level 45 by default). The lossy ones are held to their mean
  // relative error on this smooth image (measured 0.3-0.6 %) and to at most 20 % on any value (their
  // worst is at the darkest values next to bright ones); garbage or a shifted image fails both.
  const Case cases[] = {{Imf::NO_COMPRESSION, "none", 0.0}, {Imf::RLE_COMPRESSION, "RLE", 0.0},
                        {Imf::ZIPS_COMPRESSION, "ZIPS", 0.0}, {Imf::ZIP_COMPRESSION, "ZIP", 0.0},
                        {Imf::PIZ_COMPRESSION, "PIZ", 0.0}, {Imf::PXR24_COMPRESSION, "PXR24", 0.0},
                        {Imf::B44_COMPRESSION, "B44", 0.01}, {Imf::B44A_COMPRESSION, "B44A", 0.01},
                        {Imf::DWAA_COMPRESSION, "DWAA", 0.01}, {Imf::DWAB_COMPRESSION, "DWAB", 0.01}};
  const int w = 96, h = 48;
  for (const Case& k : cases)
    for (Imf::PixelType type : {Imf::HALF, Imf::FLOAT}) {
      const std::string path = tempPath(std::string(k.name) + ".exr");
      writePattern(path, w, h, k.compression, type);
      const Image img = readImage(path);
      REQUIRE(img.width == w);
      REQUIRE(img.height == h);
      double worst = 0.0, sum = 0.0;
      int exactOff = 0;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          for (int c = 0; c < 3; ++c) {
            const float stored = type == Imf::HALF ? float(half(pattern(x, y, c))) : pattern(x, y, c);
            const float got = img.at(x, y, c);
            const bool lossless = k.tolerance == 0.0 && !(k.compression == Imf::PXR24_COMPRESSION && type == Imf::FLOAT);
            if (lossless) exactOff += got != stored;
            const double e = std::abs(double(got) - stored) / stored;
            worst = std::max(worst, e);
            sum += e;
          }
      const double mean = sum / (w * h * 3);
      const std::string label = std::string(k.name) + (type == Imf::HALF ? " half" : " float");
      INFO(label << ": relative error mean " << mean
                               << ", worst " << worst);
      CHECK(exactOff == 0);
      if (k.tolerance > 0.0) {
        CHECK(mean <= k.tolerance);
        CHECK(worst <= 0.2);
      } else if (k.compression == Imf::PXR24_COMPRESSION && type == Imf::FLOAT) {
        CHECK(worst <= 2e-5);  // 16 of float's 23 mantissa bits kept
      }
      fs::remove(path);
    }
}

TEST_CASE("EXR: multi-part files, layered channels and luminance-only images") {
  const int w = 8, h = 4;
  SUBCASE("a two-part file: the colour part is found, parts sharing channel names are named by the part") {
    const std::string path = tempPath("multipart.exr");
    std::vector<float> z(std::size_t(w * h), 7.0f), rgb(std::size_t(w * h) * 3), a(std::size_t(w * h) * 3, 1.0f);
    for (int i = 0; i < w * h * 3; ++i) rgb[std::size_t(i)] = 0.5f + float(i);
    std::vector<Imf::Header> headers(2, Imf::Header(w, h));
    headers[0].setName("depth");
    headers[0].setType(Imf::SCANLINEIMAGE);
    headers[0].channels().insert("R", Imf::Channel(Imf::FLOAT));  // a depth pass stored in R, as some tools do
    headers[1].setName("beauty");
    headers[1].setType(Imf::SCANLINEIMAGE);
    for (const char* c : {"R", "G", "B"}) headers[1].channels().insert(c, Imf::Channel(Imf::FLOAT));
    {
      Imf::MultiPartOutputFile file(path.c_str(), headers.data(), 2);
      Imf::OutputPart depth(file, 0);
      Imf::FrameBuffer f0;
      f0.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(z.data()), 4, 4 * w));
      depth.setFrameBuffer(f0);
      depth.writePixels(h);
      Imf::OutputPart beauty(file, 1);
      Imf::FrameBuffer f1;
      for (int c = 0; c < 3; ++c)
        f1.insert(std::string(1, "RGB"[c]), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(rgb.data() + c), 12, 12 * w));
      beauty.setFrameBuffer(f1);
      beauty.writePixels(h);
    }
    int rw = 0, rh = 0;
    const std::vector<ImageLayer> layers = readExrLayers(path, rw, rh);
    REQUIRE(layers.size() == 2);
    CHECK(layers[0].name == "depth");
    CHECK(layers[1].name == "beauty");
    const Image img = readImage(path);
    CHECK(img.at(3, 2, 1) == rgb[std::size_t((2 * w + 3) * 3 + 1)]);
    CHECK(img.alpha.empty());
    fs::remove(path);
  }
  SUBCASE("a render-layer file without main channels: its first R, G, B layer") {
    const std::string path = tempPath("renderlayer.exr");
    writePattern(path, w, h, Imf::ZIP_COMPRESSION, Imf::FLOAT,
                 {"ViewLayer.Combined.B", "ViewLayer.Combined.G", "ViewLayer.Combined.R", "ViewLayer.Depth.Z"});
    const Image img = readImage(path);
    // Channel order in writePattern: B got pattern channel 0, G 1, R 2.
    CHECK(img.at(5, 1, 0) == pattern(5, 1, 2));
    CHECK(img.at(5, 1, 2) == pattern(5, 1, 0));
    fs::remove(path);
  }
  SUBCASE("a tiled file with mip levels: its full-resolution level") {
    const std::string path = tempPath("tiled.exr");
    Imf::Header header(w, h);
    header.setTileDescription(Imf::TileDescription(4, 4, Imf::MIPMAP_LEVELS));
    header.compression() = Imf::PIZ_COMPRESSION;
    std::vector<float> rgb(std::size_t(w * h) * 3);
    for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = 0.25f * float(i);
    Imf::FrameBuffer frame;
    for (int c = 0; c < 3; ++c) {
      header.channels().insert(std::string(1, "RGB"[c]), Imf::Channel(Imf::FLOAT));
      frame.insert(std::string(1, "RGB"[c]), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(rgb.data() + c), 12, 12 * w));
    }
    {
      Imf::TiledOutputFile file(path.c_str(), header);
      file.setFrameBuffer(frame);
      file.writeTiles(0, file.numXTiles(0) - 1, 0, file.numYTiles(0) - 1, 0);
      for (int level = 1; level < file.numLevels(); ++level) {  // coarser levels: any values
        std::vector<float> small(std::size_t(file.levelWidth(level) * file.levelHeight(level)) * 3, 1.0f);
        Imf::FrameBuffer f;
        for (int c = 0; c < 3; ++c)
          f.insert(std::string(1, "RGB"[c]), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(small.data() + c), 12,
                                                         12 * std::size_t(file.levelWidth(level))));
        file.setFrameBuffer(f);
        file.writeTiles(0, file.numXTiles(level) - 1, 0, file.numYTiles(level) - 1, level);
      }
    }
    const Image img = readImage(path);
    int off = 0;
    for (std::size_t i = 0; i < rgb.size(); ++i) off += img.rgb[i] != rgb[i];
    CHECK(off == 0);
    fs::remove(path);
  }
  SUBCASE("luminance only: grey") {
    const std::string path = tempPath("luminance.exr");
    writePattern(path, w, h, Imf::PIZ_COMPRESSION, Imf::HALF, {"Y"});
    const Image img = readImage(path);
    CHECK(img.at(2, 3, 0) == float(half(pattern(2, 3, 0))));
    CHECK(img.at(2, 3, 1) == img.at(2, 3, 0));
    CHECK(img.at(2, 3, 2) == img.at(2, 3, 0));
    fs::remove(path);
  }
  SUBCASE("no colour channels: the error lists the channels there are") {
    const std::string path = tempPath("depthonly.exr");
    writePattern(path, w, h, Imf::ZIP_COMPRESSION, Imf::FLOAT, {"Z"});
    CHECK_THROWS_WITH_AS(readImage(path), doctest::Contains("no R, G, B or Y channels (it has: Z)"), Error);
    fs::remove(path);
  }
}

TEST_CASE("EXR: the display window is the image; pixels outside the data window are 0") {
  const std::string path = tempPath("window.exr");
  Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(9, 5)), data(Imath::V2i(2, 1), Imath::V2i(5, 3));
  Imf::Header header(display, data);
  header.channels().insert("R", Imf::Channel(Imf::FLOAT));
  header.channels().insert("G", Imf::Channel(Imf::FLOAT));
  header.channels().insert("B", Imf::Channel(Imf::FLOAT));
  std::vector<float> px(4 * 3 * 3, 2.0f);
  Imf::FrameBuffer frame;
  for (int c = 0; c < 3; ++c)
    frame.insert(std::string(1, "RGB"[c]), Imf::Slice::Make(Imf::FLOAT, px.data() + c, data, 12, 12 * 4));
  {
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(3);
  }
  const Image img = readImage(path);
  REQUIRE(img.width == 10);
  REQUIRE(img.height == 6);
  CHECK(img.at(0, 0, 0) == 0.0f);
  CHECK(img.at(2, 1, 0) == 2.0f);
  CHECK(img.at(5, 3, 2) == 2.0f);
  CHECK(img.at(6, 3, 2) == 0.0f);
  fs::remove(path);
}

TEST_CASE("EXR: truncated, foreign and missing files get a clean error naming the file") {
  const std::string good = tempPath("good.exr"), cut = tempPath("cut.exr"), text = tempPath("text.exr");
  writePattern(good, 64, 64, Imf::DWAB_COMPRESSION, Imf::HALF);
  std::vector<char> bytes(fs::file_size(good));
  std::ifstream(good, std::ios::binary).read(bytes.data(), std::streamsize(bytes.size()));
  for (std::size_t keep : {std::size_t(3), std::size_t(40), bytes.size() / 2, bytes.size() - 5}) {
    std::ofstream(cut, std::ios::binary).write(bytes.data(), std::streamsize(keep));
    CAPTURE(keep);
    CHECK_THROWS_WITH_AS(readImage(cut), doctest::Contains((cut + ": cannot read EXR (").c_str()), Error);
  }
  std::ofstream(text) << "#?RADIANCE\nnot an exr\n";
  CHECK_THROWS_WITH_AS(readImage(text), doctest::Contains((text + ": cannot read EXR (").c_str()), Error);
  CHECK_THROWS_WITH_AS(readImage(tempPath("missing.exr")), doctest::Contains("cannot read EXR"), Error);
  for (const std::string& p : {good, cut, text}) fs::remove(p);
}
