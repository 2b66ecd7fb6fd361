#version 330 core
// Two-sided diffuse + soft specular with a hemisphere ambient term.
in vec3 v_normal;
in vec3 v_colour;
in vec3 v_world;
uniform vec4 u_colour;          // base colour
uniform int u_vertex_colours;   // 1: use the per-vertex colour
uniform int u_flat;             // 1: unlit u_colour (wireframe pass)
uniform vec3 u_light_direction; // towards the light, normalised
uniform vec3 u_eye;
out vec4 frag_colour;
void main() {
  if (u_flat == 1) {
    frag_colour = u_colour;
    return;
  }
  vec3 base = (u_vertex_colours == 1) ? v_colour : u_colour.rgb;
  vec3 n = normalize(v_normal);
  vec3 view_dir = normalize(u_eye - v_world);
  if (dot(n, view_dir) < 0.0) n = -n;
  float diffuse = max(dot(n, u_light_direction), 0.0);
  float fill = max(dot(n, normalize(vec3(0.6, 0.2, 0.5))), 0.0);
  float hemi = 0.5 + 0.5 * n.y;
  vec3 h = normalize(u_light_direction + view_dir);
  float specular = pow(max(dot(n, h), 0.0), 32.0) * 0.15;
  vec3 colour = base * (0.25 + 0.15 * hemi + 0.55 * diffuse + 0.15 * fill) + vec3(specular);
  frag_colour = vec4(colour, u_colour.a);
}
