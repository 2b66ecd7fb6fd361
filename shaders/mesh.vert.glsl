#version 330 core
// Lit triangle meshes (avatars, controller boxes). World-space lighting.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_colour;
uniform mat4 u_model;
uniform mat4 u_normal_matrix;
uniform mat4 u_view_projection;
out vec3 v_normal;
out vec3 v_colour;
out vec3 v_world;
void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = mat3(u_normal_matrix) * a_normal;
  v_colour = a_colour;
  gl_Position = u_view_projection * world;
}
