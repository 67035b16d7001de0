// image_io.cpp — PNG through stb_image_write, EXR through OpenEXR (exr_file.h), PFM by hand.
#include "image/image_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include <stb_image_write.h>

#include "image/exr_file.h"
#include "util/error.h"

namespace caustica {

std::string fileExtension(const std::string& path) {
  size_t dot = path.rfind('.');
  size_t slash = path.rfind('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

void checkImageExtension(const std::string& path) {
  std::string ext = fileExtension(path);
  if (ext != ".png" && ext != ".exr" && ext != ".pfm")
    throw Error(path + ": unsupported image type '" + ext + "' (use .png, .exr or .pfm)");
}

void writePng(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb, int channels) {
  if (!stbi_write_png(path.c_str(), width, height, channels, rgb.data(), width * channels))
    throw Error(path + ": cannot write PNG");
}

namespace {

// RGBA floats, interleaved, of an image with alpha.
std::vector<float> interleaveAlpha(const Image& img) {
  const size_t n = static_cast<size_t>(img.width) * img.height;
  std::vector<float> rgba(n * 4);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = img.rgb[i * 3 + c];
    rgba[i * 4 + 3] = img.alpha[i];
  }
  return rgba;
}

// The image's own layer: linear float R, G, B (+ A: OpenEXR's convention is colour premultiplied by
// alpha, which rgb already is).
ImageLayer mainLayer(const Image& img) {
  ImageLayer main;
  main.channels = {"R", "G", "B"};
  main.data = img.rgb;
  if (!img.alpha.empty()) {
    main.channels.push_back("A");
    main.data = interleaveAlpha(img);
  }
  return main;
}

void writeExr(const std::string& path, const Image& img) { writeExrLayers(path, img.width, img.height, {mainLayer(img)}); }

void writePfm(const std::string& path, const Image& img) {
  std::ofstream f(path, std::ios::binary);
  if (!f) throw Error(path + ": cannot open for writing");
  f << "PF\n" << img.width << " " << img.height << "\n-1.0\n";  // negative scale: little endian
  for (int y = img.height - 1; y >= 0; --y)  // PFM rows run bottom to top
    f.write(reinterpret_cast<const char*>(&img.rgb[static_cast<size_t>(y) * img.width * 3]),
            static_cast<std::streamsize>(img.width) * 3 * sizeof(float));
  if (!f) throw Error(path + ": write failed");
}

Image readExr(const std::string& path) {
  int w = 0, h = 0;
  const std::vector<ImageLayer> layers = readExrLayers(path, w, h);
  const ImageLayer* layer = colorLayer(layers);
  if (!layer) {
    std::string names;
    for (const ImageLayer& l : layers)
      for (const std::string& c : l.channels) names += (names.empty() ? "" : ", ") + (l.name.empty() ? c : l.name + "." + c);
    throw Error(path + ": the EXR file has no R, G, B or Y channels (it has: " + (names.empty() ? "none" : names) + ")");
  }
  const auto find = [&](const char* name) -> int {
    for (std::size_t c = 0; c < layer->channels.size(); ++c)
      if (layer->channels[c] == name) return int(c);
    return -1;
  };
  const std::size_t n = layer->channels.size(), pixels = std::size_t(w) * std::size_t(h);
  const int y = find("Y");
  const int rgb[3] = {find("R") >= 0 ? find("R") : y, find("G") >= 0 ? find("G") : y, find("B") >= 0 ? find("B") : y};
  const int a = find("A");
  Image img{w, h, std::vector<float>(pixels * 3)};
  if (a >= 0) img.alpha.resize(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    for (int c = 0; c < 3; ++c) img.rgb[i * 3 + c] = layer->data[i * n + std::size_t(rgb[c])];
    if (a >= 0) img.alpha[i] = layer->data[i * n + std::size_t(a)];
  }
  return img;
}

Image readPfm(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw Error(path + ": cannot open");
  std::string magic;
  int w = 0, h = 0;
  double scale = 0;
  f >> magic >> w >> h >> scale;
  f.get();
  if (!f || magic != "PF" || w <= 0 || h <= 0 || w > 65536 || h > 65536 || scale == 0.0)
    throw Error(path + ": not a colour PFM file");
  if (scale > 0) throw Error(path + ": big-endian PFM is not supported");
  Image img{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  for (int y = h - 1; y >= 0; --y)
    f.read(reinterpret_cast<char*>(&img.rgb[static_cast<size_t>(y) * w * 3]), static_cast<std::streamsize>(w) * 3 * 4);
  if (!f) throw Error(path + ": truncated PFM file");
  return img;
}

}  // namespace

void writeExrLayers(const std::string& path, const Image& image, const std::vector<ImageLayer>& layers) {
  std::vector<ImageLayer> all = {mainLayer(image)};
  std::set<std::string> names;
  for (const ImageLayer& l : layers) {
    if (l.name.empty() || !names.insert(l.name).second || l.channels.empty())
      throw Error(path + ": internal: EXR layer '" + l.name + "' is unnamed, repeated or has no channels");
    all.push_back(l);
  }
  writeExrLayers(path, image.width, image.height, all);
}

std::vector<float> unpremultiplied(const Image& image) {
  std::vector<float> rgb = image.rgb;
  for (size_t i = 0; i < image.alpha.size(); ++i)
    for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = image.alpha[i] > 0.0f ? rgb[i * 3 + c] / image.alpha[i] : 0.0f;
  return rgb;
}

void writeImage(const std::string& path, const Image& image, const ToneMapSettings& tone) {
  checkImageExtension(path);
  std::string ext = fileExtension(path);
  if (!image.alpha.empty() && image.alpha.size() != static_cast<size_t>(image.width) * image.height)
    throw Error("internal: " + path + ": alpha of the wrong size");
  if (ext == ".png" && !image.alpha.empty()) {
    std::vector<std::uint8_t> rgb = tonemapImage(unpremultiplied(image), tone), rgba(image.alpha.size() * 4);
    for (size_t i = 0; i < image.alpha.size(); ++i) {
      for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = rgb[i * 3 + c];
      rgba[i * 4 + 3] = static_cast<std::uint8_t>(std::lround(std::clamp(image.alpha[i], 0.0f, 1.0f) * 255.0f));
    }
    writePng(path, image.width, image.height, rgba, 4);
  } else if (ext == ".pfm" && !image.alpha.empty()) {
    throw Error(path + ": PFM has no alpha channel: write .exr or .png with --background transparent");
  } else if (ext == ".png") writePng(path, image.width, image.height, tonemapImage(image.rgb, tone));
  else if (ext == ".exr") writeExr(path, image);
  else writePfm(path, image);
}

Image readImage(const std::string& path) {
  std::string ext = fileExtension(path);
  if (ext == ".exr") return readExr(path);
  if (ext == ".pfm") return readPfm(path);
  throw Error(path + ": cannot read '" + ext + "' images (use .exr or .pfm)");
}

}  // namespace caustica
