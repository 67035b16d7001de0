// shard.h — one render split over machines (docs/render-farm.md): `render --shard K/N` renders the K-th
// of N disjoint shares of the sample indices of a render, `merge` adds the shards' partials into the
// sums one machine would have made. No GL: the arithmetic and the checks on parts.
//
// Every sample's random stream depends only on (pixel, global sample index, seed) (glsl/lib/rng.glsl),
// so a shard that renders the sample indices [first, end) makes exactly those samples of the whole
// render; merge adds the Kahan-compensated sums of the parts in double and rounds once, so the merged
// image equals one machine's up to the order of float summation (measured in tests/gpu/shard_test.cpp).
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "cli/checkpoint.h"

namespace caustica::cli {

// The share of shard k of n (1 <= k <= n) of a render of `spp` samples per pixel: the samples are dealt
// in pairs, [2 floor((k-1) P / n), 2 floor(k P / n)) with P = ceil(spp / 2) pairs (the last share ends
// at spp), so every share starts at an even index: the half image (each pixel's odd-numbered samples,
// by the pixel's own count) then holds the same samples as one machine's. Shares of n > P shards can
// be empty (first == end).
SampleShare shareOf(int k, int n, int spp);
// "K/N" of --shard: throws Error naming the option unless 1 <= K <= N.
std::pair<int, int> parseShardOption(const std::string& text);
// "shard 2/4 (samples 16-31)" for messages; "(no samples)" for an empty share.
std::string describeShare(const SampleShare& s);

// One part given to merge: its file name (for messages) and its contents.
struct MergePart {
  std::string path;
  Checkpoint checkpoint;
};

struct MergeResult {
  // The added parts: state (sums, spp = samples of every part, sampleBase = the end of the merged
  // samples when they run from 0 without a gap), seed, scene hash and identity of the render.
  Checkpoint merged;
  std::uint32_t total = 0;  // the render's --spp
  // Sample indices [first, end) of the render that no part holds (empty when complete).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> missing;
  bool complete() const { return missing.empty(); }
  // Whether the merged samples are [0, n) for some n: then `merged` is a checkpoint render --resume
  // can continue (with a larger --spp).
  bool resumable = false;
};

// Adds the parts. Refuses (Error naming the file(s) and the problem) a part that is not a shard's
// partial, of another scene, with other settings (naming each differing setting), of another --spp
// total or image size, parts whose shares overlap (the same shard twice included), and, unless
// `allowPartial`, a shard that did not finish its share or samples no part holds. With `allowPartial`
// it adds what there is and lists what is missing in MergeResult::missing.
MergeResult mergeShards(const std::vector<MergePart>& parts, bool allowPartial);

// The sums of `b` added into `a` (same size; a's compensation kept exact): per value the exact-ish
// total (a - a.comp) + (b - b.comp) in double, rounded once to float, with the rounding error as the
// new compensation; the plain sums (visitPlainSums: half image, coverage) added in double and rounded.
// spp adds; sampleBase is left to the caller.
void addAccumulation(AccumulationState& a, const AccumulationState& b);

}  // namespace caustica::cli
