// aov_output.h — `render --aov LIST`: the feature buffers (albedo, normal, depth, variance) and the raw
// image written beside the output, as layers of its EXR file or as files next to a PNG or PFM
// (docs/denoising.md). No GL: the images come from the renderer's saved sums.
#pragma once
#include <string>
#include <vector>

#include "gpu/renderer.h"
#include "image/image_io.h"
#include "image/tonemap.h"

namespace caustica::cli {

enum class Aov { Albedo, Normal, Depth, Variance, Raw };
const char* aovName(Aov a);  // "albedo" | "normal" | "depth" | "variance" | "raw"
// "albedo,normal,..." (any order, each once; "all" for every one); throws Error naming a bad entry.
std::vector<Aov> parseAovList(const std::string& text);
// Whether any of them needs the feature buffers (all but raw).
bool aovsNeedFeatures(const std::vector<Aov>& aovs);
// The files the AOVs go to besides `output` itself: none for an EXR output (they are its layers), else
// STEM.raw.EXT (the output's own format) and STEM.NAME.pfm for the feature images (linear floats, what
// OpenImageDenoise's oidnDenoise reads).
std::vector<std::string> aovFiles(const std::string& output, const std::vector<Aov>& aovs);
// Writes `image` to `output` (as writeImage does) with the AOVs: `raw` is the raw mean, `state` the
// renderer's saved sums (with feature sums when aovsNeedFeatures). Throws Error naming a file.
void writeImageWithAovs(const std::string& output, const Image& image, const ToneMapSettings& tone,
                        const std::vector<Aov>& aovs, const Image& raw, const AccumulationState& state);

}  // namespace caustica::cli
