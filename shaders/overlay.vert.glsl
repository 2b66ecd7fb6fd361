#version 330 core
// Screen-space overlay: text, labels, legends, landmark dots, measurement lines, UI.
// Positions are pixels from the viewport's top-left corner.
layout(location = 0) in vec2 a_position;
layout(location = 1) in vec2 a_uv;
layout(location = 2) in vec4 a_colour;
uniform vec2 u_viewport_size;
out vec2 v_uv;
out vec4 v_colour;
void main() {
  v_uv = a_uv;
  v_colour = a_colour;
  vec2 ndc = vec2(a_position.x / u_viewport_size.x * 2.0 - 1.0,
                  1.0 - a_position.y / u_viewport_size.y * 2.0);
  gl_Position = vec4(ndc, 0.0, 1.0);
}
