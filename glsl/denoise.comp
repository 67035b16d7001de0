// denoise.comp — the edge-aware à-trous denoiser (docs/denoising.md), one stage per variant:
// CAUSTICA_DENOISE_PREPARE divides each pixel's mean by its albedo and finds its variance, guide
// (normal, albedo, distance) and distance gradient; CAUSTICA_DENOISE_PASS is one à-trous pass with taps
// `step` pixels apart, the last one multiplying the albedo back in; CAUSTICA_DENOISE_RESIDUAL one pass
// spreading what the filter took from each pixel over its surface, the last one adding it to the output.
// C++ twin: app/image/denoise.cpp. Radiance linear; distances in scene units.
#include "shared/gpu_layout.h"
#include "lib/sampling.glsl"
#include "lib/denoise.glsl"

layout(local_size_x = CAUSTICA_WORKGROUP_X, local_size_y = CAUSTICA_WORKGROUP_Y) in;

layout(rgba32f, binding = CAUSTICA_DENOISE_IMAGE_ACCUM) uniform restrict readonly image2D accumImage;
layout(rgba32f, binding = CAUSTICA_DENOISE_IMAGE_GUIDE) uniform restrict image2D guideImage;
layout(rgba32f, binding = CAUSTICA_DENOISE_IMAGE_CENTRE) uniform restrict image2D centreImage;
layout(rgba32f, binding = CAUSTICA_DENOISE_IMAGE_PONG) uniform restrict writeonly image2D pongImage;
layout(location = 3) uniform float sigmaDepth;  // DenoiseSettings (app/image/denoise.h)

bool insideImage(ivec2 q, ivec2 size) { return all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size)); }

#ifdef CAUSTICA_DENOISE_PREPARE
layout(rgba32f, binding = CAUSTICA_DENOISE_IMAGE_ALBEDO) uniform restrict readonly image2D albedoImage;
layout(rgba32f, binding = CAUSTICA_DENOISE_IMAGE_NORMAL) uniform restrict readonly image2D normalImage;
layout(location = 4) uniform float albedoFloor;

// Unit mean normal (0: none) and mean distance of pixel q; w = -1 without samples.
vec4 pixelNormalDistance(ivec2 q) {
  vec4 acc = imageLoad(accumImage, q);
  if (!(acc.a > 0.0)) return vec4(0.0, 0.0, 0.0, -1.0);
  vec4 ns = imageLoad(normalImage, q);
  vec3 nrm = ns.xyz / acc.a;
  float len = length(nrm);
  return vec4(len > kDenoiseNormalMinLength ? nrm / len : vec3(0.0), ns.w / acc.a);
}

