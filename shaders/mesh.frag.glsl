#version 330 core
// Two-sided diffuse + soft specular with a hemisphere ambient term.
in vec3 v_normal;
#ifdef VERTEX_COLOURS
in vec3 v_colour;                 // per-vertex colour (the variant with VERTEX_COLOURS defined)
#endif
uniform vec4 u_colour;            // base colour
uniform int u_flat;               // 1: unlit u_colour (wireframe pass)
uniform vec3 u_light_direction;   // towards the light, normalised
uniform vec3 u_eye;
uniform mat4 u_inverse_view_projection;
uniform vec4 u_viewport;          // x, y, width, height in pixels (glViewport's)
out vec4 frag_colour;

// The fragment's world position: its window coordinates back through the viewport (depth range
// 0..1) and the inverse view-projection. It replaces a world-position varying, which would cost
// the software rasterizer three more interpolated values per triangle.
vec3 world_position() {
  vec3 ndc = vec3((gl_FragCoord.xy - u_viewport.xy) / u_viewport.zw, gl_FragCoord.z) * 2.0 - 1.0;
  vec4 p = u_inverse_view_projection * vec4(ndc, 1.0);
  return p.xyz / p.w;
}

void main() {
  if (u_flat == 1) {
    frag_colour = u_colour;
    return;
  }
#ifdef VERTEX_COLOURS
  vec3 base = v_colour;
#else
  vec3 base = u_colour.rgb;
#endif
  vec3 n = normalize(v_normal);
  vec3 view_dir = normalize(u_eye - world_position());
  if (dot(n, view_dir) < 0.0) n = -n;
  float diffuse = max(dot(n, u_light_direction), 0.0);
  float fill = max(dot(n, normalize(vec3(0.6, 0.2, 0.5))), 0.0);
  float hemi = 0.5 + 0.5 * n.y;
  vec3 h = normalize(u_light_direction + view_dir);
  float specular = pow(max(dot(n, h), 0.0), 32.0) * 0.15;
  vec3 colour = base * (0.25 + 0.15 * hemi + 0.55 * diffuse + 0.15 * fill) + vec3(specular);
  frag_colour = vec4(colour, u_colour.a);
}
