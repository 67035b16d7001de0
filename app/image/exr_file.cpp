// exr_file.cpp — EXR reading and writing through OpenEXR's C++ API (multi-part input, float frame
// buffers); luminance/chroma files through its RGBA interface, which converts them.
#include "image/exr_file.h"

#include <algorithm>
#include <cstdint>
#include <exception>
#include <map>
#include <mutex>
#include <new>
#include <thread>

#include <ImathBox.h>
#include <half.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
#include <ImfOutputFile.h>
#include <ImfPartType.h>
#include <ImfRgbaFile.h>
#include <ImfThreading.h>

#include "util/error.h"

namespace caustica {
namespace {

constexpr std::int64_t kMaxSide = 1 << 16;         // pixels per side of an image read
constexpr std::int64_t kMaxPixels = 1ll << 28;     // pixels of an image read (each layer)
constexpr std::int64_t kMaxValues = 1ll << 29;     // floats of all layers read together (2 GiB)

// OpenEXR decodes and encodes lines in parallel on its global thread pool (DWA and PIZ are slow
// single-threaded); sized once to the machine.
void startThreads() {
  static std::once_flag once;
  std::call_once(once, [] {
    const unsigned n = std::thread::hardware_concurrency();
    Imf::setGlobalThreadCount(int(std::clamp(n, 1u, 16u)));
  });
}

std::int64_t boxWidth(const Imath::Box2i& b) { return std::int64_t(b.max.x) - b.min.x + 1; }
std::int64_t boxHeight(const Imath::Box2i& b) { return std::int64_t(b.max.y) - b.min.y + 1; }

[[noreturn]] void readFailed(const std::string& path, const std::string& what) {
  throw Error(path + ": cannot read EXR (" + what + ")");
}

// Splits "a.b.R" into layer "a.b" and channel "R" (no '.': the main layer "").
std::pair<std::string, std::string> splitChannel(const std::string& full) {
  const std::size_t dot = full.rfind('.');
  if (dot == std::string::npos) return {"", full};
  return {full.substr(0, dot), full.substr(dot + 1)};
}

bool hasChannel(const ImageLayer& l, const char* name) {
  return std::find(l.channels.begin(), l.channels.end(), name) != l.channels.end();
}

// A luminance/chroma image (Y with RY, BY): OpenEXR's RGBA interface converts it to RGB (half).
std::vector<ImageLayer> readLuminanceChroma(const std::string& path, const Imath::Box2i& display,
                                          const Imath::Box2i& data, bool alpha) {
  Imf::RgbaInputFile file(path.c_str());
  const std::int64_t w = boxWidth(data), h = boxHeight(data);
  std::vector<Imf::Rgba> pixels(std::size_t(w * h));
  file.setFrameBuffer(&pixels[0] - data.min.x - data.min.y * w, 1, std::size_t(w));
  file.readPixels(data.min.y, data.max.y);
  ImageLayer out;
  out.channels = {"R", "G", "B"};
  if (alpha) out.channels.push_back("A");
  const std::int64_t dw = boxWidth(display), dh = boxHeight(display);
  const std::size_t n = out.channels.size();
  out.data.assign(std::size_t(dw * dh) * n, 0.0f);
  for (std::int64_t y = std::max(data.min.y, display.min.y); y <= std::min(data.max.y, display.max.y); ++y)
    for (std::int64_t x = std::max(data.min.x, display.min.x); x <= std::min(data.max.x, display.max.x); ++x) {
      const Imf::Rgba& p = pixels[std::size_t((y - data.min.y) * w + (x - data.min.x))];
      float* o = &out.data[std::size_t((y - display.min.y) * dw + (x - display.min.x)) * n];
      o[0] = p.r;
      o[1] = p.g;
      o[2] = p.b;
      if (alpha) o[3] = p.a;
    }
  return {out};
}

}  // namespace

void writeExrLayers(const std::string& path, int width, int height, const std::vector<ImageLayer>& layers) {
  if (width < 1 || height < 1) throw Error(path + ": cannot write an empty EXR image");
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  // Half values converted up front: OpenEXR reads each slice in the type it is declared with.
  std::vector<std::vector<Imath::half>> halves(layers.size());
  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;
  Imf::FrameBuffer frame;
  for (std::size_t l = 0; l < layers.size(); ++l) {
    const ImageLayer& layer = layers[l];
    const std::size_t n = layer.channels.size();
    if (n == 0 || layer.data.size() != pixels * n)
      throw Error("internal: " + path + ": EXR layer '" + layer.name + "' holds " + std::to_string(layer.data.size()) +
                  " values for " + std::to_string(n) + " channels of " + std::to_string(pixels) + " pixels");
    const Imf::PixelType type = layer.half ? Imf::HALF : Imf::FLOAT;
    if (layer.half) halves[l].assign(layer.data.begin(), layer.data.end());
    for (std::size_t c = 0; c < n; ++c) {
      const std::string name = layer.name.empty() ? layer.channels[c] : layer.name + "." + layer.channels[c];
      if (header.channels().findChannel(name)) throw Error("internal: " + path + ": EXR channel " + name + " twice");
      header.channels().insert(name, Imf::Channel(type));
      char* base = layer.half ? reinterpret_cast<char*>(halves[l].data() + c)
                              : reinterpret_cast<char*>(const_cast<float*>(layer.data.data() + c));
      const std::size_t size = layer.half ? sizeof(Imath::half) : sizeof(float);
      frame.insert(name, Imf::Slice(type, base, size * n, size * n * std::size_t(width)));
    }
  }
  try {
    startThreads();
    Imf::OutputFile file(path.c_str(), header);
    file.setFrameBuffer(frame);
    file.writePixels(height);
  } catch (const std::exception& e) {
    throw Error(path + ": cannot write EXR (" + e.what() + ")");
  }
}

std::vector<ImageLayer> readExrLayers(const std::string& path, int& width, int& height) {
  try {
    startThreads();
    Imf::MultiPartInputFile file(path.c_str());
    const int parts = file.parts();
    // The image is the first part's display window; other parts must share it.
    const Imath::Box2i display = file.header(0).displayWindow();
    const std::int64_t dw = boxWidth(display), dh = boxHeight(display);
    if (dw < 1 || dh < 1 || dw > kMaxSide || dh > kMaxSide || dw * dh > kMaxPixels)
      readFailed(path, "its display window " + std::to_string(dw) + "x" + std::to_string(dh) +
                           " is empty or too large (at most " + std::to_string(kMaxSide) + " per side)");
    width = int(dw);
    height = int(dh);
    // Do the parts' channel names collide? Then layers are named after their parts.
    std::map<std::string, int> seen;
    for (int p = 0; p < parts; ++p)
      for (auto it = file.header(p).channels().begin(); it != file.header(p).channels().end(); ++it) ++seen[it.name()];
    const bool prefixParts = std::any_of(seen.begin(), seen.end(), [](const auto& s) { return s.second > 1; });

    std::vector<ImageLayer> layers;
    std::int64_t values = 0;
    for (int p = 0; p < parts; ++p) {
      const Imf::Header& header = file.header(p);
      if (header.hasType() && Imf::isDeepData(header.type())) continue;  // deep samples: no flat image
      const Imath::Box2i data = header.dataWindow();
      const std::int64_t w = boxWidth(data), h = boxHeight(data);
      if (w < 1 || h < 1 || w > kMaxSide || h > kMaxSide || w * h > kMaxPixels)
        readFailed(path, "the data window of part " + std::to_string(p) + " is empty or too large");
      const Imf::ChannelList& channels = header.channels();
      const bool luminanceChroma = channels.findChannel("Y") && (channels.findChannel("RY") || channels.findChannel("BY"));
      if (luminanceChroma && parts == 1) return readLuminanceChroma(path, display, data, channels.findChannel("A"));
      const std::string partName = prefixParts && header.hasName() ? header.name() : "";
      // Group the full-resolution channels by layer, in the file's (alphabetical) order.
      std::map<std::string, ImageLayer> byName;
      std::map<std::string, std::vector<std::string>> fileNames;  // layer -> its channels' names in the file
      std::vector<std::string> order;
      for (auto it = channels.begin(); it != channels.end(); ++it) {
        if (it.channel().xSampling != 1 || it.channel().ySampling != 1) continue;  // subsampled chroma
        auto [layer, channel] = splitChannel(it.name());
        if (!partName.empty()) layer = layer.empty() ? partName : partName + "." + layer;
        if (!byName.count(layer)) order.push_back(layer);
        ImageLayer& l = byName[layer];
        l.name = layer;
        l.channels.push_back(channel);
        fileNames[layer].push_back(it.name());
      }
      for (const std::string& name : order) {
        ImageLayer& l = byName[name];
        const std::size_t n = l.channels.size();
        values += std::int64_t(n) * (w * h + dw * dh);
        if (values > kMaxValues) readFailed(path, "its channels are too large to read together");
        std::vector<float> buffer(std::size_t(w * h) * n);
        Imf::FrameBuffer frame;
        for (std::size_t c = 0; c < n; ++c)
          frame.insert(fileNames[name][c], Imf::Slice::Make(Imf::FLOAT, buffer.data() + c, data, sizeof(float) * n,
                                                             sizeof(float) * n * std::size_t(w)));
        Imf::InputPart part(file, p);
        part.setFrameBuffer(frame);
        part.readPixels(data.min.y, data.max.y);
        // Into the display window.
        l.data.assign(std::size_t(dw * dh) * n, 0.0f);
        for (std::int64_t y = std::max(data.min.y, display.min.y); y <= std::min(data.max.y, display.max.y); ++y) {
          const std::int64_t x0 = std::max(data.min.x, display.min.x), x1 = std::min(data.max.x, display.max.x);
          if (x0 > x1) break;
          std::copy_n(&buffer[std::size_t((y - data.min.y) * w + (x0 - data.min.x)) * n], std::size_t(x1 - x0 + 1) * n,
                      &l.data[std::size_t((y - display.min.y) * dw + (x0 - display.min.x)) * n]);
        }
        layers.push_back(std::move(l));
      }
    }
    return layers;
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    readFailed(path, "out of memory");
  } catch (const std::exception& e) {
    std::string what = e.what();
    if (what.size() > 300) what = what.substr(0, 300) + "...";
    readFailed(path, what);
  }
}

const ImageLayer* colorLayer(const std::vector<ImageLayer>& layers) {
  const auto rgb = [](const ImageLayer& l) { return hasChannel(l, "R") && hasChannel(l, "G") && hasChannel(l, "B"); };
  for (const ImageLayer& l : layers)
    if (l.name.empty() && rgb(l)) return &l;
  for (const ImageLayer& l : layers)
    if (rgb(l)) return &l;
  for (const ImageLayer& l : layers)
    if (hasChannel(l, "Y")) return &l;
  return nullptr;
}

}  // namespace caustica
