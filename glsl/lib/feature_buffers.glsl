// feature_buffers.glsl — the denoiser's feature buffers (CAUSTICA_AOV; docs/denoising.md): per pixel,
// summed over the same samples as the accumulation image (its count is theirs), the albedo, shading
// normal and distance of each sample's first non-specular hit, and the second moment of its radiance's
// luminance (the pixel's variance). Through smooth glass, mirrors and alpha cut-outs the path's
// specular chain is followed (OpenImageDenoise's convention): a glass ball's albedo is what is seen
// through it. Emitting surfaces and rays that leave the scene record albedo 1 (what a denoiser divides
// by leaves their radiance as it is) and normal 0 (OpenImageDenoise's "no surface"). World space;
// distance in scene units along the (unfolded) path from the camera.

layout(rgba32f, binding = CAUSTICA_IMAGE_ALBEDO) uniform restrict image2D albedoImage;  // rgb albedo, a luminance^2
layout(rgba32f, binding = CAUSTICA_IMAGE_NORMAL) uniform restrict image2D normalImage;  // xyz normal, w distance

// One sample's features, gathered along its path (part of PathState).
struct SampleFeatures {
  vec3 albedo;
  vec3 normal;     // unit shading normal on the side the ray came from; 0: none
  float distance;  // path length to the first non-specular hit (scene units; 0: none)
  float travelled; // path length so far
  bool found;      // the first non-specular hit (or an emitter, or the sky) is recorded
};

SampleFeatures noFeatures() { return SampleFeatures(vec3(0.0), vec3(0.0), 0.0, 0.0, false); }

// The path of this sample went `t` further along its ray.
void featuresTravel(inout SampleFeatures f, float t) {
  if (!f.found) f.travelled += t;
}

// Records what the path found as the sample's features, unless something is recorded already: a surface
// (at the distance travelled) or, with `sky`, the ray leaving the scene (distance 0).
void featuresRecord(inout SampleFeatures f, vec3 albedo, vec3 normal, bool sky) {
  if (!f.found) {
    f.albedo = albedo;
    f.normal = normal;
    f.distance = sky ? 0.0 : f.travelled;
    f.found = true;
  }
}

// One pixel's feature sums as the two images hold them.
struct FeatureSums {
  vec4 albedo;  // rgb: albedo sum; a: sum of luminance(radiance)^2
  vec4 normal;  // xyz: normal sum; w: distance sum
};

FeatureSums loadFeatureSums(ivec2 pixel) {
  return FeatureSums(imageLoad(albedoImage, pixel), imageLoad(normalImage, pixel));
}

void storeFeatureSums(ivec2 pixel, FeatureSums s) {
  imageStore(albedoImage, pixel, s.albedo);
  imageStore(normalImage, pixel, s.normal);
}

// Adds one finite sample of radiance `value` and its features (a rejected sample adds nothing, as it
// adds nothing to the accumulation image's count).
void addFeatureSample(inout FeatureSums s, SampleFeatures f, vec3 value) {
  float l = luminance(value);
  s.albedo += vec4(f.albedo, l * l);
  s.normal += vec4(f.normal, f.distance);
}
