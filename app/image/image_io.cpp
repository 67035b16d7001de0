// image_io.cpp — PNG through stb_image_write, EXR through tinyexr, PFM by hand.
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
#include <tinyexr.h>

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

void writeExr(const std::string& path, const Image& img) {
  // tinyexr's SaveEXR takes interleaved RGB(A) floats and writes them as 32-bit float channels.
  const char* err = nullptr;
  std::vector<float> rgba;
  if (!img.alpha.empty()) {  // OpenEXR's convention: colour premultiplied by alpha, which rgb already is
    const size_t n = static_cast<size_t>(img.width) * img.height;
    rgba.resize(n * 4);
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = img.rgb[i * 3 + c];
      rgba[i * 4 + 3] = img.alpha[i];
    }
  }
  int rc = rgba.empty() ? SaveEXR(img.rgb.data(), img.width, img.height, 3, 0 /* float, not half */, path.c_str(), &err)
                        : SaveEXR(rgba.data(), img.width, img.height, 4, 0, path.c_str(), &err);
  if (rc != TINYEXR_SUCCESS) {
    std::string msg = err ? err : "error " + std::to_string(rc);
    if (err) FreeEXRErrorMessage(err);
    throw Error(path + ": cannot write EXR (" + msg + ")");
  }
}

// One channel of an EXR file being written: its full name and where its floats are.
struct ExrChannel {
  std::string name;
  const float* data;  // first value; `stride` floats between pixels
  int stride;
};

void writeExrChannels(const std::string& path, int width, int height, std::vector<ExrChannel> channels) {
  // OpenEXR keeps a file's channels sorted by name (its channel list is a map): write them so.
  std::sort(channels.begin(), channels.end(), [](const ExrChannel& a, const ExrChannel& b) { return a.name < b.name; });
  const size_t n = static_cast<size_t>(width) * height;
  std::vector<std::vector<float>> planes(channels.size(), std::vector<float>(n));
  std::vector<unsigned char*> planePtrs(channels.size());
  std::vector<EXRChannelInfo> infos(channels.size());
  std::vector<int> types(channels.size(), TINYEXR_PIXELTYPE_FLOAT);
  for (size_t c = 0; c < channels.size(); ++c) {
    if (channels[c].name.size() >= sizeof infos[c].name) throw Error(path + ": EXR channel name too long: " + channels[c].name);
    std::memset(&infos[c], 0, sizeof infos[c]);
    std::memcpy(infos[c].name, channels[c].name.c_str(), channels[c].name.size() + 1);
    for (size_t i = 0; i < n; ++i) planes[c][i] = channels[c].data[i * static_cast<size_t>(channels[c].stride)];
    planePtrs[c] = reinterpret_cast<unsigned char*>(planes[c].data());
  }
  EXRHeader header;
  InitEXRHeader(&header);
  EXRImage image;
  InitEXRImage(&image);
  image.num_channels = static_cast<int>(channels.size());
  image.images = planePtrs.data();
  image.width = width;
  image.height = height;
  header.num_channels = static_cast<int>(channels.size());
  header.channels = infos.data();
  header.pixel_types = types.data();
  header.requested_pixel_types = types.data();
  header.compression_type = TINYEXR_COMPRESSIONTYPE_ZIP;
  const char* err = nullptr;
  const int rc = SaveEXRImageToFile(&image, &header, path.c_str(), &err);
  if (rc != TINYEXR_SUCCESS) {
    std::string msg = err ? err : "error " + std::to_string(rc);
    if (err) FreeEXRErrorMessage(err);
    throw Error(path + ": cannot write EXR (" + msg + ")");
  }
}

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
  float* rgba = nullptr;
  int w = 0, h = 0;
  const char* err = nullptr;
  if (LoadEXR(&rgba, &w, &h, path.c_str(), &err) != TINYEXR_SUCCESS) {
    std::string msg = err ? err : "unreadable";
    if (err) FreeEXRErrorMessage(err);
    throw Error(path + ": cannot read EXR (" + msg + ")");
  }
  Image img{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3)};
  for (size_t i = 0; i < static_cast<size_t>(w) * h; ++i)
    for (int c = 0; c < 3; ++c) img.rgb[i * 3 + c] = rgba[i * 4 + c];
  std::free(rgba);
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
  const size_t n = static_cast<size_t>(image.width) * image.height;
  std::vector<ExrChannel> channels;
  const char* rgb[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) channels.push_back({rgb[c], image.rgb.data() + c, 3});
  if (!image.alpha.empty()) channels.push_back({"A", image.alpha.data(), 1});
  std::set<std::string> names;
  for (const ImageLayer& l : layers) {
    if (l.name.empty() || !names.insert(l.name).second || l.channels.empty())
      throw Error(path + ": internal: EXR layer '" + l.name + "' is unnamed, repeated or has no channels");
    if (l.data.size() != n * l.channels.size())
      throw Error(path + ": internal: EXR layer '" + l.name + "' does not match the image size");
    for (size_t c = 0; c < l.channels.size(); ++c)
      channels.push_back({l.name + "." + l.channels[c], l.data.data() + c, static_cast<int>(l.channels.size())});
  }
  writeExrChannels(path, image.width, image.height, channels);
}

