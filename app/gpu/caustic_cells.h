// caustic_cells.h — the caustic cell table of manifold NEE (glsl/lib/caustic_cells.glsl): per caustic
// caster, the cells where photons sent from the emitters through the caster land, each holding their
// count and summed direction back to the caster. Built once per scene on the GPU by the caustic photon
// pass (glsl/caustic_photons.comp) with integer atomics: the table holds the same cells and sums
// whatever order the photons run in (a table too small to hold every cell is rebuilt twice as large),
// so a render and its resumed continuation see the same cells.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "accel/light_tree.h"
#include "gpu/gl_objects.h"
#include "shared/gpu_layout.h"

namespace caustica {

constexpr std::uint32_t kCausticPhotons = 1u << 16;  // photons per caster

// Most entries photonEmitterTable makes (32 MiB); beyond, the photon pass lets the light tree choose.
constexpr std::uint64_t kMaxPhotonEmitterEntries = 1u << 22;

// Where the photons of each caster of cp (cp.count.x of them) leave from: per caster, one entry per
// light-tree leaf in tree.leavesBySource order, (cumulative probability as float bits, leaf index),
// the probability of an emitter in proportion to power x bounded emission cosine towards the caster's
// sphere / clamped squared distance to its centre (lightImportance's bound, per triangle). A continuous
// function of the geometry in an order the scene's scale and place keep, so that a scaled or moved
// scene sends its photons from the same points (the light tree's own choice from the caster's centre
// follows its cones, which rounding can rebuild otherwise). Casters outside `casterMask`, or without an
// emitter facing them, get all-zero entries (no photons). Empty (the light tree chooses) without
// emitters or with more than kMaxPhotonEmitterEntries entries.
std::vector<glm::uvec2> photonEmitterTable(const LightTree& tree, const gpu::CasterParams& cp, std::uint32_t casterMask);

// Which table a photon pass fills (caustic_photons.comp's `table`): manifold NEE's (photons to the
// casters of cp.count.w along their own chain; bucket mask in cp.count.z, CAUSTICA_TEXUNIT_CELL_*)
// or caster guiding's (photons to the casters of cp.guide.y along any chain of smooth events, counted for
// the caster of their last event; bucket mask in cp.guide.x, CAUSTICA_TEXUNIT_GUIDE_*).
enum class CellTable : std::uint32_t { Manifold = 0, Guide = 1 };

// Buckets (of 4 slots) of a first table for `casters` casters: a power of 2 with room for every
// photon landing in a cell of its own at half load.
std::uint32_t cellTableBuckets(std::uint32_t casters);

// What a built table holds: the photons that landed in a cell and the cells they filled.
struct CausticCellStats {
  std::uint64_t photons = 0, cells = 0;
  std::uint32_t buckets = 0;  // the table's size (4 slots each)
};

class CausticCells {
 public:
  explicit CausticCells(CellTable table = CellTable::Manifold) : table_(table) {}
  // Runs the photon pass with `program` (caustic_photons.comp; the scene's textures, storage blocks and
  // UBOs bound as for a path-tracing dispatch) for the cp.count.x casters of `cp`, whose count.z (manifold
  // NEE's table) or guide.x (caster guiding's) it sets to the table's bucket mask; `upload(cp)` puts cp where the shaders read it (called before each try).
  // The photons leave from emitters drawn from `tree`'s photonEmitterTable.
  template <class Upload>
  void build(const GlProgram& program, const LightTree& tree, gpu::CasterParams& cp, Upload&& upload) {
    const std::vector<glm::uvec2> emitters = photonEmitterTable(tree, cp, table_ == CellTable::Guide ? cp.guide.y : cp.count.w);
    const GlBuffer emitterBuffer = emitters.empty() ? GlBuffer() : GlBuffer::fromVector(emitters);
    const auto entries = static_cast<std::uint32_t>(emitters.size() / std::max<std::uint32_t>(cp.count.x, 1u));
    std::uint32_t& mask = table_ == CellTable::Guide ? cp.guide.x : cp.count.z;
    for (std::uint32_t buckets = cellTableBuckets(cp.count.x), tries = 0; tries < 3; ++tries, buckets *= 2) {
      mask = buckets - 1u;
      upload(cp);
      if (run(program, cp.count.x, buckets, emitterBuffer, entries)) return;
    }
    mask = 0u;  // no table: no cells (the same on every run)
    upload(cp);
  }
  void bind() const;  // on CAUSTICA_TEXUNIT_CELL_KEYS and _CELLS, or _GUIDE_KEYS and _GUIDE_CELLS
  bool built() const { return built_; }
  std::size_t bytes() const { return keys_.size() + cells_.size(); }
  CausticCellStats stats() const;  // reads the table back (zero before a build)

 private:
  // false: a photon was dropped. `emitters`: photonEmitterTable's, `entries` per caster (0: none).
  bool run(const GlProgram& program, std::uint32_t casters, std::uint32_t buckets, const GlBuffer& emitters,
           std::uint32_t entries);
  CellTable table_;
  GlBuffer keys_, cells_;
  GlBufferTexture keysView_, cellsView_;
  bool built_ = false;
};

}  // namespace caustica
