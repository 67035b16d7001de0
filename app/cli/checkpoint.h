// checkpoint.h — the checkpoint file of a long render (`render --checkpoint`, `--resume`): the running
// sums, sample counters, seed, scene fingerprint and image-changing settings. Format and I/O only, no GL.
#pragma once
#include <cstdint>
#include <string>

#include "gpu/render_settings.h"
#include "gpu/renderer.h"
#include "scene/scene.h"

namespace caustica::cli {

constexpr const char* kCheckpointMagic = "CAUSTICA-CKPT";
// 2: adds the odd-sample half image (error estimate, adaptive sampling); version 1 files are refused.
// 3: adds a "coverage 0|1" header line and, with 1, the r32f coverage image after the three others
// (--background transparent); version 2 files still load (no coverage: opaque renders).
constexpr int kCheckpointVersion = 3;
constexpr int kCheckpointOldestVersion = 2;

struct Checkpoint {
  AccumulationState state;        // the three rgba32f images (+ coverage), spp and the next global sample index
  std::uint32_t seed = 0;
  std::uint64_t sceneHash = 0;    // hashSceneFiles of the scene file(s)
  std::string settingsText;       // checkpointSettingsText(...)
};

// The settings that change the image, one "key value" a line (size, seed, max-depth, integrator,
// dispersion, caster-probability, camera): two renders may share samples only if these are equal.
std::string checkpointSettingsText(const RenderSettings& settings, int cameraIndex, const Camera& camera);

// Writes `path` atomically: a temporary file in the same folder (path + ".tmp"), fsync, rename. An
// interrupted write leaves the previous checkpoint intact. Throws Error naming the file on failure.
void writeCheckpoint(const std::string& path, const Checkpoint& checkpoint);
// Reads and verifies (magic, version, sizes, checksum of the data); throws Error naming the file if
// it is not a checkpoint, truncated or corrupted.
Checkpoint readCheckpoint(const std::string& path);

// "" when `checkpoint` belongs to this scene and these settings; otherwise what differs, e.g.
// "seed: checkpoint 1, this render 2; scene files differ (checkpoint 0123..., this scene 4567...)".
std::string checkpointMismatch(const Checkpoint& checkpoint, std::uint64_t sceneHash, const std::string& settingsText);

}  // namespace caustica::cli
