// raster.vert — vertex stage of the raster mode (docs/render-modes.md): world-space triangles (the
// scene is flattened, no model matrix) through the camera, or through the camera mirrored in a plane.
layout(location = 0) in vec3 inPosition;     // world space
layout(location = 1) in vec3 inNormal;       // unit shading normal (world space)
layout(location = 2) in vec2 inUv;           // TEXCOORD_0 (glTF: v down)
layout(location = 3) in vec3 inGeomNormal;   // unit normal of the triangle's front (counter-clockwise) face
layout(location = 4) in vec4 inColor;        // vertex colour (COLOR_0, linear RGBA; white without)

layout(location = 0) uniform mat4 viewProj;  // world -> clip (for a mirror pass: times the reflection)
layout(location = 1) uniform vec4 clipPlane; // keeps world points with dot(clipPlane, (p, 1)) >= 0

out vec3 vPosition;
out vec3 vNormal;
out vec2 vUv;
out vec3 vGeomNormal;
out vec4 vColor;

void main() {
  vPosition = inPosition;
  vNormal = inNormal;
  vUv = inUv;
  vGeomNormal = inGeomNormal;
  vColor = inColor;
  gl_ClipDistance[0] = dot(clipPlane, vec4(inPosition, 1.0));
  gl_Position = viewProj * vec4(inPosition, 1.0);
}
