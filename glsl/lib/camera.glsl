// camera.glsl — eye rays with a box filter over the pixel's square footprint: from a pinhole, or
// (frame.camForward.w = 1) parallel from an orthographic camera's image plane through the eye.
// Pixel (0,0) is the top-left of the image; directions are world space, unit length.

void eyeRay(uvec2 pixel, vec2 jitter, out vec3 org, out vec3 dir) {
  vec2 size = vec2(frame.frame.xy);
  vec2 ndc = vec2((float(pixel.x) + jitter.x) / size.x * 2.0 - 1.0, 1.0 - (float(pixel.y) + jitter.y) / size.y * 2.0);
  if (frame.camForward.w > 0.0) {
    org = frame.camPos.xyz + ndc.x * frame.camRight.xyz + ndc.y * frame.camUp.xyz;
    dir = frame.camForward.xyz;
  } else {
    org = frame.camPos.xyz;
    dir = normalize(frame.camForward.xyz + ndc.x * frame.camRight.xyz + ndc.y * frame.camUp.xyz);
  }
}
