// image_io.h — linear float images and their files: .png (tone-mapped 8-bit sRGB, + straight alpha),
// .exr (linear float RGB, + alpha) and .pfm (linear float RGB), chosen by extension. Row 0 is the top.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "image/tonemap.h"

namespace caustica {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // width * height * 3, linear radiance (mean over each pixel's footprint)
  // width * height coverage in [0, 1] (--background transparent), or empty: opaque. rgb is then
  // premultiplied (the mean over every sample, misses adding 0), as EXR stores it; PNG gets rgb / alpha.
  std::vector<float> alpha;
  float& at(int x, int y, int c) { return rgb[(static_cast<size_t>(y) * width + x) * 3 + c]; }
  float at(int x, int y, int c) const { return rgb[(static_cast<size_t>(y) * width + x) * 3 + c]; }
};

// Lower-case extension with the dot (".png"), or "" if none.
std::string fileExtension(const std::string& path);
// Throws Error unless `path` ends in .png, .exr or .pfm.
void checkImageExtension(const std::string& path);
// Writes by extension; PNG goes through `tone`. With alpha: PNG is RGBA with straight alpha (the colour
// is rgb / alpha, tone-mapped), EXR has an A channel (rgb premultiplied), PFM is refused (no alpha).
// Throws Error naming the file on failure.
void writeImage(const std::string& path, const Image& image, const ToneMapSettings& tone = {});
// Reads a linear .exr or .pfm file.
Image readImage(const std::string& path);
// One named layer of a multi-layer EXR file (render --aov): its channels are stored as "NAME.C" for
// each C of `channels` (e.g. "albedo.R"); the unnamed layer "" holds R, G, B (and A) of the image.
struct ImageLayer {
  std::string name;                   // e.g. "albedo"; "" for the image's own R, G, B, A
  std::vector<std::string> channels;  // e.g. {"R", "G", "B"}, {"X", "Y", "Z"} or {"Z"}
  std::vector<float> data;            // width * height * channels.size() floats, interleaved, row 0 the top
};
// Writes `image` (as writeImage writes an EXR: R, G, B, and A with alpha) and every layer in `layers`
// into one EXR file of 32-bit float channels. Throws Error naming the file on failure, or when a
// layer's data does not match the image size or a name repeats.
void writeExrLayers(const std::string& path, const Image& image, const std::vector<ImageLayer>& layers);
// Every channel of an EXR file grouped into layers by the text before the last '.' of the channel
// name ("" for R, G, B, A), in the file's order; width and height are set. Throws Error naming the file.
std::vector<ImageLayer> readExrLayers(const std::string& path, int& width, int& height);

// Writes 8-bit RGB bytes (w*h*3), or RGBA bytes (w*h*4) with channels = 4, as PNG.
void writePng(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb, int channels = 3);
// Straight (unpremultiplied) colour of a premultiplied pixel: rgb / alpha, 0 where alpha is 0.
std::vector<float> unpremultiplied(const Image& image);

}  // namespace caustica
