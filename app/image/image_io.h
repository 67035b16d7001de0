// image_io.h — linear float images and their files: .png (tone-mapped 8-bit sRGB), .exr (linear
// float RGB) and .pfm (linear float RGB), chosen by extension. Row 0 is the top of the image.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "image/tonemap.h"

namespace caustica {

struct Image {
  int width = 0, height = 0;
  std::vector<float> rgb;  // width * height * 3, linear radiance (mean over each pixel's footprint)
  float& at(int x, int y, int c) { return rgb[(static_cast<size_t>(y) * width + x) * 3 + c]; }
  float at(int x, int y, int c) const { return rgb[(static_cast<size_t>(y) * width + x) * 3 + c]; }
};

// Lower-case extension with the dot (".png"), or "" if none.
std::string fileExtension(const std::string& path);
// Throws Error unless `path` ends in .png, .exr or .pfm.
void checkImageExtension(const std::string& path);
// Writes by extension; PNG goes through `tone`. Throws Error naming the file on failure.
void writeImage(const std::string& path, const Image& image, const ToneMapSettings& tone = {});
// Reads a linear .exr or .pfm file.
Image readImage(const std::string& path);
// Writes 8-bit RGB bytes (w*h*3) as PNG.
void writePng(const std::string& path, int width, int height, const std::vector<std::uint8_t>& rgb);

}  // namespace caustica
