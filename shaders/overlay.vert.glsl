#version 330 core
// Screen-space overlay: text, labels, legends, landmark dots, measurement lines, UI.
// Positions are pixels from the viewport's top-left corner. Vertex layout: unlit_vertex.glsl.
uniform vec2 u_viewport_size;
void main() {
  pass_colour_and_uv();
  vec2 ndc = vec2(a_position.x / u_viewport_size.x * 2.0 - 1.0,
                  1.0 - a_position.y / u_viewport_size.y * 2.0);
  gl_Position = vec4(ndc, 0.0, 1.0);
}
