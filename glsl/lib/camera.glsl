// camera.glsl — pinhole eye rays with a box filter over the pixel's square footprint.
// Pixel (0,0) is the top-left of the image; directions are world space, unit length.

vec3 eyeRayDirection(uvec2 pixel, vec2 jitter) {
  vec2 size = vec2(frame.frame.xy);
  vec2 ndc = vec2((float(pixel.x) + jitter.x) / size.x * 2.0 - 1.0, 1.0 - (float(pixel.y) + jitter.y) / size.y * 2.0);
  return normalize(frame.camForward.xyz + ndc.x * frame.camRight.xyz + ndc.y * frame.camUp.xyz);
}
