// scene_buffers.h — the scene's buffers on the GPU: whether the TriShade words must be split over several
// storage blocks because one would exceed GL_MAX_SHADER_STORAGE_BLOCK_SIZE, the shader defines that tell
// split_buffers.glsl, and the upload. BVH nodes and TriGeom are one buffer each, read through buffer
// textures (bvh_textures.*), so the block size does not bound them.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include "accel/gpu_scene.h"
#include "gpu/gl_limits.h"
#include "gpu/gl_objects.h"

namespace caustica {

// One array's split: `parts` blocks of `perPart` elements (the last may hold fewer); part 0 at the
// array's own binding, part k > 0 at bindings[k - 1].
struct SplitArray {
  const char* name = "";
  std::size_t elementBytes = 0, count = 0, perPart = 0;
  int parts = 1;
  std::vector<int> bindings;
};

struct SceneBufferLayout {
  SplitArray nodes, triGeom, triShade;
  TriShadeLayout shade;  // the blocks the TriShade words hold (texcoords, vertex colours, tangents)
  // CAUSTICA_TRISHADE_TEXCOORDS, _COLORS, _TANGENTS for the blocks the words hold; CAUSTICA_<ARRAY>_PARTS=n,
  // _PART=elements, _BINDING<k>=index for each split array (none when no array is split).
  std::vector<std::string> defines() const;
  int extraBlocks() const { return nodes.parts + triGeom.parts + triShade.parts - 3; }
  std::string describe() const;  // e.g. "one block per array" or "triangles in 2 blocks"
};

// Plans the split for `g` under `limits`. Throws Error naming the scene, the array and the sizes when an
// array needs more than CAUSTICA_MAX_SPLIT_PARTS blocks or the GPU has too few storage blocks.
SceneBufferLayout planSceneBuffers(const GpuScene& g, const GlLimits& limits, const std::string& scenePath);

// Creates the storage buffers of `g` in `buffers` (indexed by binding; the counters buffer included) and
// frees each host array as soon as its copy is on the GPU, so the host holds one copy at a time. When
// g.triGeom and g.triShade were not packed (packScene(..., false)), they are packed from `scene` and
// `bvh` in slices straight into their blocks (the host never holds them whole).
void uploadSceneBuffers(GpuScene& g, const Scene& scene, const Bvh& bvh, const SceneBufferLayout& layout,
                        std::vector<GlBuffer>& buffers);

// Reads TriGeom and TriShade back into `g` (the raster mode builds its mesh from them).
void downloadSceneArrays(GpuScene& g, const SceneBufferLayout& layout, const std::vector<GlBuffer>& buffers);

}  // namespace caustica
