// The vertex layout of the unlit programs, one for all: link_program() inserts this file after
// the #version line of flat.vert.glsl and overlay.vert.glsl (render/shader_sources.hpp,
// kUnlitVertex). The renderer's flat and overlay vertices and the editor's ImGui vertices all
// feed location 0 with the position (2 or 3 floats; a missing z reads as 0), 1 with the RGBA
// colour and 2 with the texture coordinate.
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec4 a_colour;
layout(location = 2) in vec2 a_uv;
out vec4 v_colour;
out vec2 v_uv;

// Hands the colour and the texture coordinate on to the fragment shader unchanged.
void pass_colour_and_uv() {
  v_colour = a_colour;
  v_uv = a_uv;
}
