// exr_file.h — OpenEXR files through the OpenEXR library (Debian libopenexr-dev): every compression
// (PIZ, ZIP, DWAA, DWAB, ...), half and float channels, multi-part and layered files; named layers
// and channels for writing (the beauty image plus AOVs such as albedo and normal).
#pragma once
#include <string>
#include <vector>

namespace caustica {

// One named layer of an EXR image: its channels are stored as "NAME.C" for each C of `channels` (e.g.
// "albedo.R"); the unnamed layer "" holds the image's own R, G, B (and A).
struct ImageLayer {
  std::string name;                   // e.g. "albedo"; "" for the image's own R, G, B, A
  std::vector<std::string> channels;  // e.g. {"R", "G", "B"}, {"X", "Y", "Z"} or {"Z"}
  std::vector<float> data;            // width * height * channels.size() floats, interleaved, row 0 the top
  bool half = false;                  // writing: store as 16-bit half floats (else 32-bit float)
};

// Writes the layers into one single-part scanline file, ZIP-compressed (lossless). Throws Error naming
// the file on failure, or when a layer's data is not width * height * channels floats or a channel's
// name repeats.
void writeExrLayers(const std::string& path, int width, int height, const std::vector<ImageLayer>& layers);

// Reads every layer of every part of an EXR file, channels converted to 32-bit float: the layer name is
// the channel name up to its last '.', prefixed by the part's name in a multi-part file whose parts
// share channel names. A file holding only luminance/chroma channels (Y, RY, BY) is returned as one
// main layer R, G, B (A). Images are the display window (pixels outside the data window are 0).
// Throws Error("PATH: cannot read EXR (...)") on an unreadable, truncated or oversized file.
std::vector<ImageLayer> readExrLayers(const std::string& path, int& width, int& height);

// The layer an image viewer shows: the main layer if it has R, G and B, else the first layer that
// has them, else the first layer with a luminance channel Y (grey). nullptr when there is none.
const ImageLayer* colorLayer(const std::vector<ImageLayer>& layers);

}  // namespace caustica
