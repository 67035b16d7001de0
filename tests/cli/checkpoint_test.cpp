// checkpoint_test.cpp — the checkpoint file format without a GL context: round trip, refusal of
// truncated and corrupted files, the mismatch message, and atomic replacement.
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cli/checkpoint.h"
#include "util/error.h"

using namespace caustica;
using namespace caustica::cli;
namespace fs = std::filesystem;

namespace {

Checkpoint sample(int w, int h, float base) {
  Checkpoint ck;
  ck.state.width = w;
  ck.state.height = h;
  ck.state.spp = 8;
  ck.state.sampleBase = 8;
  for (int i = 0; i < w * h * 4; ++i) {
    ck.state.accum.push_back(base + 0.25f * float(i));
    ck.state.comp.push_back(-1e-7f * float(i));
    ck.state.half.push_back(0.5f * base + 0.125f * float(i));
  }
  ck.seed = 7;
  ck.sceneHash = 0x0123456789abcdefull;
  ImageSettings is;
  is.render.width = w;
  is.render.height = h;
  is.render.seed = 7;
  ck.identity = accumulationIdentity(is, Camera{});
  return ck;
}

std::string tempPath(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("caustica-ckpt-test-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void spit(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

}  // namespace

TEST_CASE("checkpoint: round trip keeps every float bit and header field") {
  std::string path = tempPath("round.ckpt");
  Checkpoint a = sample(3, 2, 1.5f);
  writeCheckpoint(path, a);
  CHECK_FALSE(fs::exists(path + ".tmp"));
  Checkpoint b = readCheckpoint(path);
  CHECK(b.state.width == 3);
  CHECK(b.state.height == 2);
  CHECK(b.state.spp == 8);
  CHECK(b.state.sampleBase == 8u);
  CHECK(b.seed == 7u);
  CHECK(b.sceneHash == 0x0123456789abcdefull);
  CHECK(b.identity == a.identity);
  CHECK(b.state.accum == a.state.accum);
  CHECK(b.state.comp == a.state.comp);
  CHECK(b.state.half == a.state.half);
  CHECK(b.state.coverage.empty());  // an opaque render has no coverage image
  CHECK(slurp(path).rfind("CAUSTICA-CKPT 5\n", 0) == 0);
  CHECK(checkpointMismatch(b, 0x0123456789abcdefull, a.identity).empty());
}

TEST_CASE("checkpoint: the coverage image of a transparent render round-trips; older versions are refused") {
  std::string path = tempPath("coverage.ckpt");
  Checkpoint a = sample(3, 2, 1.5f);
  for (int i = 0; i < 6; ++i) a.state.coverage.push_back(float(i % 3) * 4.0f);
  writeCheckpoint(path, a);
  Checkpoint b = readCheckpoint(path);
  CHECK(b.state.coverage == a.state.coverage);
  CHECK(b.state.accum == a.state.accum);
  std::string bytes = slurp(path);
  CHECK(bytes.find("\ncoverage 1\n") != std::string::npos);
  // Its coverage is checksummed too, and a missing coverage block reads as truncated.
  std::string flipped = bytes;
  flipped[flipped.size() - 2] ^= 0x10;
  spit(path, flipped);
  CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("checksum"), Error);
  spit(path, bytes.substr(0, bytes.size() - 6 * sizeof(float)));
  CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("truncated"), Error);
  // A version-3 file (its settings text named only some of the image's settings) is refused, naming
  // the file and what to do.
  writeCheckpoint(path, sample(3, 2, 1.5f));
  std::string v3 = slurp(path);
  v3.replace(0, std::string("CAUSTICA-CKPT 5").size(), "CAUSTICA-CKPT 3");
  spit(path, v3);
  CHECK_THROWS_WITH_AS(readCheckpoint(path),
                       doctest::Contains("coverage.ckpt: not a usable caustica checkpoint: version 3 (this caustica "
                                         "reads versions 4 to 6, whose settings name every option that changes the image; "
                                         "render again to write one)"),
                       Error);
}

TEST_CASE("checkpoint: truncated, corrupted and foreign files are refused with the file's name") {
  std::string path = tempPath("bad.ckpt");
  writeCheckpoint(path, sample(4, 4, 2.0f));
  const std::string good = slurp(path);
  spit(path, good.substr(0, good.size() - 5));
  CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("truncated"), Error);
  spit(path, good.substr(0, 40));
  CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("bad.ckpt: not a usable caustica checkpoint"), Error);
  std::string flipped = good;
  flipped[flipped.size() - 3] ^= 0x10;
  spit(path, flipped);
  CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("checksum"), Error);
  // A version-1 file (no half image: no error estimate to resume adaptive sampling from) is refused.
  std::string v1 = good;
  v1.replace(0, std::string("CAUSTICA-CKPT 5").size(), "CAUSTICA-CKPT 1");
  spit(path, v1);
  CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("version 1 (this caustica reads versions 4 to 6"), Error);
  std::string v6 = good;
  v6.replace(0, std::string("CAUSTICA-CKPT 5").size(), "CAUSTICA-CKPT 7");
  spit(path, v6);
  CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("version 7 (this caustica reads versions 4 to 6)"), Error);
  spit(path, "P6\n1 1\n255\nabc");
  CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("no CAUSTICA-CKPT header"), Error);
  CHECK_THROWS_AS(readCheckpoint(tempPath("missing.ckpt")), Error);
}

