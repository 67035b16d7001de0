// checkpoint.h — the checkpoint file of a long render (`render --checkpoint`, `--resume`): the running
// sums, sample counters, seed, scene fingerprint and accumulation identity. Format and I/O only, no GL.
//
// Whether two sets of samples may be added together is decided by two values, and only these:
// hashSceneFiles(scene path) (cli/bench/reference_cache.h) and accumulationIdentity(settings, camera)
// (cli/image_settings.h), derived from the one field list of ImageSettings, so that an option added
// there is part of it without further code. Anything else that adds samples together (render --shard,
// merge) should store and compare these two the same way: checkpointMismatch below, or
// identityDifference for the settings alone.
#pragma once
#include <cstdint>
#include <optional>
#include <string>

#include "cli/image_settings.h"
#include "gpu/renderer.h"
#include "scene/scene.h"

namespace caustica::cli {

constexpr const char* kCheckpointMagic = "CAUSTICA-CKPT";
// 2: adds the odd-sample half image (error estimate, adaptive sampling); version 1 files are refused.
// 3: adds a "coverage 0|1" header line and, with 1, the r32f coverage image after the three others
// (--background transparent).
// 4: the settings text is the accumulation identity (every Accumulation field of ImageSettings, one
// "key value" a line); older files are refused, naming the file: their settings text lacks fields.
// 5: adds an optional "shard K/N FIRST END TOTAL" line: the file is the partial of a shard (render
// --shard, cli/shard.h). Version 4 files read as version 5 files without it.
// 6: adds a "features 1" header line and the denoiser's two rgba32f feature-sum images after the others
// (render --denoise, --aov; docs/denoising.md). A render without feature buffers still writes version 5.
constexpr int kCheckpointVersion = 6;
constexpr int kCheckpointVersionWithoutFeatures = 5;
constexpr int kCheckpointOldestVersion = 4;

// The share of one shard of a render (render --shard K/N): the global sample indices [first, end) of a
// render of `total` samples per pixel. A shard's partial holds [first, AccumulationState::sampleBase).
struct SampleShare {
  int index = 0, count = 0;  // K and N of --shard K/N (1 <= K <= N)
  std::uint32_t first = 0, end = 0, total = 0;
  bool operator==(const SampleShare& o) const {
    return index == o.index && count == o.count && first == o.first && end == o.end && total == o.total;
  }
  bool operator!=(const SampleShare& o) const { return !(*this == o); }
};

struct Checkpoint {
  AccumulationState state;        // the three rgba32f images (+ coverage, + feature sums), spp and the next global sample index
  std::uint32_t seed = 0;
  std::uint64_t sceneHash = 0;    // hashSceneFiles of the scene file(s)
  std::string identity;           // accumulationIdentity(settings, camera) of the render
  // Set in a shard's partial (mergeable with `caustica merge`); unset in a whole render's checkpoint.
  std::optional<SampleShare> shard;
};

// Writes `path` atomically: a temporary file in the same folder (path + ".tmp"), fsync, rename. An
// interrupted write leaves the previous checkpoint intact. Throws Error naming the file on failure.
void writeCheckpoint(const std::string& path, const Checkpoint& checkpoint);
// Reads and verifies (magic, version, sizes, checksum of the data); throws Error naming the file if
// it is not a checkpoint, truncated or corrupted.
Checkpoint readCheckpoint(const std::string& path);

// "" when `checkpoint` belongs to this scene and this identity; otherwise what differs, e.g.
// "seed: checkpoint 1, this render 2; scene files differ (checkpoint 0123..., this scene 4567...)".
std::string checkpointMismatch(const Checkpoint& checkpoint, std::uint64_t sceneHash, const std::string& identity);
// The same for a render of the scene packed as `gpu` (Renderer::gpuScene): the manifold and
// guide-probability lines of both identities are compared as the image sees them (resolveIdentityScene,
// cli/image_settings.h), so a checkpoint that recorded "manifold auto" continues with --manifold off where
// auto finds no caster.
// With gpu null (before the scene is packed) the manifold and guide-probability lines are left out of the comparison.
std::string checkpointMismatch(const Checkpoint& checkpoint, std::uint64_t sceneHash, const std::string& identity,
                               const GpuScene* gpu);

}  // namespace caustica::cli
