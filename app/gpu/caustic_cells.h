// caustic_cells.h — the caustic cell table of manifold NEE (glsl/lib/caustic_cells.glsl): per caustic
// caster, the cells where photons sent from the emitters through the caster land, each holding their
// count and summed direction back to the caster. Built once per scene on the GPU by the caustic photon
// pass (glsl/caustic_photons.comp) with integer atomics: the table holds the same cells and sums
// whatever order the photons run in (a table too small to hold every cell is rebuilt twice as large),
// so a render and its resumed continuation see the same cells.
#pragma once
#include <cstdint>

#include "gpu/gl_objects.h"
#include "shared/gpu_layout.h"

namespace caustica {

constexpr std::uint32_t kCausticPhotons = 1u << 16;  // photons per caster

// Buckets (of 4 slots) of a first table for `casters` casters: a power of 2 with room for every
// photon landing in a cell of its own at half load.
std::uint32_t cellTableBuckets(std::uint32_t casters);

class CausticCells {
 public:
  // Runs the photon pass with `program` (caustic_photons.comp; the scene's textures, storage blocks and
  // UBOs bound as for a path-tracing dispatch) for the cp.count.x casters of `cp`, whose count.z it sets
  // to the table's bucket mask; `upload(cp)` puts cp where the shaders read it (called before each try).
  template <class Upload>
  void build(const GlProgram& program, gpu::CasterParams& cp, Upload&& upload) {
    for (std::uint32_t buckets = cellTableBuckets(cp.count.x), tries = 0; tries < 3; ++tries, buckets *= 2) {
      cp.count.z = buckets - 1u;
      upload(cp);
      if (run(program, cp.count.x, buckets)) return;
    }
    cp.count.z = 0u;  // no table: manifold NEE finds no cells (the same on every run)
    upload(cp);
  }
  void bind() const;  // on CAUSTICA_TEXUNIT_CELL_KEYS and CAUSTICA_TEXUNIT_CELLS
  bool built() const { return built_; }
  std::size_t bytes() const { return keys_.size() + cells_.size(); }

 private:
  bool run(const GlProgram& program, std::uint32_t casters, std::uint32_t buckets);  // false: a photon was dropped
  GlBuffer keys_, cells_;
  GlBufferTexture keysView_, cellsView_;
  bool built_ = false;
};

}  // namespace caustica
