// shard.cpp — shares of sample indices, and merging shards' partials with every refusal named.
#include "cli/shard.h"

#include <algorithm>
#include <cstdlib>

#include "cli/bench/bench_metrics.h"
#include "util/error.h"

namespace caustica::cli {

SampleShare shareOf(int k, int n, int spp) {
  if (n < 1 || k < 1 || k > n || spp < 0) throw Error("internal: shareOf(" + std::to_string(k) + ", " + std::to_string(n) + ")");
  const std::uint64_t pairs = (std::uint64_t(spp) + 1) / 2;
  const std::uint64_t a = (std::uint64_t(k) - 1) * pairs / std::uint64_t(n), b = std::uint64_t(k) * pairs / std::uint64_t(n);
  SampleShare s;
  s.index = k;
  s.count = n;
  s.first = std::uint32_t(std::min<std::uint64_t>(2 * a, std::uint64_t(spp)));
  s.end = std::uint32_t(std::min<std::uint64_t>(2 * b, std::uint64_t(spp)));
  s.total = std::uint32_t(spp);
  return s;
}

std::pair<int, int> parseShardOption(const std::string& text) {
  const auto bad = [&] {
    return Error("option --shard needs K/N with 1 <= K <= N (the K-th of N shares of the samples), got '" + text + "'");
  };
  const size_t slash = text.find('/');
  if (slash == std::string::npos) throw bad();
  const auto number = [&](const std::string& s) {
    char* end = nullptr;
    const long v = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || *end != '\0' || v < 1 || v > (1 << 30)) throw bad();
    return int(v);
  };
  const int k = number(text.substr(0, slash)), n = number(text.substr(slash + 1));
  if (k > n) throw bad();
  return {k, n};
}

namespace {
std::string range(std::uint32_t first, std::uint32_t end) {
  return end == first + 1 ? std::to_string(first) : std::to_string(first) + "-" + std::to_string(end - 1);
}
}  // namespace

std::string describeShare(const SampleShare& s) {
  return "shard " + std::to_string(s.index) + "/" + std::to_string(s.count) +
         (s.first == s.end ? " (no samples)" : " (samples " + range(s.first, s.end) + ")");
}

void addAccumulation(AccumulationState& a, const AccumulationState& b) {
  if (a.width != b.width || a.height != b.height || a.accum.size() != b.accum.size() || a.comp.size() != b.comp.size() ||
      a.accum.size() != a.comp.size())
    throw Error("internal: addAccumulation of states of different sizes");
  for (size_t i = 0; i < a.accum.size(); ++i) {
    // The exact-ish value each Kahan pair stands for is sum - compensation (accumulate.glsl).
    const double total = (double(a.accum[i]) - double(a.comp[i])) + (double(b.accum[i]) - double(b.comp[i]));
    const float rounded = float(total);
    a.accum[i] = rounded;
    a.comp[i] = float(double(rounded) - total);
  }
  visitPlainSums(a, [&](const char* name, std::vector<float>& into) {
    const std::vector<float>* from = nullptr;
    visitPlainSums(b, [&](const char* other, const std::vector<float>& v) {
      if (std::string(other) == name) from = &v;
    });
    if (into.size() != from->size()) throw Error(std::string("internal: addAccumulation: the ") + name + " sums differ in size");
    for (size_t i = 0; i < into.size(); ++i) into[i] = float(double(into[i]) + double((*from)[i]));
  });
  a.spp += b.spp;
}

