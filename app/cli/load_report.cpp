// load_report.cpp — the load figures of `render` and `info` as text.
#include "cli/load_report.h"

#include <cstdio>

#include "gpu/renderer.h"
#include "util/memory_stats.h"

namespace caustica::cli {

namespace {
double perTriangle(double bytes, std::size_t triangles) { return triangles ? bytes / double(triangles) : 0.0; }
}  // namespace

std::string gpuBytesSummary(const GpuSceneBytes& b, std::size_t n) {
  char line[320];
  std::snprintf(line, sizeof line,
                "GPU %.1f MiB, %.0f B/triangle (BVH %.0f, triangles %.0f, shading %.0f, light tree %.0f, "
                "materials and textures %.0f)",
                double(b.total()) / 1048576.0, perTriangle(double(b.total()), n), perTriangle(double(b.nodes), n),
                perTriangle(double(b.triGeom), n), perTriangle(double(b.triShade), n), perTriangle(double(b.lightTree), n),
                perTriangle(double(b.materials + b.textures), n));
  return line;
}

std::string hostPeakSummary(std::size_t n) {
  const double peak = double(hostPeakBytes());
  char line[96];
  std::snprintf(line, sizeof line, "host peak %.1f MiB, %.0f B/triangle", peak / 1048576.0, perTriangle(peak, n));
  return line;
}

std::string instancesSummary(const GpuScene& g) {
  if (g.instanceCount == 0) return "no instances (flat)";
  char line[160];
  std::snprintf(line, sizeof line, "%u instances: %zu stored triangles, %llu instanced (%.1fx)", g.instanceCount,
                g.triangleCount, static_cast<unsigned long long>(g.instancedTriangles),
                g.triangleCount ? double(g.instancedTriangles) / double(g.triangleCount) : 0.0);
  return line;
}

std::string loadSummary(const Renderer& r, double parseSeconds, double startToRenderer, std::size_t n) {
  const LoadTimes& t = r.loadTimes();
  char line[256];
  std::snprintf(line, sizeof line,
                "load: parse %.2f s, BVH %.2f s, pack %.2f s, upload %.2f s, shaders %.2f s; first sample starts %.2f s "
                "after start (first pass done at %.2f s); ",
                parseSeconds, t.bvh, t.pack, t.upload, t.compile, startToRenderer + t.ready,
                t.firstPass > 0.0 ? startToRenderer + t.firstPass : 0.0);
  std::string out = line + hostPeakSummary(n) + "; " + gpuBytesSummary(r.gpuBytes(), n) + "; " + r.bufferLayout().describe();
  if (r.gpuScene().instanceCount > 0) out += "; " + instancesSummary(r.gpuScene());
  return out;
}

}  // namespace caustica::cli
