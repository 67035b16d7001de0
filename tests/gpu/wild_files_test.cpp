// wild_files_test.cpp — files as other tools write them (tests/data/wild/, scripts/make-test-data)
// render the image of their uncompressed source: Draco, meshopt (with filters and fallback buffers),
// KHR_mesh_quantization and WebP textures.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "gl_test_util.h"

using namespace caustica;
using namespace caustica::test;

namespace {

RenderSettings tiny(std::uint32_t seed) {
  RenderSettings s;
  s.width = s.height = 40;
  s.seed = seed;
  return s;
}

Image renderWild(const std::string& file, std::uint32_t seed, int spp) {
  const Scene scene = loadScene(sourcePath("tests/data/wild/" + file));
  return renderScene(scene, sceneCamera(scene), tiny(seed), spp).image;
}

// relMSE = mean((x - ref)^2 / (ref^2 + 0.01)) over every channel (docs/benchmarks.md).
double relMse(const Image& x, const Image& ref) {
  double sum = 0.0;
  for (std::size_t i = 0; i < x.rgb.size(); ++i) {
    const double d = double(x.rgb[i]) - ref.rgb[i];
    sum += d * d / (double(ref.rgb[i]) * ref.rgb[i] + 0.01);
  }
  return sum / double(x.rgb.size());
}

}  // namespace

TEST_CASE("compressed files render the image of their uncompressed source") {
  // The same seed gives the same random numbers, so a variant whose geometry is the source's within
  // the quantization step gives nearly the source's image: measured relMSE 1.3e-5 (quantized,
  // meshopt), 1.6e-4 (gltfpack), 1.5e-3 (Draco, whose 10-bit normals send a few paths elsewhere) and
  // 0 (WebP, lossless), against 3.5e-2 between two seeds of the source; means within 0.06 %. A texture
  // read through the wrong coordinates, a normal decoded wrong or a missing vertex colour moves the
  // image far more; a 0.5 % bias in brightness fails the mean.
  const int spp = 16;
  const Image source = renderWild("compress-source.gltf", 7, spp);
  const Image otherSeed = renderWild("compress-source.gltf", 8, spp);
  const double noise = relMse(otherSeed, source);
  MESSAGE("source against another seed: relMSE " << noise);
  for (const char* file : {"compress-draco.glb", "compress-draco-sequential.glb", "compress-quantized.glb",
                           "compress-meshopt.glb", "compress-gltfpack.glb", "compress-gltfpack-filters.glb",
                           "compress-gltfpack-filters.gltf", "compress-webp.glb"}) {
    CAPTURE(std::string(file));
    const Image img = renderWild(file, 7, spp);
    const double e = relMse(img, source);
    const double bias = meanOf(img) / meanOf(source) - 1.0;
    MESSAGE(std::string(file) << ": relMSE " << e << ", mean " << 100.0 * bias << " %");
    CHECK(e < 5e-3);
    CHECK(e < 0.1 * noise);
    CHECK(std::abs(bias) < 0.003);
  }
}
