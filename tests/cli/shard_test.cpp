// shard_test.cpp — shares of sample indices and merge without a GL context: shares are disjoint, cover
// the render and start at even indices for any N and spp; the shard line round-trips in the checkpoint;
// merging adds Kahan pairs to the exact total; every bad set of parts is refused naming the problem.
#include <doctest/doctest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli/checkpoint.h"
#include "cli/shard.h"
#include "util/error.h"

using namespace caustica;
using namespace caustica::cli;
namespace fs = std::filesystem;

namespace {

std::string tempPath(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("caustica-shard-test-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

// A shard's partial of a 2x1 render: each of its samples adds `perSample` (+ the sample index / 1000,
// so that parts differ) to every channel of every pixel, in the order a renderer adds them (Kahan).
Checkpoint part(int k, int n, int spp, int held = -1, std::uint32_t seed = 1, std::uint64_t scene = 42) {
  Checkpoint ck;
  const SampleShare s = shareOf(k, n, spp);
  ck.shard = s;
  AccumulationState& st = ck.state;
  st.width = 2;
  st.height = 1;
  st.accum.assign(8, 0.0f);
  st.comp.assign(8, 0.0f);
  st.half.assign(8, 0.0f);
  const std::uint32_t end = held < 0 ? s.end : s.first + std::uint32_t(held);
  for (std::uint32_t i = s.first; i < end; ++i) {
    const float v = 0.1f + float(i) / 1000.0f;
    for (int c = 0; c < 8; ++c) {
      const float value = c % 4 == 3 ? 1.0f : v;
      const float y = value - st.comp[c];
      const float t = st.accum[c] + y;
      st.comp[c] = (t - st.accum[c]) - y;
      st.accum[c] = t;
      if (i % 2 == 1) st.half[c] += value;
    }
  }
  st.spp = int(end - s.first);
  st.sampleBase = end;
  ck.seed = seed;
  ck.sceneHash = scene;
  ImageSettings is;
  is.render.width = 2;
  is.render.height = 1;
  is.render.seed = seed;
  ck.identity = accumulationIdentity(is, Camera{});
  return ck;
}

std::vector<MergePart> parts(int n, int spp) {
  std::vector<MergePart> out;
  for (int k = 1; k <= n; ++k) out.push_back({"p" + std::to_string(k) + ".ckpt", part(k, n, spp)});
  return out;
}

}  // namespace

TEST_CASE("shards: the N shares are disjoint, cover [0, spp) and start at even indices, for any N and spp") {
  for (int spp : {0, 1, 2, 3, 7, 16, 63, 64, 1000, 65536})
    for (int n : {1, 2, 3, 4, 5, 7, 8, 16, 100, 1000}) {
      CAPTURE(spp);
      CAPTURE(n);
      std::uint32_t next = 0, largest = 0, smallest = ~0u;
      for (int k = 1; k <= n; ++k) {
        const SampleShare s = shareOf(k, n, spp);
        CHECK(s.first == next);  // in order, no gap, no overlap
        CHECK(s.end >= s.first);
        CHECK(s.first % 2 == 0);
        CHECK(s.total == std::uint32_t(spp));
        next = s.end;
        largest = std::max(largest, s.end - s.first);
        smallest = std::min(smallest, s.end - s.first);
      }
      CHECK(next == std::uint32_t(spp));
      if (n * 2 <= spp) CHECK(largest - smallest <= 3);  // even: pairs differ by at most one (+1 for an odd spp)
    }
  CHECK(describeShare(shareOf(2, 4, 16)) == "shard 2/4 (samples 4-7)");
  CHECK(describeShare(shareOf(3, 4, 2)) == "shard 3/4 (no samples)");
  CHECK(parseShardOption("3/8") == std::pair<int, int>(3, 8));
  for (const char* bad : {"0/4", "5/4", "4", "a/b", "1/0", "-1/2", "2/4x", ""})
    CHECK_THROWS_WITH_AS(parseShardOption(bad), doctest::Contains("option --shard needs K/N with 1 <= K <= N"), Error);
}

TEST_CASE("shards: the shard line round-trips; version 4 files still read; a bad shard line is refused") {
  const std::string path = tempPath("shard.ckpt");
  Checkpoint a = part(2, 3, 10, 3);
  writeCheckpoint(path, a);
  Checkpoint b = readCheckpoint(path);
  REQUIRE(b.shard);
  CHECK(*b.shard == *a.shard);
  CHECK(b.state.accum == a.state.accum);
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(bytes.find("\nshard 2/3 2 6 10\n") != std::string::npos);
  // A version-4 checkpoint (a whole render, no shard line) reads as before.
  Checkpoint whole = a;
  whole.shard.reset();
  writeCheckpoint(path, whole);
  std::ifstream in4(path, std::ios::binary);
  std::string v4((std::istreambuf_iterator<char>(in4)), std::istreambuf_iterator<char>());
  v4.replace(0, std::string("CAUSTICA-CKPT 5").size(), "CAUSTICA-CKPT 4");
  std::ofstream(path, std::ios::binary | std::ios::trunc) << v4;
  CHECK_FALSE(readCheckpoint(path).shard);
  std::string badLine = bytes;
  badLine.replace(badLine.find("shard 2/3 2 6 10"), 16, "shard 4/3 2 6 10");
  std::ofstream(path, std::ios::binary | std::ios::trunc) << badLine;
  CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("shard.ckpt: not a usable caustica checkpoint: bad shard line"), Error);
}

TEST_CASE("shards: merged Kahan pairs carry the exact total") {
  // Values whose float sum loses bits: 1 + 2^-30 added 2^10 times per part.
  AccumulationState a, b;
  for (AccumulationState* s : {&a, &b}) {
    s->width = s->height = 1;
    s->accum.assign(4, 0.0f);
    s->comp.assign(4, 0.0f);
    s->half.assign(4, 0.0f);
    for (int i = 0; i < 1024; ++i) {
      const float y = (1.0f + std::ldexp(1.0f, -22)) - s->comp[0];
      const float t = s->accum[0] + y;
      s->comp[0] = (t - s->accum[0]) - y;
      s->accum[0] = t;
    }
    s->spp = 1024;
  }
  addAccumulation(a, b);
  const double exact = 2048.0 * (1.0 + std::ldexp(1.0, -22));
  CHECK(double(a.accum[0]) - double(a.comp[0]) == doctest::Approx(exact).epsilon(1e-12));
  CHECK(a.spp == 2048);
}

TEST_CASE("merge: complete sets add up, in any order of the parts") {
  std::vector<MergePart> p = parts(4, 18);
  std::swap(p[0], p[3]);
  const MergeResult r = mergeShards(p, false);
  CHECK(r.complete());
  CHECK(r.resumable);
  CHECK(r.total == 18u);
  CHECK(r.merged.state.spp == 18);
  CHECK(r.merged.state.sampleBase == 18u);
  CHECK_FALSE(r.merged.shard);  // a whole render's checkpoint: render --resume extends it
  CHECK(r.merged.state.accum[3] == 18.0f);  // sample counts are exact
  // One part holding every sample (one machine's sums, as part() adds them) equals the merged sums to
  // float rounding of the total.
  const Checkpoint one = part(1, 1, 18);
  for (int c = 0; c < 8; ++c)
    CHECK(double(r.merged.state.accum[c]) - double(r.merged.state.comp[c]) ==
          doctest::Approx(double(one.state.accum[c]) - double(one.state.comp[c])).epsilon(1e-6));
  for (int c = 0; c < 8; ++c)  // the same odd samples (shares start at even indices), to float rounding
    CHECK(r.merged.state.half[c] == doctest::Approx(one.state.half[c]).epsilon(1e-6));
  CHECK(r.merged.state.half[3] == one.state.half[3]);  // and exactly as many
  // N larger than the pairs: empty shares merge too.
  CHECK(mergeShards(parts(8, 5), false).merged.state.spp == 5);
}

TEST_CASE("merge: every bad set of parts is refused, naming the files and the problem") {
  auto refused = [](const std::vector<MergePart>& p, const std::string& what, bool partial = false) {
    CHECK_THROWS_WITH_AS(mergeShards(p, partial), doctest::Contains(what.c_str()), Error);
  };
  refused({}, "no parts to merge");
  std::vector<MergePart> p = parts(4, 16);
  {  // a whole render's checkpoint
    std::vector<MergePart> q = p;
    q[1].checkpoint.shard.reset();
    refused(q, "p2.ckpt: not a shard's partial but the checkpoint of a whole render");
  }
  {  // another scene
    std::vector<MergePart> q = p;
    q[2].checkpoint = part(3, 4, 16, -1, 1, 43);
    refused(q, "p3.ckpt and p1.ckpt are renders of different scene files");
  }
  {  // another seed: named
    std::vector<MergePart> q = p;
    q[2].checkpoint = part(3, 4, 16, -1, 2);
    refused(q, "p3.ckpt and p1.ckpt are renders with other settings: seed: p1.ckpt 1, p3.ckpt 2");
  }
  {  // another image size: named
    std::vector<MergePart> q = p;
    ImageSettings is;
    is.render.width = 4;
    is.render.height = 1;
    q[1].checkpoint.identity = accumulationIdentity(is, Camera{});
    refused(q, "other settings: width: p1.ckpt 2, p2.ckpt 4");
  }
  {  // another --spp
    std::vector<MergePart> q = p;
    q[3].checkpoint = part(4, 4, 32);
    refused(q, "p4.ckpt and p1.ckpt are shards of renders of different --spp (32 and 16)");
  }
  {  // the same shard twice
    std::vector<MergePart> q = p;
    q.push_back({"again.ckpt", part(2, 4, 16)});
    refused(q, "p2.ckpt (shard 2/4 (samples 4-7)) and again.ckpt (shard 2/4 (samples 4-7)) overlap: the same shard given twice");
  }
  {  // shares of another N that overlap
    std::vector<MergePart> q = {p[0], p[1], {"half.ckpt", part(2, 2, 16)}, p[3]};
    refused(q, "overlap: their samples would count twice");
  }
  {  // a missing shard: named by number and samples
    std::vector<MergePart> q = {p[0], p[1], p[3]};
    refused(q, "missing shard 3/4 (samples 8-11) of the 16-spp render");
    const MergeResult r = mergeShards(q, true);  // --partial: what there is
    CHECK(r.merged.state.spp == 12);
    CHECK(r.merged.state.accum[3] == 12.0f);
    REQUIRE(r.missing.size() == 1);
    CHECK(r.missing[0] == std::pair<std::uint32_t, std::uint32_t>(8, 12));
    CHECK_FALSE(r.resumable);  // a gap: not a checkpoint to continue
  }
  {  // an unfinished shard: named, with the command that finishes it
    std::vector<MergePart> q = p;
    q[2].checkpoint = part(3, 4, 16, 1);
    refused(q, "p3.ckpt: shard 3/4 (samples 8-11) is incomplete: it holds samples 8 (continue it with render --shard 3/4 "
               "--resume p3.ckpt); or merge what there is with --partial");
    const MergeResult r = mergeShards(q, true);
    CHECK(r.merged.state.spp == 13);
    REQUIRE(r.missing.size() == 1);
    CHECK(r.missing[0] == std::pair<std::uint32_t, std::uint32_t>(9, 12));
  }
  {  // the last shards missing: a prefix, which can be continued as a checkpoint
    std::vector<MergePart> q = {p[0], p[1]};
    refused(q, "missing shard 3/4, 4/4 (samples 8-15)");
    const MergeResult r = mergeShards(q, true);
    CHECK(r.resumable);
    CHECK(r.merged.state.sampleBase == 8u);
  }
  {  // a part with a sum image the others lack (here coverage: --background transparent)
    std::vector<MergePart> q = p;
    q[3].checkpoint.state.coverage.assign(2, 1.0f);
    refused(q, "p4.ckpt and p1.ckpt: one holds the coverage sums and the other not");
  }
  {  // a part whose samples lie outside its share (a hand-edited or mixed-up file)
    std::vector<MergePart> q = p;
    q[0].checkpoint.state.sampleBase = 9;
    refused(q, "p1.ckpt: shard 1/4 (samples 0-3) holds 4 samples ending before sample 9, outside its share");
  }
}
