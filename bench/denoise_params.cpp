// denoise_params.cpp — how the denoiser's settings (app/image/denoise.h) trade noise for bias: runs the
// C++ twin with every combination of the given settings over checkpoints of `render --denoise
// --checkpoint` (their feature sums) and prints, per checkpoint and setting, relMSE against a reference
// and the image's and caustic region's mean over the reference's. A benchmark, not a test.
//   build/bench/denoise_params --reference REF.exr [--caustic x0,y0,x1,y1] [--iterations 3,4,5]
//       [--residual-passes 0,5] [--sigma-luminance 4,8] [--sigma-depth 1] [--albedo-floor 0.01]
//       [--deficit] [--breakdown] [--dump PREFIX] [--image FILE] CHECKPOINT...
// (caustic region in normalized image coordinates, as bench/scenes.json gives it; --deficit: where the
// filter moved energy, by reference value; --breakdown: relMSE near feature edges and elsewhere; --dump:
// each denoised image and its error map as PNG; --image: the figures of a given image too).
#include <cstdio>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "cli/bench/bench_metrics.h"
#include "cli/checkpoint.h"
#include "image/denoise.h"
#include "image/image_io.h"
#include "util/error.h"

using namespace caustica;

namespace {

std::vector<double> numbers(const std::string& text) {
  std::vector<double> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) out.push_back(std::atof(item.c_str()));
  return out;
}

