// image_io.h — linear float images and their files: .png (tone-mapped 8-bit sRGB, + straight alpha),
// .exr (linear float RGB, + alpha; through OpenEXR, exr_file.h) and .pfm (linear float RGB), chosen by extension. Row 0 is the top.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "image/exr_file.h"
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
// Reads a linear .exr (its colour layer, exr_file.h: R, G, B or Y, and A when present, any compression,
// half or float) or .pfm file.
Image readImage(const std::string& path);
// Writes `image` (as writeImage writes an EXR: R, G, B, and A with alpha) and every layer in `layers`
// (named, e.g. "albedo" with channels R, G, B: ImageLayer in exr_file.h) into one EXR file through
// OpenEXR. Throws Error naming the file on failure, or when a layer is unnamed, repeated or does not
// match the image size. (readExrLayers in exr_file.h reads them back.)
void writeExrLayers(const std::string& path, const Image& image, const std::vector<ImageLayer>& layers);
// Writes 8-bit RGB bytes (w*h*3), or RGBA bytes (w*h*4) with channels = 4, as PNG.
void writePng(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb, int channels = 3);
// Straight (unpremultiplied) colour of a premultiplied pixel: rgb / alpha, 0 where alpha is 0.
std::vector<float> unpremultiplied(const Image& image);

}  // namespace caustica
