// load_report.h — one-line summaries of what loading a scene cost: seconds by step (parse, BVH build,
// packing, upload, shader compilation, first sample), host peak memory and GPU bytes per triangle.
// Printed by `render` and `info` (docs/benchmarks.md, "Big scenes").
#pragma once
#include <cstddef>
#include <string>

#include "accel/gpu_scene.h"

namespace caustica {
class Renderer;
}

namespace caustica::cli {

// "GPU 95.2 MiB, 95 B/triangle (BVH 35, triangles 48, shading 12, light tree 0, materials and textures 0)"
std::string gpuBytesSummary(const GpuSceneBytes& bytes, std::size_t triangles);
// "host peak 240.1 MiB, 240 B/triangle" (VmHWM so far; on llvmpipe GPU buffers are host memory too)
std::string hostPeakSummary(std::size_t triangles);
// "66 instances: 1000000 stored triangles, 64100000 instanced (64.1x)", or "no instances (flat)".
std::string instancesSummary(const GpuScene& g);
// "load: parse 1.20 s, BVH 0.50 s, pack 0.20 s, upload 0.10 s, shaders 0.30 s; first sample starts 2.40 s
// after start (first pass done at 2.90 s); host peak ...; GPU ...; one block per array[; instancesSummary]". `parseSeconds`: reading the scene;
// `startToRenderer`: seconds from the command's start to the Renderer's construction.
std::string loadSummary(const Renderer& renderer, double parseSeconds, double startToRenderer, std::size_t triangles);

}  // namespace caustica::cli
