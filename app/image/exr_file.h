// exr_file.h — OpenEXR files through the OpenEXR library (Debian libopenexr-dev): every compression
// (PIZ, ZIP, DWAA, DWAB, ...), half and float channels, multi-part and layered files; named layers
// and channels for writing (the beauty image plus AOVs such as albedo and normal).
#pragma once
#include <string>
#include <vector>

namespace caustica {

// One layer of an EXR image: channels `name.channel` (or just `channel` for the main layer, name ""),
// values interleaved per pixel, width * height * channels.size(), row 0 the top row.
struct ExrLayer {
  std::string name;                   // "" = the main layer (R, G, B and A); else e.g. "albedo", "normal"
  std::vector<std::string> channels;  // e.g. {"R", "G", "B"} or {"X", "Y", "Z"}
  std::vector<float> values;
  bool half = false;                  // writing: store as 16-bit half floats (else 32-bit float)
};

// Writes the layers into one single-part scanline file, ZIP-compressed (lossless). Throws Error naming
// the file on failure or when a layer's value count is not width * height * channels.
void writeExrLayers(const std::string& path, int width, int height, const std::vector<ExrLayer>& layers);

// Reads every layer of every part of an EXR file, channels converted to 32-bit float: the layer name is
// the channel name up to its last '.', prefixed by the part's name in a multi-part file whose parts
// share channel names. A file holding only luminance/chroma channels (Y, RY, BY) is returned as one
// main layer R, G, B (A). Images are the display window (pixels outside the data window are 0).
// Throws Error("PATH: cannot read EXR (...)") on an unreadable, truncated or oversized file.
std::vector<ExrLayer> readExrLayers(const std::string& path, int& width, int& height);

// The layer an image viewer shows: the main layer if it has R, G and B, else the first layer that
// has them, else the first layer with a luminance channel Y (grey). nullptr when there is none.
const ExrLayer* colorLayer(const std::vector<ExrLayer>& layers);

}  // namespace caustica
