// cmd_merge.cpp — `caustica merge`: adds the partials of a render's shards (render --shard K/N) into
// the image one machine would have rendered (docs/render-farm.md). Needs no GPU.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "cli/aov_output.h"
#include "cli/checkpoint.h"
#include "cli/cli_common.h"
#include "cli/commands.h"
#include "cli/shard.h"
#include "image/denoise.h"
#include "image/error_estimate.h"
#include "image/image_io.h"
#include "util/error.h"

namespace caustica::cli {

int cmdMerge(const std::vector<std::string>& args) {
  const std::vector<OptionSpec> specs = {
      {"--output", "-o", "FILE",
       "the merged render: .png (tone-mapped sRGB), .exr or .pfm (linear), or .ckpt (a checkpoint that render "
       "--resume can extend to more samples)"},
      {"--partial", "", "",
       "merge the parts there are even if samples are missing (shards not given or not finished): the image of "
       "the samples held, each pixel the mean of its own samples"},
      {"--denoise", "", "",
       "write the denoised image of the merged samples (docs/denoising.md): the shards must have been rendered with "
       "--denoise or --aov (their partials then hold the feature sums); the denoiser's C++ twin runs on the CPU"},
      {"--aov", "", "LIST",
       "also write albedo, normal, depth, variance, raw (or all) of the merged samples, as render --aov does"},
      {"--exposure", "", "STOPS", "PNG exposure in stops (default 0)"},
      {"--tonemap", "", "CURVE", "PNG tone curve: aces (default) or clamp"},
      {"--quiet", "-q", "", "print nothing but errors"},
  };
  Options opts("caustica merge PART... -o OUTPUT [options]",
               "Adds the partials of one render's shards (the files 'caustica render --shard K/N' writes) and\n"
               "writes the image of all their samples: the image one machine would have rendered with the same\n"
               "scene, settings and --spp, up to float rounding (docs/render-farm.md). Refuses parts of another\n"
               "scene, with other settings, --spp or size, overlapping parts and, unless --partial, missing or\n"
               "unfinished shards, naming the files and what is wrong.",
               specs);
  if (!opts.parse(args)) return 0;
  const bool quiet = opts.has("--quiet");
  if (!opts.has("--output")) throw Error("option --output (-o) is required: where the merged render goes");
  const std::string out = opts.get("--output", "");
  const bool toCheckpoint = fileExtension(out) == ".ckpt";
  if (!toCheckpoint) checkImageExtension(out);
  ToneMapSettings tone;
  tone.exposureStops = static_cast<float>(opts.getDouble("--exposure", tone.exposureStops));
  tone.curve = parseToneCurve(opts.get("--tonemap", toneCurveName(tone.curve)));
  if (opts.positional().empty()) throw Error("no parts given: caustica merge PART... -o OUTPUT");
  const bool denoise = opts.has("--denoise");
  const std::vector<Aov> aovs = opts.has("--aov") ? parseAovList(opts.get("--aov", "")) : std::vector<Aov>{};
  if (toCheckpoint && (denoise || !aovs.empty()))
    throw Error(out + ": --denoise and --aov write images; a .ckpt output keeps the feature sums for a later render or merge");
  checkWritableFile(out, "output");
  for (const std::string& f : aovFiles(out, aovs)) checkWritableFile(f, "--aov");

  std::vector<MergePart> parts;
  for (const std::string& path : opts.positional()) {
    std::error_code ec;
    if (std::filesystem::equivalent(path, out, ec))
      throw Error(path + ": a part is also the output; write the merged render elsewhere");
    parts.push_back({path, readCheckpoint(path)});
    const Checkpoint& ck = parts.back().checkpoint;
    if (ck.shard)
      note(quiet, path + ": " + describeShare(*ck.shard) + " of " + std::to_string(ck.shard->total) + " spp, " +
                      (ck.state.sampleBase == ck.shard->end ? std::string("complete")
                                                            : "holds " + std::to_string(ck.state.spp) + " of its " +
                                                                  std::to_string(ck.shard->end - ck.shard->first)));
  }
  const MergeResult r = mergeShards(parts, opts.has("--partial"));
  const AccumulationState& st = r.merged.state;
  if ((denoise || aovsNeedFeatures(aovs)) && !st.hasFeatures())
    throw Error(parts.front().path + ": the parts hold no feature sums (their shards were rendered without --denoise or "
                                     "--aov): merge without " + std::string(denoise ? "--denoise" : "--aov") +
                ", or render the shards with it");
  if (!r.complete()) {
    std::string missing;
    for (const auto& [first, end] : r.missing)
      missing += (missing.empty() ? "" : ", ") + std::to_string(first) + (end == first + 1 ? "" : "-" + std::to_string(end - 1));
    // Always said: the output is not the whole render.
    std::fprintf(stderr, "caustica: partial merge: %d of %u samples per pixel; missing samples %s\n", st.spp, r.total,
                 missing.c_str());
  }
  const ErrorEstimate e = estimateError(st.width, st.height, st.accum, st.comp, st.half);
  char line[160];
  std::snprintf(line, sizeof line, "merged %zu part(s): %d of %u spp, %dx%d, estimated relMSE %.4g", parts.size(), st.spp,
                r.total, st.width, st.height, e.image);
  note(quiet, line);
  if (toCheckpoint) {
    if (!r.resumable)
      throw Error(out + ": the merged samples have gaps, so they cannot be continued as a checkpoint; write an image, "
                        "or give the missing shards");
    writeCheckpoint(out, r.merged);
  } else {
    if (!st.coverage.empty() && fileExtension(out) == ".pfm")
      throw Error(out + ": PFM has no alpha channel: write .exr or .png for a render with --background transparent");
    const std::vector<float>* coverage = st.coverage.empty() ? nullptr : &st.coverage;
    const Image raw = meanImage(st.width, st.height, st.accum, coverage);
    if (!denoise) {
      writeImageWithAovs(out, raw, tone, aovs, raw, st);
    } else {
      // The same filter as render --denoise (its GLSL's C++ twin), on the merged sums.
      const auto t0 = std::chrono::steady_clock::now();
      const std::vector<float> sums = denoiseSums(DenoiseInput{st.width, st.height, &st.accum, &st.albedo, &st.normal});
      char ms[64];
      std::snprintf(ms, sizeof ms, "denoised on the CPU in %.1f ms",
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      note(quiet, ms);
      writeImageWithAovs(out, meanImage(st.width, st.height, sums, coverage), tone, aovs, raw, st);
    }
  }
  note(quiet, "wrote " + std::filesystem::absolute(out).string());
  return 0;
}

}  // namespace caustica::cli
