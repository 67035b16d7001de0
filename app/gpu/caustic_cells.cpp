// caustic_cells.cpp — the caustic photon pass's dispatch and its table.
#include "gpu/caustic_cells.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace caustica {

std::uint32_t cellTableBuckets(std::uint32_t casters) {
  const std::uint64_t slots = 2ull * std::max<std::uint32_t>(casters, 1u) * kCausticPhotons;
  std::uint32_t buckets = 1;
  while (4ull * buckets < slots) buckets *= 2;
  return buckets;
}

bool CausticCells::run(const GlProgram& program, std::uint32_t casters, std::uint32_t buckets) {
  keys_ = GlBuffer::fromVector(std::vector<std::uint32_t>(4u * buckets, 0u), GL_DYNAMIC_COPY);
  cells_ = GlBuffer::fromVector(std::vector<gpu::CausticCell>(4u * buckets, gpu::CausticCell{0u, 0u, 0u, 0u}), GL_DYNAMIC_COPY);
  const std::uint32_t zero = 0;
  GlBuffer drops = GlBuffer::create(sizeof zero, &zero, GL_DYNAMIC_COPY);
  keys_.bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_CELL_KEYS);
  cells_.bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_CELLS);
  drops.bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_CELL_DROPS);
  program.use();
  glUniform1ui(0, kCausticPhotons);
  if (casters > 0) glDispatchCompute((kCausticPhotons + 63u) / 64u, casters, 1u);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
  std::uint32_t dropped = 0;
  drops.read(0, sizeof dropped, &dropped);
  keysView_ = GlBufferTexture::create(keys_, GL_RGBA32UI);
  cellsView_ = GlBufferTexture::create(cells_, GL_RGBA32UI);
  built_ = true;
  if (std::getenv("CAUSTICA_CELLS_DEBUG")) {
    std::vector<gpu::CausticCell> got(4u * buckets);
    cells_.read(0, got.size() * sizeof(gpu::CausticCell), got.data());
    std::uint64_t photons = 0, used = 0;
    for (const auto& c : got) {
      photons += c.count;
      used += c.count > 0;
    }
    std::fprintf(stderr, "cells: %u buckets, %llu cells used, %llu photons, %u dropped\n", buckets,
                 (unsigned long long)used, (unsigned long long)photons, dropped);
  }
  return dropped == 0;
}

void CausticCells::bind() const {
  if (!built_) return;
  keysView_.bind(CAUSTICA_TEXUNIT_CELL_KEYS);
  cellsView_.bind(CAUSTICA_TEXUNIT_CELLS);
}

}  // namespace caustica