TEST_CASE("checkpoint: the mismatch names each differing setting and the scene") {
  Checkpoint ck = sample(2, 2, 0.0f);
  ImageSettings is;
  is.render.width = 2;
  is.render.height = 2;
  is.render.seed = 9;
  is.render.maxDepth = 12;
  is.scene.env = "sun-sky";
  std::string diff = checkpointMismatch(ck, 42, accumulationIdentity(is, Camera{}));
  CHECK(diff.find("seed: checkpoint 7, this render 9") != std::string::npos);
  CHECK(diff.find("max-depth: checkpoint 256, this render 12") != std::string::npos);
  CHECK(diff.find("env: checkpoint auto, this render sun-sky") != std::string::npos);
  CHECK(diff.find("scene files differ") != std::string::npos);
  CHECK(diff.find("width") == std::string::npos);
  Camera moved;
  moved.position.x = 0.5f;
  is.render.seed = 7;
  is.render.maxDepth = 256;
  is.scene.env = "auto";
  is.camera = 1;
  std::string camDiff = checkpointMismatch(ck, ck.sceneHash, accumulationIdentity(is, moved));
  CHECK(camDiff.find("camera: checkpoint 0, this render 1") != std::string::npos);
  CHECK(camDiff.find("camera-view: checkpoint 0 ") != std::string::npos);
}

TEST_CASE("checkpoint: a write interrupted before its rename leaves the previous checkpoint intact") {
  std::string path = tempPath("atomic.ckpt");
  Checkpoint first = sample(2, 3, 1.0f);
  writeCheckpoint(path, first);
  // A run killed mid-write leaves a partial temporary file next to the checkpoint.
  std::string partial = slurp(path).substr(0, 60);
  spit(path + ".tmp", partial);
  Checkpoint still = readCheckpoint(path);
  CHECK(still.state.accum == first.state.accum);
  // The next write replaces the stale temporary file and the checkpoint.
  Checkpoint second = sample(2, 3, 5.0f);
  writeCheckpoint(path, second);
  CHECK(readCheckpoint(path).state.accum == second.state.accum);
  CHECK_FALSE(fs::exists(path + ".tmp"));
  // A write that cannot happen (its folder is gone) throws and touches nothing else.
  CHECK_THROWS_WITH_AS(writeCheckpoint(tempPath("nope") + "/x/y.ckpt", first), doctest::Contains("y.ckpt.tmp"), Error);
  fs::remove_all(fs::path(path).parent_path());
}

TEST_CASE("checkpoint: the denoiser's feature sums (version 6) round-trip, with and without coverage and a shard line; without them it stays version 5") {
  for (bool coverage : {false, true}) {
    INFO("coverage ", coverage);
    const std::string path = tempPath("features.ckpt");
    Checkpoint a = sample(3, 2, 2.5f);
    if (coverage) a.state.coverage.assign(6, 3.0f);
    if (coverage) a.shard = SampleShare{2, 3, 4, 8, 12};  // a shard's partial with feature sums
    for (int i = 0; i < 3 * 2 * 4; ++i) {
      a.state.albedo.push_back(0.1f * float(i));
      a.state.normal.push_back(-0.3f * float(i));
    }
    writeCheckpoint(path, a);
    CHECK(slurp(path).rfind(std::string(kCheckpointMagic) + " 6\n", 0) == 0);
    const Checkpoint b = readCheckpoint(path);
    CHECK(b.shard == a.shard);
    CHECK(b.state.albedo == a.state.albedo);
    CHECK(b.state.normal == a.state.normal);
    CHECK(b.state.coverage == a.state.coverage);
    CHECK(b.state.accum == a.state.accum);
    // A flipped bit in the feature sums fails the checksum; a missing image is a truncated file.
    std::string bytes = slurp(path);
    bytes[bytes.size() - 5] ^= 0x10;
    spit(path, bytes);
    CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("checksum"), Error);
    spit(path, slurp(path).substr(0, bytes.size() - 4 * 24));
    CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("truncated"), Error);
    fs::remove(path);
  }
  const std::string path = tempPath("plain.ckpt");
  writeCheckpoint(path, sample(3, 2, 1.0f));
  CHECK(slurp(path).rfind(std::string(kCheckpointMagic) + " 5\n", 0) == 0);  // readable by older versions
  CHECK_FALSE(readCheckpoint(path).state.hasFeatures());
  fs::remove(path);
}