namespace {

using SampleRanges = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

// Each part on its own: a shard's partial, consistent with its share.
void checkEachPart(const std::vector<MergePart>& parts) {
  for (const MergePart& p : parts) {
    const Checkpoint& ck = p.checkpoint;
    if (!ck.shard)
      throw Error(p.path + ": not a shard's partial but the checkpoint of a whole render (continue it with "
                           "render --resume; merge takes the files render --shard K/N writes)");
    const SampleShare& s = *ck.shard;
    if (ck.state.sampleBase < s.first || ck.state.sampleBase > s.end ||
        std::uint32_t(ck.state.spp) != ck.state.sampleBase - s.first)
      throw Error(p.path + ": " + describeShare(s) + " holds " + std::to_string(ck.state.spp) +
                  " samples ending before sample " + std::to_string(ck.state.sampleBase) + ", outside its share");
  }
}

// The parts together: one render (scene, settings, --spp, size) as the first part `ref`.
void checkPartsAgree(const std::vector<MergePart>& parts) {
  const MergePart& ref = parts.front();
  for (const MergePart& p : parts) {
    const Checkpoint& a = ref.checkpoint;
    const Checkpoint& b = p.checkpoint;
    if (b.sceneHash != a.sceneHash)
      throw Error(p.path + " and " + ref.path + " are renders of different scene files (scene " + hex64(b.sceneHash) +
                  " and " + hex64(a.sceneHash) + ")");
    const std::string diff = identityDifference(a.identity, b.identity, ref.path, p.path);
    if (!diff.empty()) throw Error(p.path + " and " + ref.path + " are renders with other settings: " + diff);
    if (b.shard->total != a.shard->total)
      throw Error(p.path + " and " + ref.path + " are shards of renders of different --spp (" +
                  std::to_string(b.shard->total) + " and " + std::to_string(a.shard->total) + ")");
    if (b.state.width != a.state.width || b.state.height != a.state.height || b.state.accum.size() != a.state.accum.size())
      throw Error(p.path + " and " + ref.path + " have different image sizes (" + std::to_string(b.state.width) + "x" +
                  std::to_string(b.state.height) + " and " + std::to_string(a.state.width) + "x" +
                  std::to_string(a.state.height) + ")");
    // Every per-pixel sum (half image, coverage, ...: visitPlainSums) is in both or in neither.
    visitPlainSums(a.state, [&](const char* name, const std::vector<float>& sa) {
      visitPlainSums(b.state, [&](const char* other, const std::vector<float>& sb) {
        if (std::string(name) == other && sa.size() != sb.size())
          throw Error(p.path + " and " + ref.path + ": one holds the " + name + " sums and the other not (or of another size)");
      });
    });
  }
}

// The parts sorted by their share's first sample; no two shares may overlap (the same shard given twice included).
std::vector<const MergePart*> sortedDisjointParts(const std::vector<MergePart>& parts) {
  std::vector<const MergePart*> order;
  for (const MergePart& p : parts) order.push_back(&p);
  std::stable_sort(order.begin(), order.end(), [](const MergePart* x, const MergePart* y) {
    return x->checkpoint.shard->first < y->checkpoint.shard->first;
  });
  for (size_t i = 0; i + 1 < order.size(); ++i) {
    const SampleShare& a = *order[i]->checkpoint.shard;
    for (size_t j = i + 1; j < order.size(); ++j) {
      const SampleShare& b = *order[j]->checkpoint.shard;
      if (b.first >= a.end) break;
      if (b.first == b.end) continue;  // an empty share overlaps nothing
      const bool same = a == b;
      throw Error(order[i]->path + " (" + describeShare(a) + ") and " + order[j]->path + " (" + describeShare(b) +
                  ") overlap" + (same ? ": the same shard given twice" : ": their samples would count twice"));
    }
  }
  return order;
}

// The first incomplete shard (its unrendered tail is missing) with how to continue it; empty when none.
std::string firstIncomplete(const std::vector<const MergePart*>& order) {
  std::string incomplete;
  for (const MergePart* p : order) {
    const Checkpoint& ck = p->checkpoint;
    if (ck.state.sampleBase < ck.shard->end) {
      if (incomplete.empty())
        incomplete = p->path + ": " + describeShare(*ck.shard) + " is incomplete: it holds " +
                     (ck.state.spp == 0 ? std::string("no samples") : "samples " + range(ck.shard->first, ck.state.sampleBase)) +
                     " (continue it with render --shard " + std::to_string(ck.shard->index) + "/" +
                     std::to_string(ck.shard->count) + " --resume " + p->path + ")";
    }
  }
  return incomplete;
}

// Every sample index of [0, total) not held by a part (`order` sorted by first sample).
SampleRanges missingSamples(const std::vector<const MergePart*>& order, std::uint32_t total) {
  SampleRanges missing;
  std::uint32_t covered = 0;
  for (const MergePart* p : order) {
    const SampleShare& s = *p->checkpoint.shard;
    if (s.first == s.end) continue;
    if (s.first > covered) missing.emplace_back(covered, s.first);
    if (p->checkpoint.state.sampleBase < s.end) missing.emplace_back(p->checkpoint.state.sampleBase, s.end);
    covered = std::max(covered, s.end);
  }
  if (covered < total) missing.emplace_back(covered, total);
  return missing;
}

// The missing sample ranges, each with the shards K/N that would render it when every part splits the
// render into the same N.
std::string describeMissing(const std::vector<MergePart>& parts, const SampleRanges& missing, std::uint32_t total) {
  const int n = parts.front().checkpoint.shard->count;
  bool sameN = true;
  for (const MergePart& p : parts) sameN = sameN && p.checkpoint.shard->count == n;
  std::string what;
  for (const auto& [first, end] : missing) {
    std::string shards;
    if (sameN)
      for (int k = 1; k <= n; ++k) {
        const SampleShare s = shareOf(k, n, int(total));
        if (s.first < end && s.end > first) shards += (shards.empty() ? "" : ", ") + std::to_string(k) + "/" + std::to_string(n);
      }
    what += (what.empty() ? "" : "; ") + (shards.empty() ? "" : "shard " + shards + " ") + "(samples " + range(first, end) + ")";
  }
  return what;
}

// The parts' sums added in sample order (the order does not matter beyond float rounding) into `result`,
// with the seed, scene hash and identity of `ref` (the first part given).
void addParts(const Checkpoint& ref, const std::vector<const MergePart*>& order, MergeResult& result) {
  Checkpoint& m = result.merged;
  m.seed = ref.seed;
  m.sceneHash = ref.sceneHash;
  m.identity = ref.identity;
  m.state = order.front()->checkpoint.state;
  for (size_t i = 1; i < order.size(); ++i) addAccumulation(m.state, order[i]->checkpoint.state);
  // Resumable only when the samples run from 0 without a gap: then the next sample is their count.
  const std::uint32_t held = std::uint32_t(m.state.spp);
  std::uint32_t gapless = 0;
  for (const MergePart* p : order)
    if (p->checkpoint.shard->first == gapless) gapless = p->checkpoint.state.sampleBase;
  result.resumable = gapless == held;
  m.state.sampleBase = held;
}

}  // namespace

MergeResult mergeShards(const std::vector<MergePart>& parts, bool allowPartial) {
  if (parts.empty()) throw Error("no parts to merge");
  checkEachPart(parts);
  checkPartsAgree(parts);
  const std::vector<const MergePart*> order = sortedDisjointParts(parts);
  MergeResult result;
  result.total = parts.front().checkpoint.shard->total;
  const std::string incomplete = firstIncomplete(order);
  result.missing = missingSamples(order, result.total);
  if (!allowPartial) {
    if (!incomplete.empty()) throw Error(incomplete + "; or merge what there is with --partial");
    if (!result.missing.empty())
      throw Error("missing " + describeMissing(parts, result.missing, result.total) + " of the " +
                  std::to_string(result.total) +
                  "-spp render: no part given holds them (render them with --shard, or merge what there is with --partial)");
  }
  addParts(parts.front().checkpoint, order, result);
  return result;
}

}  // namespace caustica::cli
