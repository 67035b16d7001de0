// caustic_cells.cpp — the caustic photon pass's dispatch and its table.
#include "gpu/caustic_cells.h"

#include <algorithm>
#include <cmath>
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

std::vector<glm::uvec2> photonEmitterTable(const LightTree& tree, const gpu::CasterParams& cp, std::uint32_t casterMask) {
  const std::size_t n = tree.leavesBySource.size(), casters = cp.count.x;
  if (n == 0 || casters == 0 || static_cast<std::uint64_t>(n) * casters > kMaxPhotonEmitterEntries) return {};
  std::vector<glm::uvec2> table(n * casters, glm::uvec2(0u));
  std::vector<double> cdf(n);
  for (std::size_t c = 0; c < casters; ++c) {
    if ((casterMask & (1u << c)) == 0u) continue;
    const glm::dvec3 centre(cp.sphere[c]);
    const double r = cp.sphere[c].w;
    double sum = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const gpu::LightNode& leaf = tree.nodes[tree.leavesBySource[k]];
      const glm::dvec3 d = centre - 0.5 * (glm::dvec3(leaf.boundsMin) + glm::dvec3(leaf.boundsMax));
      const double d2 = glm::dot(d, d), dist = std::sqrt(d2);
      double cosW = dist > 0.0 ? glm::dot(glm::dvec3(leaf.axis), d) / dist : 1.0;
      if ((leaf.link.y & gpu::kLightNodeTwoSided) != 0u) cosW = std::abs(cosW);
      // The smallest emission angle towards the sphere: theta_w less the sphere's half angle.
      const double beta = dist > r ? std::asin(r / dist) : 1.5707963267948966;
      const double theta = std::max(0.0, std::acos(std::clamp(cosW, -1.0, 1.0)) - beta);
      const double w = static_cast<double>(leaf.boundsMin.w) * std::max(0.0, std::cos(theta)) / std::max(d2, r * r);
      sum += std::isfinite(w) ? w : 0.0;
      cdf[k] = sum;
    }
    if (!(sum > 0.0)) continue;
    for (std::size_t k = 0; k < n; ++k) {
      const float p = k + 1 == n ? 1.0f : static_cast<float>(cdf[k] / sum);
      table[c * n + k] = glm::uvec2(glm::floatBitsToUint(p), tree.leavesBySource[k]);
    }
  }
  return table;
}

bool CausticCells::run(const GlProgram& program, std::uint32_t casters, std::uint32_t buckets, const GlBuffer& emitters,
                       std::uint32_t entries) {
  keys_ = GlBuffer::fromVector(std::vector<std::uint32_t>(4u * buckets, 0u), GL_DYNAMIC_COPY);
  cells_ = GlBuffer::fromVector(std::vector<gpu::CausticCell>(4u * buckets, gpu::CausticCell{0u, 0u, 0u, 0u}), GL_DYNAMIC_COPY);
  const std::uint32_t zero = 0;
  GlBuffer drops = GlBuffer::create(sizeof zero, &zero, GL_DYNAMIC_COPY);
  keys_.bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_CELL_KEYS);
  cells_.bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_CELLS);
  drops.bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_CELL_DROPS);
  if (entries > 0) emitters.bindBase(GL_SHADER_STORAGE_BUFFER, CAUSTICA_BINDING_PHOTON_EMITTERS);
  program.use();
  glUniform1ui(0, kCausticPhotons);
  glUniform1ui(1, entries);
  glUniform1ui(2, static_cast<std::uint32_t>(table_));
  if (casters > 0) glDispatchCompute((kCausticPhotons + 63u) / 64u, casters, 1u);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
  std::uint32_t dropped = 0;
  drops.read(0, sizeof dropped, &dropped);
  keysView_ = GlBufferTexture::create(keys_, GL_RGBA32UI);
  cellsView_ = GlBufferTexture::create(cells_, GL_RGBA32UI);
  built_ = true;
  if (std::getenv("CAUSTICA_CELLS_DEBUG")) {
    const CausticCellStats s = stats();
    std::fprintf(stderr, "cells: %u buckets, %llu cells used, %llu photons, %u dropped\n", s.buckets,
                 (unsigned long long)s.cells, (unsigned long long)s.photons, dropped);
  }
  return dropped == 0;
}

CausticCellStats CausticCells::stats() const {
  CausticCellStats s;
  if (!built_) return s;
  std::vector<gpu::CausticCell> got(cells_.size() / sizeof(gpu::CausticCell));
  cells_.read(0, got.size() * sizeof(gpu::CausticCell), got.data());
  for (const auto& c : got) {
    s.photons += c.count;
    s.cells += c.count > 0;
  }
  s.buckets = static_cast<std::uint32_t>(got.size() / 4u);
  return s;
}

void CausticCells::bind() const {
  if (!built_) return;
  keysView_.bind(table_ == CellTable::Guide ? CAUSTICA_TEXUNIT_GUIDE_KEYS : CAUSTICA_TEXUNIT_CELL_KEYS);
  cellsView_.bind(table_ == CellTable::Guide ? CAUSTICA_TEXUNIT_GUIDE_CELLS : CAUSTICA_TEXUNIT_CELLS);
}

}  // namespace caustica