std::vector<ImageLayer> readExrLayers(const std::string& path, int& width, int& height) {
  EXRVersion version;
  const char* err = nullptr;
  auto fail = [&](const char* what) {
    std::string msg = err ? err : what;
    if (err) FreeEXRErrorMessage(err);
    return Error(path + ": cannot read EXR (" + msg + ")");
  };
  if (ParseEXRVersionFromFile(&version, path.c_str()) != TINYEXR_SUCCESS) throw fail("not an EXR file");
  EXRHeader header;
  InitEXRHeader(&header);
  if (ParseEXRHeaderFromFile(&header, &version, path.c_str(), &err) != TINYEXR_SUCCESS) throw fail("bad header");
  for (int c = 0; c < header.num_channels; ++c) header.requested_pixel_types[c] = TINYEXR_PIXELTYPE_FLOAT;
  EXRImage image;
  InitEXRImage(&image);
  if (LoadEXRImageFromFile(&image, &header, path.c_str(), &err) != TINYEXR_SUCCESS) {
    FreeEXRHeader(&header);
    throw fail("unreadable");
  }
  width = image.width;
  height = image.height;
  std::vector<ImageLayer> layers;
  const size_t n = static_cast<size_t>(width) * height;
  if (image.images == nullptr) {  // tiled files: not written by caustica
    FreeEXRImage(&image);
    FreeEXRHeader(&header);
    throw Error(path + ": cannot read EXR (tiled files are not supported here)");
  }
  for (int c = 0; c < header.num_channels; ++c) {
    const std::string full = header.channels[c].name;
    const size_t dot = full.rfind('.');
    const std::string layer = dot == std::string::npos ? "" : full.substr(0, dot);
    const std::string channel = dot == std::string::npos ? full : full.substr(dot + 1);
    auto it = std::find_if(layers.begin(), layers.end(), [&](const ImageLayer& l) { return l.name == layer; });
    if (it == layers.end()) it = layers.insert(layers.end(), ImageLayer{layer, {}, {}});
    it->channels.push_back(channel);
  }
  for (ImageLayer& l : layers) {
    l.data.resize(n * l.channels.size());
    for (size_t k = 0; k < l.channels.size(); ++k) {
      const std::string full = l.name.empty() ? l.channels[k] : l.name + "." + l.channels[k];
      for (int c = 0; c < header.num_channels; ++c)
        if (full == header.channels[c].name) {
          const float* plane = reinterpret_cast<const float*>(image.images[c]);
          for (size_t i = 0; i < n; ++i) l.data[i * l.channels.size() + k] = plane[i];
        }
    }
  }
  FreeEXRImage(&image);
  FreeEXRHeader(&header);
  return layers;
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