// The smaller one-sided difference of the mean distance towards the two neighbours along d that have
// samples (0 when neither has).
float denoiseAxisGradient(ivec2 p, ivec2 d, float z, ivec2 size) {
  float best = 3.0e38;
  for (int sign = -1; sign <= 1; sign += 2) {
    ivec2 q = p + sign * d;
    if (!insideImage(q, size)) continue;
    vec4 g = pixelNormalDistance(q);
    if (g.w >= 0.0) best = min(best, abs(g.w - z));
  }
  return best < 3.0e38 ? best : 0.0;
}

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = imageSize(accumImage);
  if (!insideImage(p, size)) return;
  vec4 acc = imageLoad(accumImage, p);
  vec4 nz = pixelNormalDistance(p);
  if (!(acc.a > 0.0)) {
    imageStore(guideImage, p, nz);
    imageStore(pongImage, p, vec4(0.0));
    imageStore(centreImage, p, vec4(1.0, 1.0, 1.0, 0.0));
    return;
  }
  float n = acc.a;
  vec3 mean = acc.rgb / n;
  vec4 as = imageLoad(albedoImage, p);
  vec3 alb = max(as.rgb / n, vec3(albedoFloor));
  vec3 illum = mean / alb;
  float z = nz.w;
  float gradient = denoiseAxisGradient(p, ivec2(1, 0), z, size) + denoiseAxisGradient(p, ivec2(0, 1), z, size);
  float var;
  if (n >= kDenoiseMinTemporalSamples) {
    var = denoiseMeanVariance(n, as.a, luminance(mean));
  } else {  // luminance moments of the similar pixels around
    float s0 = 0.0, s1 = 0.0, s2 = 0.0;
    for (int j = -2; j <= 2; ++j)
      for (int k = -2; k <= 2; ++k) {
        ivec2 q = p + ivec2(k, j);
        if (!insideImage(q, size)) continue;
        vec4 gq = pixelNormalDistance(q);
        if (gq.w < 0.0) continue;
        vec4 aq = imageLoad(accumImage, q);
        float l = luminance(aq.rgb / aq.a);
        float wq = denoiseTapWeight(nz.xyz, gq.xyz, z, gq.w, denoiseDepthScale(sigmaDepth, gradient, max(abs(j), abs(k)), z),
                                    0.0, 1.0);
        s0 += wq;
        s1 += wq * l;
        s2 += wq * l * l;
      }
    float m = s1 / s0;
    var = max(s2 / s0 - m * m, 0.0);
  }
  imageStore(guideImage, p, denoiseGuide(nz.xyz, luminance(alb), z));
  imageStore(pongImage, p, vec4(illum, var));
  imageStore(centreImage, p, vec4(alb, gradient));
}
#endif

#if defined(CAUSTICA_DENOISE_PASS) || defined(CAUSTICA_DENOISE_RESIDUAL)
layout(rgba32f, binding = CAUSTICA_DENOISE_IMAGE_PING) uniform restrict readonly image2D pingImage;
layout(rgba32f, binding = CAUSTICA_DENOISE_IMAGE_OUTPUT) uniform restrict writeonly image2D outputImage;
layout(location = 0) uniform int step;  // pixels between taps: 2^pass
layout(location = 1) uniform int last;  // the last pass: 1 writes the output; 2 (filter passes) the residual

// The kernel of a pass by |offset|: 1/4, 1/2, 1/4.
const float kKernel[2] = float[](1.0 / 2.0, 1.0 / 4.0);

// Tap t (0..8, row by row; 4 is the centre) of an à-trous pass around p, `step` pixels apart: its pixel
// q, kernel weight and guide gq; false for the centre and for taps outside the image or without samples
// (the C++ twin's forEachTap).
bool denoiseTap(ivec2 p, int t, int step, ivec2 size, out ivec2 q, out float kernel, out vec4 gq) {
  ivec2 o = ivec2(t % 3 - 1, t / 3 - 1);
  q = p + step * o;
  kernel = kKernel[abs(o.x)] * kKernel[abs(o.y)];
  gq = vec4(0.0, 0.0, 0.0, -1.0);
  if (t == 4 || !insideImage(q, size)) return false;
  gq = imageLoad(guideImage, q);
  return gq.w >= 0.0;
}
#endif

#ifdef CAUSTICA_DENOISE_PASS
layout(location = 2) uniform float sigmaLuminance;

