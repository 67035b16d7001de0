// coverage.glsl — --background transparent (CAUSTICA_TRANSPARENT): counts, per pixel, the samples whose
// camera ray hit the scene, in the r32f coverage image; alpha = that count / the accumulation's count.
// A camera ray that passes only through alpha cut-outs and leaves counts as a miss; one that refracts
// or reflects and then leaves counts as a hit (it sees the environment through the glass).

layout(r32f, binding = CAUSTICA_IMAGE_COVERAGE) uniform restrict image2D coverageImage;

bool gCameraRayMissed = false;  // this invocation's camera ray left the scene (set by the tracer)

// The pixel's coverage count (samples whose camera ray hit). Exact in float up to 2^24 samples per pixel.
float loadCoverage(ivec2 pixel) { return imageLoad(coverageImage, pixel).r; }
void storeCoverage(ivec2 pixel, float hits) { imageStore(coverageImage, pixel, vec4(hits, 0.0, 0.0, 0.0)); }

// Adds hit (0 or 1) to the pixel's coverage count.
void accumulateCoverage(ivec2 pixel, float hit) { storeCoverage(pixel, loadCoverage(pixel) + hit); }
