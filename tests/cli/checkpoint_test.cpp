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
  RenderSettings rs;
  rs.width = w;
  rs.height = h;
  rs.seed = 7;
  ck.settingsText = checkpointSettingsText(rs, 0, Camera{});
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
  CHECK(b.settingsText == a.settingsText);
  CHECK(b.state.accum == a.state.accum);
  CHECK(b.state.comp == a.state.comp);
  CHECK(b.state.half == a.state.half);
  CHECK(b.state.coverage.empty());  // an opaque render has no coverage image
  CHECK(slurp(path).rfind("CAUSTICA-CKPT 3\n", 0) == 0);
  CHECK(checkpointMismatch(b, 0x0123456789abcdefull, a.settingsText).empty());
}

TEST_CASE("checkpoint: the coverage image of a transparent render round-trips; version 2 files still load") {
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
  // A version-2 file (written before coverage existed: no coverage line, three images) loads as opaque.
  writeCheckpoint(path, sample(3, 2, 1.5f));
  std::string v2 = slurp(path);
  v2.replace(0, std::string("CAUSTICA-CKPT 3").size(), "CAUSTICA-CKPT 2");
  v2.erase(v2.find("coverage 0\n"), std::string("coverage 0\n").size());
  spit(path, v2);
  Checkpoint old = readCheckpoint(path);
  CHECK(old.state.coverage.empty());
  CHECK(old.state.half == a.state.half);
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
  v1.replace(0, std::string("CAUSTICA-CKPT 3").size(), "CAUSTICA-CKPT 1");
  spit(path, v1);
  CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("version 1 (this caustica reads versions 2 to 3)"), Error);
  spit(path, "P6\n1 1\n255\nabc");
  CHECK_THROWS_WITH_AS(readCheckpoint(path), doctest::Contains("no CAUSTICA-CKPT header"), Error);
  CHECK_THROWS_AS(readCheckpoint(tempPath("missing.ckpt")), Error);
}

TEST_CASE("checkpoint: the mismatch names each differing setting and the scene") {
  Checkpoint ck = sample(2, 2, 0.0f);
  RenderSettings rs;
  rs.width = 2;
  rs.height = 2;
  rs.seed = 9;
  rs.maxDepth = 12;
  std::string diff = checkpointMismatch(ck, 42, checkpointSettingsText(rs, 0, Camera{}));
  CHECK(diff.find("seed: checkpoint 7, this render 9") != std::string::npos);
  CHECK(diff.find("max-depth: checkpoint 256, this render 12") != std::string::npos);
  CHECK(diff.find("scene files differ") != std::string::npos);
  CHECK(diff.find("size") == std::string::npos);
  Camera moved;
  moved.position.x = 0.5f;
  rs.seed = 7;
  rs.maxDepth = 256;
  std::string camDiff = checkpointMismatch(ck, ck.sceneHash, checkpointSettingsText(rs, 1, moved));
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