// One à-trous pass: 3x3 taps `step` pixels apart, weighted by the kernel and denoiseTapWeight, over the
// demodulated illumination and its variance (ping: rgb, a). The last pass writes the remodulated output
// (last 1), or (last 2) what the filter took from each pixel, the raw mean minus the output, with the
// filtered illumination's luminance (output image: rgb, a) for the residual passes.
void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = imageSize(pingImage);
  if (!insideImage(p, size)) return;
  vec4 gp = imageLoad(guideImage, p);
  if (gp.w < 0.0) {
    imageStore(pongImage, p, vec4(0.0));
    if (last != 0) imageStore(outputImage, p, vec4(0.0));
    return;
  }
  vec4 cp = imageLoad(pingImage, p), ctr = imageLoad(centreImage, p);
  vec3 np = denoiseGuideNormal(gp);
  float ap = denoiseGuideAlbedo(gp);
  float ds = denoiseDepthScale(sigmaDepth, ctr.a, step, gp.w);
  float sumW = kKernel[0] * kKernel[0];
  vec3 sumI = sumW * cp.rgb;
  float sumV = sumW * sumW * cp.a;
  for (int t = 0; t < 9; ++t) {
    ivec2 q;
    float kernel;
    vec4 gq;
    if (!denoiseTap(p, t, step, size, q, kernel, gq)) continue;
    vec4 cq = imageLoad(pingImage, q);
    float lumDiff = luminance(ctr.rgb * (cq.rgb - cp.rgb));
    float ls = denoiseLuminanceScale(sigmaLuminance, cp.a, cq.a, ap, denoiseGuideAlbedo(gq));
    float wq = kernel * denoiseTapWeight(np, denoiseGuideNormal(gq), gp.w, gq.w, ds, lumDiff, ls);
    sumW += wq;
    sumI += wq * cq.rgb;
    sumV += wq * wq * cq.a;
  }
  vec3 illum = sumI / sumW;
  imageStore(pongImage, p, vec4(illum, sumV / (sumW * sumW)));
  if (last == 0) return;
  vec4 acc = imageLoad(accumImage, p);
  if (last == 1) imageStore(outputImage, p, vec4(ctr.rgb * illum * acc.a, acc.a));
  else imageStore(outputImage, p, vec4(acc.rgb / acc.a - ctr.rgb * illum, luminance(illum)));
}
#endif

#ifdef CAUSTICA_DENOISE_RESIDUAL
layout(rgba32f, binding = CAUSTICA_DENOISE_IMAGE_FILTERED) uniform restrict readonly image2D filteredImage;
layout(rgba32f, binding = CAUSTICA_DENOISE_IMAGE_MOMENTS) uniform restrict readonly image2D momentImage;
layout(location = 5) uniform float sigmaResidual;
layout(location = 6) uniform float residualBound;

// One residual pass: the same taps, weighted by normal, distance and the relative difference of the
// filtered illumination's luminance (ping: residual rgb, that luminance a), spread the residual over its
// surface and its like; the last one writes the output: the filtered illumination x albedo (filtered
// image) plus the spread residual, at most residualBound standard deviations of the pixel's mean.
void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = imageSize(pingImage);
  if (!insideImage(p, size)) return;
  vec4 gp = imageLoad(guideImage, p);
  if (gp.w < 0.0) {
    imageStore(pongImage, p, vec4(0.0));
    if (last != 0) imageStore(outputImage, p, vec4(0.0));
    return;
  }
  vec4 ctr = imageLoad(centreImage, p);
  vec4 rp = imageLoad(pingImage, p);
  vec3 np = denoiseGuideNormal(gp);
  float ds = denoiseDepthScale(sigmaDepth, ctr.a, step, gp.w);
  float sumW = kKernel[0] * kKernel[0];
  vec3 sumR = sumW * rp.rgb;
  for (int t = 0; t < 9; ++t) {
    ivec2 q;
    float kernel;
    vec4 gq;
    if (!denoiseTap(p, t, step, size, q, kernel, gq)) continue;
    vec4 rq = imageLoad(pingImage, q);
    float wq = kernel * denoiseTapWeight(np, denoiseGuideNormal(gq), gp.w, gq.w, ds, rp.a - rq.a, sigmaResidual * (rp.a + rq.a) + kDenoiseTiny);
    sumW += wq;
    sumR += wq * rq.rgb;
  }
  vec3 spread = sumR / sumW;
  imageStore(pongImage, p, vec4(spread, rp.a));
  if (last != 0) {
    vec4 acc = imageLoad(accumImage, p);
    vec3 correction = spread;
    if (acc.a >= kDenoiseMinTemporalSamples)
      correction = denoiseBoundedCorrection(correction, residualBound, acc.a, imageLoad(momentImage, p).a, luminance(acc.rgb / acc.a));
    imageStore(outputImage, p, vec4((ctr.rgb * imageLoad(filteredImage, p).rgb + correction) * acc.a, acc.a));
  }
}
#endif
