#version 330 core
in vec4 v_colour;
in vec2 v_uv;
uniform int u_textured;
uniform sampler2D u_texture;
out vec4 frag_colour;
void main() {
  frag_colour = (u_textured == 1) ? texture(u_texture, v_uv) * v_colour : v_colour;
}
