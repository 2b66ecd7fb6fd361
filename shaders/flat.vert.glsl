#version 330 core
// Unlit world-space geometry: floor grid lines and textured quads.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec4 a_colour;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_view_projection;
out vec4 v_colour;
out vec2 v_uv;
void main() {
  v_colour = a_colour;
  v_uv = a_uv;
  gl_Position = u_view_projection * vec4(a_position, 1.0);
}
