#version 330 core
// Lit triangle meshes (avatars, controller boxes). World-space lighting.
// Varyings are what Mesa's software rasterizer (llvmpipe) pays for per triangle on the calling
// thread, so the vertex shader hands on only the normal, and the colour only in the variant
// with per-vertex colours (VERTEX_COLOURS defined: the renderer's second mesh program); the
// fragment shader finds the world position from gl_FragCoord.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_colour;
uniform mat4 u_model;
uniform mat4 u_normal_matrix;
uniform mat4 u_view_projection;
out vec3 v_normal;
#ifdef VERTEX_COLOURS
out vec3 v_colour;
#endif
void main() {
  v_normal = mat3(u_normal_matrix) * a_normal;
#ifdef VERTEX_COLOURS
  v_colour = a_colour;
#endif
  gl_Position = u_view_projection * (u_model * vec4(a_position, 1.0));
}