Image meanImage(const std::vector<float>& sums, int w, int h) {
  Image img{w, h, std::vector<float>(static_cast<size_t>(w) * h * 3), {}};
  for (size_t i = 0; i < static_cast<size_t>(w) * h; ++i)
    for (int c = 0; c < 3; ++c) img.rgb[i * 3 + c] = sums[i * 4 + 3] > 0.0f ? sums[i * 4 + c] / sums[i * 4 + 3] : 0.0f;
  return img;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::string refPath;
    std::vector<double> caustic, iterations = {5}, residuals = {5}, sigmaR = {0.3}, bounds = {2}, sigmaL = {6}, sigmaZ = {1}, floors = {0.01};
    std::vector<std::string> checkpoints;
    std::vector<std::string> images;  // --image FILE: also print these images' figures (e.g. render --denoise outputs)
    std::string dump;
    bool deficit = false, breakdown = false;  // also print where energy went, and the relMSE near feature edges  // --dump PREFIX: each denoised image and its relMSE map as PREFIX-N.png / PREFIX-N-error.png
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw Error(a + " needs a value");
        return argv[++i];
      };
      if (a == "--reference") refPath = next();
      else if (a == "--caustic") caustic = numbers(next());
      else if (a == "--iterations") iterations = numbers(next());
      else if (a == "--sigma-luminance") sigmaL = numbers(next());
      else if (a == "--sigma-depth") sigmaZ = numbers(next());
      else if (a == "--albedo-floor") floors = numbers(next());
      else if (a == "--residual-passes") residuals = numbers(next());
      else if (a == "--sigma-residual") sigmaR = numbers(next());
      else if (a == "--residual-bound") bounds = numbers(next());
      else if (a == "--dump") dump = next();
      else if (a == "--image") images.push_back(next());
      else if (a == "--deficit") deficit = true;
      else if (a == "--breakdown") breakdown = true;
      else checkpoints.push_back(a);
    }
    if (refPath.empty() || (checkpoints.empty() && images.empty())) throw Error("usage: denoise_params --reference REF.exr [options] CHECKPOINT...");
    const Image ref = readImage(refPath);
    const PixelRect whole = fullImage(ref.width, ref.height);
    const bool hasCaustic = caustic.size() == 4;
    const PixelRect region = hasCaustic ? cropToPixels(CropRect{caustic[0], caustic[1], caustic[2], caustic[3]}, ref.width, ref.height) : whole;
    const double refMean = imageMean(ref, whole), refCaustic = imageMean(ref, region);
    std::printf("| checkpoint | spp | filter | relMSE | caustic relMSE | mean / ref | caustic mean / ref |\n|---|--:|---|--:|--:|--:|--:|\n");
    for (const std::string& path : images) {
      const Image img = readImage(path);
      std::printf("| %s | | image | %.4g | %s | %.4f | %s |\n", path.c_str(), relMse(img, ref),
                  hasCaustic ? formatDouble("%.4g", relMse(img, ref, region)).c_str() : "-", imageMean(img, whole) / refMean,
                  hasCaustic ? formatDouble("%.4f", imageMean(img, region) / refCaustic).c_str() : "-");
    }
    for (const std::string& path : checkpoints) {
      const cli::Checkpoint ck = cli::readCheckpoint(path);
      const AccumulationState& st = ck.state;
      if (!st.hasFeatures()) throw Error(path + ": no feature sums (render with --denoise)");
      auto row = [&](const std::string& filter, const Image& img) {
        std::printf("| %s | %d | %s | %.4g | %s | %.4f | %s |\n", path.c_str(), st.spp, filter.c_str(), relMse(img, ref),
                    hasCaustic ? formatDouble("%.4g", relMse(img, ref, region)).c_str() : "-", imageMean(img, whole) / refMean,
                    hasCaustic ? formatDouble("%.4f", imageMean(img, region) / refCaustic).c_str() : "-");
        std::fflush(stdout);
      };
      row("raw", meanImage(st.accum, st.width, st.height));
      const DenoiseInput in{st.width, st.height, &st.accum, &st.albedo, &st.normal};
      for (double it : iterations)
       for (double rp : residuals)
        for (double sr : sigmaR)
         for (double rb : bounds)
        for (double l : sigmaL)
          for (double z : sigmaZ)
            for (double f : floors) {
              DenoiseSettings s;
              s.iterations = static_cast<int>(it);
              s.residualPasses = static_cast<int>(rp);
              s.sigmaResidual = static_cast<float>(sr);
              s.residualBound = static_cast<float>(rb);
              s.sigmaLuminance = static_cast<float>(l);
              s.sigmaDepth = static_cast<float>(z);
              s.albedoFloor = static_cast<float>(f);
              char name[128];
              std::snprintf(name, sizeof name, "it %d, res %d, sR %g, bound %g, sL %g, sZ %g, floor %g", s.iterations, s.residualPasses, sr, rb, l, z, f);
              const Image out = meanImage(denoiseSums(in, s), st.width, st.height);
              row(name, out);
              if (deficit) {  // where the denoised image lost (or gained) energy against the raw one
                const Image raw = meanImage(st.accum, st.width, st.height);
                double bucket[4] = {0, 0, 0, 0}, total = 0;
                for (size_t k = 0; k < raw.rgb.size(); ++k) {
                  const double r = ref.rgb[k];
                  const int b = r < 0.1 ? 0 : r < 1.0 ? 1 : r < 5.0 ? 2 : 3;
                  bucket[b] += raw.rgb[k] - out.rgb[k];
                  total += ref.rgb[k];
                }
                std::printf("  raw - denoised, share of the reference's sum, by reference value <0.1, <1, <5, >=5: %.4f %.4f %.4f %.4f\n",
                            bucket[0] / total, bucket[1] / total, bucket[2] / total, bucket[3] / total);
              }
              if (breakdown) {  // relMSE share of pixels near a feature edge (normal, distance, albedo)
                FeatureImages fi = featureImages(in);
                const int w = st.width, h = st.height;
                double edgeErr = 0, restErr = 0, edgeRaw = 0, restRaw = 0;
                int edgeN = 0;
                const Image raw = meanImage(st.accum, w, h);
                for (int y = 0; y < h; ++y)
                  for (int x = 0; x < w; ++x) {
                    bool edge = false;
                    for (int j = -2; j <= 2; ++j)
                      for (int k = -2; k <= 2; ++k) {
                        int qx = std::min(std::max(x + k, 0), w - 1), qy = std::min(std::max(y + j, 0), h - 1);
                        double dn = 0, dz = std::abs(fi.depth.at(x, y, 0) - fi.depth.at(qx, qy, 0)), da = 0;
                        for (int c = 0; c < 3; ++c) {
                          dn += fi.normal.at(x, y, c) * fi.normal.at(qx, qy, c);
                          da += std::abs(fi.albedo.at(x, y, c) - fi.albedo.at(qx, qy, c));
                        }
                        if (dn < 0.95 || dz > 0.05 * fi.depth.at(x, y, 0) || da > 0.05) edge = true;
                      }
                    double e = 0, r = 0;
                    for (int c = 0; c < 3; ++c) {
                      double d = out.at(x, y, c) - ref.at(x, y, c), dr = raw.at(x, y, c) - ref.at(x, y, c), q = double(ref.at(x, y, c)) * ref.at(x, y, c) + 0.01;
                      e += d * d / q / 3;
                      r += dr * dr / q / 3;
                    }
                    if (edge) { edgeErr += e; edgeRaw += r; ++edgeN; } else { restErr += e; restRaw += r; }
                  }
                const double N = double(w) * h;
                std::printf("  near edges: %.1f %% of pixels, relMSE share %.4g (raw %.4g); elsewhere %.4g (raw %.4g)\n",
                            100.0 * edgeN / N, edgeErr / N, edgeRaw / N, restErr / N, restRaw / N);
              }
              if (!dump.empty()) {
                static int n = 0;
                const std::string stem = dump + "-" + std::to_string(n++);
                writeImage(stem + ".png", out);
                Image err = out;  // (x - ref)^2 / (ref^2 + eps) per channel, x 10 for display (clamp)
                for (size_t k = 0; k < err.rgb.size(); ++k) {
                  const double d = out.rgb[k] - ref.rgb[k];
                  err.rgb[k] = static_cast<float>(10.0 * d * d / (double(ref.rgb[k]) * ref.rgb[k] + kRelMseEpsilon));
                }
                ToneMapSettings clamp;
                clamp.curve = ToneCurve::Clamp;
                writeImage(stem + "-error.png", err, clamp);
                std::printf("  (%s)\n", stem.c_str());
              }
            }
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "denoise_params: %s\n", e.what());
    return 1;
  }
}
