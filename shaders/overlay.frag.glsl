#version 330 core
// u_mode 0: solid colour; 1: round dot (uv in [-1, 1]^2); 2: texture (alpha from red for fonts
// when u_alpha_texture is 1, RGBA otherwise).
in vec2 v_uv;
in vec4 v_colour;
uniform int u_mode;
uniform int u_alpha_texture;
uniform sampler2D u_texture;
out vec4 frag_colour;
void main() {
  if (u_mode == 1) {
    if (dot(v_uv, v_uv) > 1.0) discard;
    frag_colour = v_colour;
  } else if (u_mode == 2) {
    vec4 t = texture(u_texture, v_uv);
    frag_colour = (u_alpha_texture == 1) ? vec4(v_colour.rgb, v_colour.a * t.r) : t * v_colour;
  } else {
    frag_colour = v_colour;
  }
}
