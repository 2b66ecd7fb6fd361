#version 330 core
// Unlit geometry through one matrix: the floor grid lines and textured quads (world space, the
// view-projection), and the editor's Dear ImGui draw lists (pixels, an orthographic projection).
// Vertex layout: unlit_vertex.glsl.
uniform mat4 u_view_projection;
void main() {
  pass_colour_and_uv();
  gl_Position = u_view_projection * vec4(a_position, 1.0);
}
