// shadow.vert — vertex stage of a raster-mode shadow map face: world positions through one of the six
// 90-degree views of a point light.
layout(location = 0) in vec3 inPosition;     // world space
layout(location = 0) uniform mat4 viewProj;  // world -> clip of the cube face
out vec3 vPosition;

void main() {
  vPosition = inPosition;
  gl_Position = viewProj * vec4(inPosition, 1.0);
}
