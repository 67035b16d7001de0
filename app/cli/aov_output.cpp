// aov_output.cpp — parsing --aov and writing the feature images as EXR layers or PFM files.
#include "cli/aov_output.h"

#include <algorithm>
#include <sstream>

#include "image/denoise.h"
#include "util/error.h"

namespace caustica::cli {

namespace {

constexpr Aov kAllAovs[] = {Aov::Albedo, Aov::Normal, Aov::Depth, Aov::Variance, Aov::Raw};

// STEM.NAME.EXT beside `output` (STEM: the output without its extension).
std::string besideOutput(const std::string& output, const std::string& name, const std::string& ext) {
  const std::string outExt = fileExtension(output);
  return output.substr(0, output.size() - outExt.size()) + "." + name + ext;
}

// The image an AOV writes, and the channels its EXR layer keeps of it (R, G, B of the image in order).
struct AovImage {
  Image image;
  std::vector<std::string> channels;
};

AovImage aovImage(Aov a, const Image& raw, const FeatureImages* f) {
  switch (a) {
    case Aov::Albedo: return {f->albedo, {"R", "G", "B"}};
    case Aov::Normal: return {f->normal, {"X", "Y", "Z"}};
    case Aov::Depth: return {f->depth, {"Z"}};
    case Aov::Variance: return {f->variance, {"Y"}};
    case Aov::Raw: {
      Image opaque = raw;
      opaque.alpha.clear();  // the layer's colour is premultiplied like the main image; alpha is the main image's
      return {opaque, {"R", "G", "B"}};
    }
  }
  return {};
}

}  // namespace

const char* aovName(Aov a) {
  switch (a) {
    case Aov::Albedo: return "albedo";
    case Aov::Normal: return "normal";
    case Aov::Depth: return "depth";
    case Aov::Variance: return "variance";
    case Aov::Raw: return "raw";
  }
  return "?";
}

std::vector<Aov> parseAovList(const std::string& text) {
  std::vector<Aov> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    if (item == "all") {
      for (Aov a : kAllAovs)
        if (std::find(out.begin(), out.end(), a) == out.end()) out.push_back(a);
      continue;
    }
    bool known = false;
    for (Aov a : kAllAovs)
      if (item == aovName(a)) {
        known = true;
        if (std::find(out.begin(), out.end(), a) == out.end()) out.push_back(a);
      }
    if (!known)
      throw Error("option --aov: unknown feature buffer '" + item + "' (expected albedo, normal, depth, variance, raw or all)");
  }
  if (out.empty()) throw Error("option --aov needs a list such as albedo,normal");
  return out;
}

bool aovsNeedFeatures(const std::vector<Aov>& aovs) {
  return std::any_of(aovs.begin(), aovs.end(), [](Aov a) { return a != Aov::Raw; });
}

std::vector<std::string> aovFiles(const std::string& output, const std::vector<Aov>& aovs) {
  std::vector<std::string> files;
  if (fileExtension(output) == ".exr") return files;
  for (Aov a : aovs) files.push_back(besideOutput(output, aovName(a), a == Aov::Raw ? fileExtension(output) : ".pfm"));
  return files;
}

void writeImageWithAovs(const std::string& output, const Image& image, const ToneMapSettings& tone,
                        const std::vector<Aov>& aovs, const Image& raw, const AccumulationState& state) {
  FeatureImages features;
  if (aovsNeedFeatures(aovs)) {
    if (!state.hasFeatures()) throw Error("internal: --aov needs the feature buffers");
    DenoiseInput in{state.width, state.height, &state.accum, &state.albedo, &state.normal};
    features = featureImages(in);
  }
  if (fileExtension(output) == ".exr") {
    std::vector<ImageLayer> layers;
    for (Aov a : aovs) {
      AovImage ai = aovImage(a, raw, &features);
      ImageLayer layer{aovName(a), ai.channels, {}};
      const size_t n = static_cast<size_t>(ai.image.width) * ai.image.height, k = ai.channels.size();
      layer.data.resize(n * k);
      for (size_t i = 0; i < n; ++i)
        for (size_t c = 0; c < k; ++c) layer.data[i * k + c] = ai.image.rgb[i * 3 + c];
      layers.push_back(std::move(layer));
    }
    writeExrLayers(output, image, layers);
    return;
  }
  writeImage(output, image, tone);
  const std::vector<std::string> files = aovFiles(output, aovs);
  for (size_t i = 0; i < aovs.size(); ++i) {
    if (aovs[i] == Aov::Raw) writeImage(files[i], raw, tone);
    else writeImage(files[i], aovImage(aovs[i], raw, &features).image);
  }
}

}  // namespace caustica::cli
