// shadow.frag — writes the distance from the point light over its far distance as depth, so a cube
// lookup in any direction gives the nearest occluder's distance (raster.frag: shadowVisibility).
in vec3 vPosition;
layout(location = 1) uniform vec4 lightPosFar;  // xyz: light position (world), w: far distance (scene units)

void main() {
  gl_FragDepth = clamp(length(vPosition - lightPosFar.xyz) / lightPosFar.w, 0.0, 1.0);
}
