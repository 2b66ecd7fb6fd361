// The OpenGL 3.3 core renderer. Sections: shader helpers, mesh upload, per-frame drawing
// (grid, meshes, boxes, quads, depth-tested lines), screen-space overlay (lines drawn on top,
// landmark dots, labels, legend).
#include "render/renderer.hpp"

#include <meshoptimizer.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>

#include "render/camera.hpp"
#include "render/colour_map.hpp"
#include "render/shader_sources.hpp"
#include "render/text.hpp"

namespace caliper::render {

// ---------------------------------------------------------------------------------------------
// Helpers
namespace {

Mat4 normal_matrix(const Mat4& model) {
  Mat4 n = Mat4::Identity();
  n.block<3, 3>(0, 0) = model.block<3, 3>(0, 0).inverse().transpose();
  return n;
}

}  // namespace

std::vector<float> vertex_normals(const std::vector<float>& positions,
                                  const std::vector<std::uint32_t>& indices) {
  std::vector<float> n(positions.size(), 0.0f);
  for (size_t f = 0; f + 2 < indices.size(); f += 3) {
    const size_t i0 = indices[f], i1 = indices[f + 1], i2 = indices[f + 2];
    const Vec3 a(&positions[3 * i0]), b(&positions[3 * i1]), c(&positions[3 * i2]);
    const Vec3 fn = (b - a).cross(c - a);  // length = 2 area: area weighting
    for (size_t i : {i0, i1, i2}) {
      n[3 * i] += fn.x();
      n[3 * i + 1] += fn.y();
      n[3 * i + 2] += fn.z();
    }
  }
  for (size_t v = 0; v + 2 < n.size(); v += 3) {
    const float len = std::sqrt(n[v] * n[v] + n[v + 1] * n[v + 1] + n[v + 2] * n[v + 2]);
    if (len > 0) {
      n[v] /= len;
      n[v + 1] /= len;
      n[v + 2] /= len;
    } else {
      n[v] = 0;
      n[v + 1] = 1;
      n[v + 2] = 0;
    }
  }
  return n;
}

// ---------------------------------------------------------------------------------------------
// GPU objects
struct GpuMesh {
  GLuint vao = 0, positions = 0, normals = 0, colours = 0, indices = 0;
  GLsizei index_count = 0;
  size_t vertex_count = 0;
  bool has_colours = false;
  /// Closed and consistently wound (see winding_for_culling): drawn with back faces culled,
  /// which halves the triangles Mesa's software rasterizer sets up per frame.
  bool cull_back_faces = false;
  bool inward = false;  ///< wound clockwise seen from outside (negative signed volume)
  std::vector<std::uint32_t> cpu_indices;  // kept to recompute normals on update_positions
  /// Index ranges in the index buffer: [0] the full mesh, then simplified levels, coarser and
  /// coarser, each with its geometric error (mesh units) measured on the shape at upload.
  struct Level {
    size_t first = 0;
    GLsizei count = 0;
    float error = 0;
  };
  std::vector<Level> levels;
  /// The positions at upload, kept until the levels are made (prepare_levels(), or the first
  /// draw with level of detail on); empty when the mesh gets none or has them.
  std::vector<float> level_positions;
  Eigen::AlignedBox3f box;  ///< of the current positions, for meshes that get levels (depth)
};

/// One of the two variants of the mesh program (shaders/mesh.*.glsl) and its uniforms' locations:
/// without per-vertex colours (the normal is the only varying) and with them.
struct MeshProgram {
  GLuint id = 0;
  GLint model = -1, normal = -1, colour = -1, flat = -1;
  GLint view_projection = -1, inverse_view_projection = -1, viewport = -1, light = -1, eye = -1;
};

struct Renderer::Impl {
  MeshProgram mesh_plain, mesh_coloured;
  GLuint flat_program = 0, overlay_program = 0;
  std::map<MeshHandle, GpuMesh> meshes;
  std::map<TextureHandle, GLuint> textures;
  MeshHandle next_mesh = 1;
  TextureHandle next_texture = 1;
  MeshHandle cube = 0;
  bool cull_closed_meshes = true;
  bool level_of_detail = false;
  size_t triangles_drawn = 0;
  GLuint flat_vao = 0, flat_vbo = 0;        // pos3 colour4 uv2
  GLuint overlay_vao = 0, overlay_vbo = 0;  // pos2 colour4 uv2
  std::vector<float> flat_vertices, overlay_vertices;

  /// The passes of Renderer::draw, in order, for one view with view-projection `vp_m`:
  /// lit, depth-tested meshes and boxes;
  void draw_meshes(const GlFunctions& gl, const Scene& scene, const Viewport& viewport,
                   const Mat4& view_m, const Mat4& proj, const Vec3& eye);
  /// the floor grid, the depth-tested lines and the textured quads;
  void draw_flat(const GlFunctions& gl, const Scene& scene, const Mat4& vp_m);
  /// the screen-space overlay of a w x h viewport: on-top lines, points, labels and legend.
  void draw_overlay(const GlFunctions& gl, const Scene& scene, const Mat4& vp_m, int w, int h);
};

namespace {

void check_mesh(const MeshData& m) {
  if (m.positions.size() % 3 != 0) {
    throw RenderError("mesh positions: expected 3V floats, got " +
                      std::to_string(m.positions.size()));
  }
  const size_t v = m.positions.size() / 3;
  if (!m.normals.empty() && m.normals.size() != m.positions.size()) {
    throw RenderError("mesh normals: expected " + std::to_string(3 * v) + " floats or none, got " +
                      std::to_string(m.normals.size()));
  }
  if (!m.colours.empty() && m.colours.size() != m.positions.size()) {
    throw RenderError("mesh colours: expected " + std::to_string(3 * v) + " floats or none, got " +
                      std::to_string(m.colours.size()));
  }
  if (m.indices.size() % 3 != 0) {
    throw RenderError("mesh indices: expected 3F values, got " + std::to_string(m.indices.size()));
  }
  for (std::uint32_t i : m.indices) {
    if (i >= v) {
      throw RenderError("mesh indices: vertex index " + std::to_string(i) +
                        " out of range (V = " + std::to_string(v) + ")");
    }
  }
}

void fill_buffer(const GlFunctions& gl, GLuint buffer, GLenum target, const void* data,
                 size_t bytes) {
  gl.BindBuffer(target, buffer);
  gl.BufferData(target, static_cast<GLsizeiptr>(bytes), data, GL_DYNAMIC_DRAW);
}

/// Back faces of a mesh can be culled without changing the picture only when the surface is
/// closed and consistently oriented: every directed edge (a, b) occurs exactly once and so does
/// its reverse (b, a). Meshes with holes, duplicated seams (the flat-shaded cube) or mixed
/// winding are drawn two-sided. The winding direction comes from the signed volume.
void winding_for_culling(GpuMesh& g, const std::vector<float>& positions,
                         const std::vector<std::uint32_t>& indices) {
  g.cull_back_faces = false;
  g.inward = false;
  if (indices.empty()) return;
  std::vector<std::uint64_t> edges;
  edges.reserve(indices.size());
  for (size_t f = 0; f + 2 < indices.size(); f += 3) {
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = indices[f + static_cast<size_t>(k)];
      const std::uint64_t b = indices[f + static_cast<size_t>((k + 1) % 3)];
      if (a == b) return;  // degenerate triangle: no well-defined winding
      edges.push_back(a << 32 | b);
    }
  }
  std::sort(edges.begin(), edges.end());
  if (std::adjacent_find(edges.begin(), edges.end()) != edges.end()) return;
  for (std::uint64_t e : edges) {
    const std::uint64_t reverse = (e & 0xffffffffu) << 32 | e >> 32;
    if (!std::binary_search(edges.begin(), edges.end(), reverse)) return;
  }
  double volume6 = 0;
  for (size_t f = 0; f + 2 < indices.size(); f += 3) {
    const Vec3 a(&positions[3 * size_t{indices[f]}]), b(&positions[3 * size_t{indices[f + 1]}]),
        c(&positions[3 * size_t{indices[f + 2]}]);
    volume6 += static_cast<double>(a.dot(b.cross(c)));
  }
  if (volume6 == 0.0 || !std::isfinite(volume6)) return;
  g.cull_back_faces = true;
  g.inward = volume6 < 0;
}

Eigen::AlignedBox3f bounding_box(const std::vector<float>& positions) {
  Eigen::AlignedBox3f box;
  for (size_t i = 0; i + 2 < positions.size(); i += 3) box.extend(Vec3(&positions[i]));
  return box;
}

/// The relative errors (of the mesh's extent) of the simplified levels: 1/8192 of a 1.7 m body
/// is 0.2 mm, a quarter of a pixel where the body fills 1000 pixels; 1/256 is 6.6 mm.
constexpr float kLevelErrors[] = {1.0f / 8192, 1.0f / 4096, 1.0f / 2048,
                                  1.0f / 1024, 1.0f / 512,  1.0f / 256};

/// Whether `g` gets simplified levels: closed and of Renderer::kLodMinTriangles or more.
bool wants_levels(const GpuMesh& g) {
  return g.cull_back_faces && static_cast<size_t>(g.index_count) / 3 >= Renderer::kLodMinTriangles;
}

/// Makes the simplified levels of `g` from the positions kept at upload, one for each of
/// kLevelErrors that keeps at most 85 % of the previous level's triangles, and puts the indices
/// of all levels, one after the other, in its index buffer (the full mesh's stay first).
void build_levels(const GlFunctions& gl, GpuMesh& g) {
  if (g.level_positions.empty()) return;
  const std::vector<float> positions = std::move(g.level_positions);
  g.level_positions.clear();
  const std::vector<std::uint32_t>& full = g.cpu_indices;
  const float scale = meshopt_simplifyScale(positions.data(), g.vertex_count, 3 * sizeof(float));
  std::vector<std::uint32_t> all = full, out(full.size());
  size_t previous = full.size();
  for (float relative : kLevelErrors) {
    float error = 0;
    const size_t n = meshopt_simplify(out.data(), full.data(), full.size(), positions.data(),
                                      g.vertex_count, 3 * sizeof(float), 0, relative, 0, &error);
    if (n == 0 || n > previous * 85 / 100) continue;
    g.levels.push_back(GpuMesh::Level{all.size(), static_cast<GLsizei>(n), error * scale});
    all.insert(all.end(), out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n));
    previous = n;
  }
  gl.BindVertexArray(g.vao);
  fill_buffer(gl, g.indices, GL_ELEMENT_ARRAY_BUFFER, all.data(), all.size() * 4);
  gl.BindVertexArray(0);
}

void set_mesh_data(const GlFunctions& gl, GpuMesh& g, const MeshData& m) {
  winding_for_culling(g, m.positions, m.indices);
  g.vertex_count = m.positions.size() / 3;
  g.index_count = static_cast<GLsizei>(m.indices.size());
  g.cpu_indices = m.indices;
  g.has_colours = !m.colours.empty();
  gl.BindVertexArray(g.vao);
  fill_buffer(gl, g.positions, GL_ARRAY_BUFFER, m.positions.data(), m.positions.size() * 4);
  gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  gl.EnableVertexAttribArray(0);
  const std::vector<float> normals =
      m.normals.empty() ? vertex_normals(m.positions, m.indices) : m.normals;
  fill_buffer(gl, g.normals, GL_ARRAY_BUFFER, normals.data(), normals.size() * 4);
  gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  gl.EnableVertexAttribArray(1);
  const std::vector<float> colours =
      m.colours.empty() ? std::vector<float>(m.positions.size(), 1.0f) : m.colours;
  fill_buffer(gl, g.colours, GL_ARRAY_BUFFER, colours.data(), colours.size() * 4);
  gl.VertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  gl.EnableVertexAttribArray(2);
  fill_buffer(gl, g.indices, GL_ELEMENT_ARRAY_BUFFER, m.indices.data(), m.indices.size() * 4);
  gl.BindVertexArray(0);
  g.levels.assign(1, GpuMesh::Level{0, g.index_count, 0.0f});
  g.level_positions.clear();
  g.box.setEmpty();
  if (wants_levels(g)) {
    g.level_positions = m.positions;
    g.box = bounding_box(m.positions);
  }
}

MeshProgram link_mesh_program(const GlFunctions& gl, bool vertex_colours) {
  const char* prelude = vertex_colours ? "#define VERTEX_COLOURS 1" : nullptr;
  MeshProgram p;
  p.id = link_program(gl, shaders::kMeshVert, shaders::kMeshFrag,
                      vertex_colours ? "mesh (vertex colours)" : "mesh", prelude, prelude);
  p.model = gl.GetUniformLocation(p.id, "u_model");
  p.normal = gl.GetUniformLocation(p.id, "u_normal_matrix");
  p.colour = gl.GetUniformLocation(p.id, "u_colour");
  p.flat = gl.GetUniformLocation(p.id, "u_flat");
  p.view_projection = gl.GetUniformLocation(p.id, "u_view_projection");
  p.inverse_view_projection = gl.GetUniformLocation(p.id, "u_inverse_view_projection");
  p.viewport = gl.GetUniformLocation(p.id, "u_viewport");
  p.light = gl.GetUniformLocation(p.id, "u_light_direction");
  p.eye = gl.GetUniformLocation(p.id, "u_eye");
  return p;
}

MeshData cube_mesh() {
  MeshData m;
  // 6 faces with their own vertices so that normals are flat.
  const int axes[6][3] = {{0, 1, 2}, {0, 1, 2}, {1, 2, 0}, {1, 2, 0}, {2, 0, 1}, {2, 0, 1}};
  for (int f = 0; f < 6; ++f) {
    const float sign = (f % 2 == 0) ? 1.0f : -1.0f;
    const int n = axes[f][2], u = axes[f][0], v = axes[f][1];
    const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    const auto base = static_cast<std::uint32_t>(m.positions.size() / 3);
    for (auto& c : corners) {
      float p[3];
      p[n] = sign;
      p[u] = c[0];
      p[v] = c[1] * sign;
      m.positions.insert(m.positions.end(), p, p + 3);
      float nn[3] = {0, 0, 0};
      nn[n] = sign;
      m.normals.insert(m.normals.end(), nn, nn + 3);
    }
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
  }
  return m;
}

void setup_interleaved(const GlFunctions& gl, GLuint vao, GLuint vbo,
                       std::initializer_list<int> sizes) {
  gl.BindVertexArray(vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, vbo);
  int stride = 0;
  for (int s : sizes) stride += s;
  int offset = 0, index = 0;
  for (int s : sizes) {
    gl.VertexAttribPointer(
        static_cast<GLuint>(index), s, GL_FLOAT, GL_FALSE, stride * 4,
        // NOLINTNEXTLINE(performance-no-int-to-ptr): GL takes the byte offset as a pointer
        reinterpret_cast<const void*>(static_cast<std::uintptr_t>(offset * 4)));
    gl.EnableVertexAttribArray(static_cast<GLuint>(index));
    offset += s;
    ++index;
  }
  gl.BindVertexArray(0);
}

}  // namespace

Renderer::Renderer(const GlFunctions& gl) : gl_(gl), impl_(std::make_unique<Impl>()) {
  impl_->mesh_plain = link_mesh_program(gl, false);
  impl_->mesh_coloured = link_mesh_program(gl, true);
  impl_->flat_program =
      link_program(gl, shaders::kFlatVert, shaders::kFlatFrag, "flat", shaders::kUnlitVertex);
  impl_->overlay_program = link_program(gl, shaders::kOverlayVert, shaders::kOverlayFrag, "overlay",
                                        shaders::kUnlitVertex);
  gl.GenVertexArrays(1, &impl_->flat_vao);
  gl.GenBuffers(1, &impl_->flat_vbo);
  setup_interleaved(gl, impl_->flat_vao, impl_->flat_vbo, {3, 4, 2});
  gl.GenVertexArrays(1, &impl_->overlay_vao);
  gl.GenBuffers(1, &impl_->overlay_vbo);
  setup_interleaved(gl, impl_->overlay_vao, impl_->overlay_vbo, {2, 4, 2});
  impl_->cube = upload_mesh(cube_mesh());
  gl.check("Renderer setup");
}

Renderer::~Renderer() {
  const GlFunctions& gl = gl_;
  for (auto& [h, g] : impl_->meshes) {
    GLuint buffers[4] = {g.positions, g.normals, g.colours, g.indices};
    gl.DeleteBuffers(4, buffers);
    gl.DeleteVertexArrays(1, &g.vao);
  }
  for (auto& [h, t] : impl_->textures) gl.DeleteTextures(1, &t);
  gl.DeleteBuffers(1, &impl_->flat_vbo);
  gl.DeleteVertexArrays(1, &impl_->flat_vao);
  gl.DeleteBuffers(1, &impl_->overlay_vbo);
  gl.DeleteVertexArrays(1, &impl_->overlay_vao);
  gl.DeleteProgram(impl_->mesh_plain.id);
  gl.DeleteProgram(impl_->mesh_coloured.id);
  gl.DeleteProgram(impl_->flat_program);
  gl.DeleteProgram(impl_->overlay_program);
}

MeshHandle Renderer::upload_mesh(const MeshData& mesh) {
  check_mesh(mesh);
  GpuMesh g;
  gl_.GenVertexArrays(1, &g.vao);
  GLuint buffers[4];
  gl_.GenBuffers(4, buffers);
  g.positions = buffers[0];
  g.normals = buffers[1];
  g.colours = buffers[2];
  g.indices = buffers[3];
  set_mesh_data(gl_, g, mesh);
  const MeshHandle h = impl_->next_mesh++;
  impl_->meshes.emplace(h, std::move(g));
  return h;
}

namespace {
GpuMesh& find_mesh(std::map<MeshHandle, GpuMesh>& meshes, MeshHandle h) {
  auto it = meshes.find(h);
  if (it == meshes.end()) throw RenderError("unknown mesh handle " + std::to_string(h));
  return it->second;
}
}  // namespace

void Renderer::update_mesh(MeshHandle handle, const MeshData& mesh) {
  check_mesh(mesh);
  set_mesh_data(gl_, find_mesh(impl_->meshes, handle), mesh);
}

void Renderer::set_cull_closed_meshes(bool on) {
  impl_->cull_closed_meshes = on;
}
bool Renderer::cull_closed_meshes() const {
  return impl_->cull_closed_meshes;
}
void Renderer::set_level_of_detail(bool on) {
  impl_->level_of_detail = on;
}
bool Renderer::level_of_detail() const {
  return impl_->level_of_detail;
}
void Renderer::prepare_levels(MeshHandle handle) {
  build_levels(gl_, find_mesh(impl_->meshes, handle));
}
size_t Renderer::triangles_drawn() const {
  return impl_->triangles_drawn;
}

void Renderer::update_positions(MeshHandle handle, const std::vector<float>& positions) {
  GpuMesh& g = find_mesh(impl_->meshes, handle);
  if (positions.size() != 3 * g.vertex_count) {
    throw RenderError("update_positions: expected " + std::to_string(3 * g.vertex_count) +
                      " floats, got " + std::to_string(positions.size()));
  }
  const std::vector<float> normals = vertex_normals(positions, g.cpu_indices);
  if (wants_levels(g)) g.box = bounding_box(positions);  // only level picking needs it
  gl_.BindBuffer(GL_ARRAY_BUFFER, g.positions);
  gl_.BufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(positions.size() * 4),
                    positions.data());
  gl_.BindBuffer(GL_ARRAY_BUFFER, g.normals);
  gl_.BufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(normals.size() * 4),
                    normals.data());
}

void Renderer::update_colours(MeshHandle handle, const std::vector<float>& colours) {
  GpuMesh& g = find_mesh(impl_->meshes, handle);
  if (!colours.empty() && colours.size() != 3 * g.vertex_count) {
    throw RenderError("update_colours: expected " + std::to_string(3 * g.vertex_count) +
                      " floats, got " + std::to_string(colours.size()));
  }
  g.has_colours = !colours.empty();
  if (colours.empty()) return;
  gl_.BindBuffer(GL_ARRAY_BUFFER, g.colours);
  gl_.BufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(colours.size() * 4),
                    colours.data());
}

void Renderer::release_mesh(MeshHandle handle) {
  auto it = impl_->meshes.find(handle);
  if (it == impl_->meshes.end()) return;
  GLuint buffers[4] = {it->second.positions, it->second.normals, it->second.colours,
                       it->second.indices};
  gl_.DeleteBuffers(4, buffers);
  gl_.DeleteVertexArrays(1, &it->second.vao);
  impl_->meshes.erase(it);
}

TextureHandle Renderer::upload_texture(const Image& image) {
  GLuint t = 0;
  gl_.GenTextures(1, &t);
  const TextureHandle h = impl_->next_texture++;
  impl_->textures[h] = t;
  update_texture(h, image);
  return h;
}

void Renderer::update_texture(TextureHandle handle, const Image& image) {
  auto it = impl_->textures.find(handle);
  if (it == impl_->textures.end()) throw RenderError("unknown texture " + std::to_string(handle));
  gl_.BindTexture(GL_TEXTURE_2D, it->second);
  gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  gl_.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl_.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, image.width, image.height, 0, GL_RGBA,
                 GL_UNSIGNED_BYTE, image.rgba.data());
}

void Renderer::release_texture(TextureHandle handle) {
  auto it = impl_->textures.find(handle);
  if (it == impl_->textures.end()) return;
  gl_.DeleteTextures(1, &it->second);
  impl_->textures.erase(it);
}

// ---------------------------------------------------------------------------------------------
// Per-frame drawing
namespace {

/// Space kept between two labels' boxes: enough to tell the boxes apart (2 px is the width of a
/// glyph stroke at the editor's scale), little enough to keep a label next to its line.
constexpr float kLabelGapPx = 2;

void push_flat(std::vector<float>& v, const Vec3& p, const Rgba& c, float u = 0, float w = 0) {
  v.insert(v.end(), {p.x(), p.y(), p.z(), c.r, c.g, c.b, c.a, u, w});
}

void push_overlay(std::vector<float>& v, float x, float y, float u, float w, const Rgba& c) {
  v.insert(v.end(), {x, y, c.r, c.g, c.b, c.a, u, w});
}

void overlay_rect(std::vector<float>& v, float x0, float y0, float x1, float y1, const Rgba& c) {
  push_overlay(v, x0, y0, -1, -1, c);
  push_overlay(v, x1, y0, 1, -1, c);
  push_overlay(v, x1, y1, 1, 1, c);
  push_overlay(v, x0, y0, -1, -1, c);
  push_overlay(v, x1, y1, 1, 1, c);
  push_overlay(v, x0, y1, -1, 1, c);
}

void overlay_text(std::vector<float>& v, const std::string& text, float x, float y, float scale,
                  const Rgba& c) {
  std::vector<float> xy;
  text_triangles(text, x, y, scale, xy);
  for (size_t i = 0; i + 1 < xy.size(); i += 2) push_overlay(v, xy[i], xy[i + 1], 0, 0, c);
}

/// Projects a world point to viewport pixels (y down); false when behind the camera.
bool project(const Mat4& view_projection, const Vec3& p, int w, int h, float& x, float& y) {
  const Eigen::Vector4f c = view_projection * Eigen::Vector4f(p.x(), p.y(), p.z(), 1);
  if (c.w() <= 1e-6f) return false;
  x = (c.x() / c.w() + 1) * 0.5f * static_cast<float>(w);
  y = (1 - c.y() / c.w()) * 0.5f * static_cast<float>(h);
  return true;
}

struct OverlayBatch {
  int mode;
  size_t first, count;
};

/// Sets the uniforms that are the same for every mesh of a view.
void set_view_uniforms(const GlFunctions& gl, const MeshProgram& p, const Viewport& viewport,
                       const Mat4& vp_m, const Mat4& inverse_vp, const Vec3& light,
                       const Vec3& eye) {
  gl.UseProgram(p.id);
  gl.UniformMatrix4fv(p.view_projection, 1, GL_FALSE, vp_m.data());
  gl.UniformMatrix4fv(p.inverse_view_projection, 1, GL_FALSE, inverse_vp.data());
  const float v[4] = {static_cast<float>(viewport.x), static_cast<float>(viewport.y),
                      static_cast<float>(viewport.width), static_cast<float>(viewport.height)};
  gl.Uniform4fv(p.viewport, 1, v);
  gl.Uniform3fv(p.light, 1, light.data());
  gl.Uniform3fv(p.eye, 1, eye.data());
}

/// The coarsest level of `g` whose error stays under half a pixel at the mesh's nearest depth
/// in a view (`view_m`, `proj`, `height` pixels high), for model matrix `model`; 0 (the full
/// mesh) when the mesh reaches the eye's plane.
size_t pick_level(const GpuMesh& g, const Mat4& model, const Mat4& view_m, const Mat4& proj,
                  int height) {
  if (g.levels.size() < 2 || g.box.isEmpty() || height <= 0) return 0;
  const Mat4 model_view = view_m * model;
  float w_min = std::numeric_limits<float>::infinity();  // clip w: the depth (1 when orthographic)
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner = g.box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(c));
    const float z = (model_view * corner.homogeneous()).z();
    w_min = std::min(w_min, proj(3, 2) * z + proj(3, 3));
  }
  const float scale = model.block<3, 3>(0, 0).colwise().norm().maxCoeff();
  if (!(w_min > 0) || !(scale > 0) || proj(1, 1) == 0) return 0;
  const float pixel = 2 * w_min / (std::abs(proj(1, 1)) * static_cast<float>(height));
  const float allowed = 0.5f * pixel / scale;
  size_t level = 0;
  for (size_t i = 1; i < g.levels.size(); ++i) {
    if (g.levels[i].error <= allowed) level = i;
  }
  return level;
}

/// Draws level `level` of one mesh with mesh program `u`, which is in use (and, for `wire`,
/// the full mesh's edges on top). Returns the triangles submitted.
size_t draw_mesh(const GlFunctions& gl, const MeshProgram& u, bool cull_closed_meshes,
                 const GpuMesh& g, size_t level, const Mat4& model, const Rgba& colour, bool wire,
                 const Rgba& wire_colour) {
  gl.UniformMatrix4fv(u.model, 1, GL_FALSE, model.data());
  const Mat4 n = normal_matrix(model);
  gl.UniformMatrix4fv(u.normal, 1, GL_FALSE, n.data());
  const float c[4] = {colour.r, colour.g, colour.b, colour.a};
  gl.Uniform4fv(u.colour, 1, c);
  gl.Uniform1i(u.flat, 0);
  if (g.cull_back_faces && cull_closed_meshes) {
    // A mirroring model matrix (negative determinant) reverses the winding on screen.
    const bool mirrored = model.block<3, 3>(0, 0).determinant() < 0;
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_BACK);
    gl.FrontFace(mirrored != g.inward ? GL_CW : GL_CCW);
  } else {
    gl.Disable(GL_CULL_FACE);
  }
  gl.BindVertexArray(g.vao);
  if (wire) {
    gl.Enable(GL_POLYGON_OFFSET_FILL);
    gl.PolygonOffset(1.0f, 1.0f);
  }
  const GpuMesh::Level& l = g.levels.at(wire ? 0 : level);
  gl.DrawElements(
      GL_TRIANGLES, l.count, GL_UNSIGNED_INT,
      // NOLINTNEXTLINE(performance-no-int-to-ptr): GL takes the byte offset as a pointer
      reinterpret_cast<const void*>(static_cast<std::uintptr_t>(l.first * 4)));
  size_t triangles = static_cast<size_t>(l.count) / 3;
  if (wire) {
    gl.Disable(GL_POLYGON_OFFSET_FILL);
    gl.PolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    const float wc[4] = {wire_colour.r, wire_colour.g, wire_colour.b, wire_colour.a};
    gl.Uniform4fv(u.colour, 1, wc);
    gl.Uniform1i(u.flat, 1);
    gl.DrawElements(GL_TRIANGLES, g.index_count, GL_UNSIGNED_INT, nullptr);
    gl.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    triangles += static_cast<size_t>(g.index_count) / 3;
  }
  return triangles;
}

/// Appends the floor grid's lines (pairs of flat vertices).
void push_grid(std::vector<float>& v, const FloorGrid& g) {
  const int n = static_cast<int>(std::floor(g.extent / g.spacing + 1e-4f));
  for (int i = -n; i <= n; ++i) {
    const float t = static_cast<float>(i) * g.spacing;
    Rgba c = g.colour;
    c.a = (i % 10 == 0) ? 0.9f : 0.45f;
    if (i == 0) c = {0.35f, 0.35f, 0.4f, 1.0f};
    push_flat(v, Vec3(t, g.height, -g.extent), c);
    push_flat(v, Vec3(t, g.height, g.extent), c);
    push_flat(v, Vec3(-g.extent, g.height, t), c);
    push_flat(v, Vec3(g.extent, g.height, t), c);
  }
}

/// Appends two triangles (six flat vertices, white, with texture coordinates) per quad.
void push_quads(std::vector<float>& v, const std::vector<TexturedQuad>& quads) {
  for (const TexturedQuad& q : quads) {
    const Rgba white;
    const Vec3 p00 = q.centre - q.right - q.up, p10 = q.centre + q.right - q.up;
    const Vec3 p11 = q.centre + q.right + q.up, p01 = q.centre - q.right + q.up;
    push_flat(v, p00, white, 0, 1);
    push_flat(v, p10, white, 1, 1);
    push_flat(v, p11, white, 1, 0);
    push_flat(v, p00, white, 0, 1);
    push_flat(v, p11, white, 1, 0);
    push_flat(v, p01, white, 0, 0);
  }
}

/// Appends the on-top lines as screen-space quads 3 px wide.
void overlay_lines(std::vector<float>& ov, const std::vector<Line>& lines, const Mat4& vp_m, int w,
                   int h) {
  for (const Line& l : lines) {
    if (!l.on_top) continue;
    float ax, ay, bx, by;
    if (!project(vp_m, l.a, w, h, ax, ay) || !project(vp_m, l.b, w, h, bx, by)) continue;
    float dx = bx - ax, dy = by - ay;
    const float len = std::sqrt(dx * dx + dy * dy);
    if (len < 1e-3f) continue;
    const float half = 1.5f;
    const float nx = -dy / len * half, ny = dx / len * half;
    push_overlay(ov, ax + nx, ay + ny, 0, 0, l.colour);
    push_overlay(ov, bx + nx, by + ny, 0, 0, l.colour);
    push_overlay(ov, bx - nx, by - ny, 0, 0, l.colour);
    push_overlay(ov, ax + nx, ay + ny, 0, 0, l.colour);
    push_overlay(ov, bx - nx, by - ny, 0, 0, l.colour);
    push_overlay(ov, ax - nx, ay - ny, 0, 0, l.colour);
  }
}

/// Appends each point as a square with a 1 px white border.
void overlay_points(std::vector<float>& ov, const std::vector<Point>& points, const Mat4& vp_m,
                    int w, int h) {
  for (const Point& p : points) {
    float x, y;
    if (!project(vp_m, p.position, w, h, x, y)) continue;
    const float r = p.size_px / 2;
    overlay_rect(ov, x - r - 1, y - r - 1, x + r + 1, y + r + 1, Rgba{1, 1, 1, 1});
    overlay_rect(ov, x - r, y - r, x + r, y + r, p.colour);
  }
}

/// Appends the labels: boxes (text and background margin) on the screen; keep_clear labels that
/// would cover another label move down until they are clear of it.
void overlay_labels(std::vector<float>& ov, const std::vector<Label>& labels, const Mat4& vp_m,
                    int w, int h) {
  std::vector<const Label*> shown;
  std::vector<TextBox> boxes;
  for (const Label& l : labels) {
    float x = l.anchor.x(), y = l.anchor.y();
    if (!l.screen && !project(vp_m, l.anchor, w, h, x, y)) continue;
    const float tw = text_width(l.text, l.scale), th = text_height(l.text, l.scale);
    if (!l.screen) {  // centre world labels vertically on their anchor, a little to the right
      x += 6;
      y -= th / 2;
    }
    shown.push_back(&l);
    boxes.push_back({x - 3, y - 3, x + tw + 3, y + th + 1, !l.keep_clear});
  }
  separate_boxes(boxes, kLabelGapPx);
  for (size_t i = 0; i < shown.size(); ++i) {
    const Label& l = *shown[i];
    const TextBox& b = boxes[i];
    if (l.background) overlay_rect(ov, b.x0, b.y0, b.x1, b.y1, Rgba{1, 1, 1, 0.8f});
    overlay_text(ov, l.text, b.x0 + 3, b.y0 + 3, l.scale, l.colour);
  }
}

/// Appends the colour legend in the viewport's top right corner: title, bar, three values.
void overlay_legend(std::vector<float>& ov, const Legend& lg, int w, int h) {
  const float scale = 2.0f;
  const float bar_w = 22, bar_h = std::min(220.0f, static_cast<float>(h) * 0.4f);
  const float box_w = std::max(130.0f, text_width(lg.title, scale) + 16);
  const float x0 = static_cast<float>(w) - box_w, y0 = 16;
  overlay_rect(ov, x0 - 10, y0 - 8, static_cast<float>(w) - 6, y0 + bar_h + 34,
               Rgba{1, 1, 1, 0.85f});
  overlay_text(ov, lg.title, x0 - 4, y0, scale, Rgba{0, 0, 0, 1});
  const float by0 = y0 + 20;
  const int steps = 32;
  for (int i = 0; i < steps; ++i) {
    // top = max value
    const float t0 = 1 - static_cast<float>(i) / steps, t1 = 1 - static_cast<float>(i + 1) / steps;
    const Rgba c0 = colour_at(lg.colour_map, t0), c1 = colour_at(lg.colour_map, t1);
    const float ya = by0 + bar_h * static_cast<float>(i) / steps;
    const float yb = by0 + bar_h * static_cast<float>(i + 1) / steps;
    push_overlay(ov, x0, ya, 0, 0, c0);
    push_overlay(ov, x0 + bar_w, ya, 0, 0, c0);
    push_overlay(ov, x0 + bar_w, yb, 0, 0, c1);
    push_overlay(ov, x0, ya, 0, 0, c0);
    push_overlay(ov, x0 + bar_w, yb, 0, 0, c1);
    push_overlay(ov, x0, yb, 0, 0, c1);
  }
  for (int k = 0; k <= 2; ++k) {
    const float value = lg.max_value + (lg.min_value - lg.max_value) * static_cast<float>(k) / 2;
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", static_cast<double>(value));
    const float y = by0 + bar_h * static_cast<float>(k) / 2 - 6;
    overlay_text(ov, text, x0 + bar_w + 8, y, scale, Rgba{0, 0, 0, 1});
  }
}

}  // namespace

void Renderer::Impl::draw_meshes(const GlFunctions& gl, const Scene& scene,
                                 const Viewport& viewport, const Mat4& view_m, const Mat4& proj,
                                 const Vec3& eye) {
  const Mat4 vp_m = proj * view_m;
  // The inverse in double: the fragment shader maps window coordinates back to the world with it.
  const Mat4 inverse_vp = vp_m.cast<double>().inverse().cast<float>();
  const Vec3 light = scene.light_direction.normalized();
  set_view_uniforms(gl, mesh_coloured, viewport, vp_m, inverse_vp, light, eye);
  set_view_uniforms(gl, mesh_plain, viewport, vp_m, inverse_vp, light, eye);
  const MeshProgram* in_use = &mesh_plain;
  auto use = [&](const MeshProgram& p) -> const MeshProgram& {
    if (in_use != &p) gl.UseProgram(p.id);
    in_use = &p;
    return p;
  };
  for (const MeshInstance& m : scene.meshes) {
    auto it = meshes.find(m.mesh);
    if (it == meshes.end()) continue;
    GpuMesh& g = it->second;
    const MeshProgram& p = use(m.vertex_colours && g.has_colours ? mesh_coloured : mesh_plain);
    if (level_of_detail && !m.wireframe) build_levels(gl, g);  // once
    const size_t level =
        level_of_detail ? pick_level(g, m.model, view_m, proj, viewport.height) : 0;
    triangles_drawn += draw_mesh(gl, p, cull_closed_meshes, g, level, m.model, m.colour,
                                 m.wireframe, m.wireframe_colour);
  }
  const GpuMesh& cube_mesh = meshes.at(cube);
  const MeshProgram& plain = use(mesh_plain);
  for (const Box& b : scene.boxes) {
    Mat4 s = Mat4::Identity();
    s.diagonal().head<3>() = b.half_extents;
    draw_mesh(gl, plain, cull_closed_meshes, cube_mesh, 0, b.transform * s, b.colour, false,
              b.colour);
  }
  gl.Disable(GL_CULL_FACE);
  gl.FrontFace(GL_CCW);
}

void Renderer::Impl::draw_flat(const GlFunctions& gl, const Scene& scene, const Mat4& vp_m) {
  flat_vertices.clear();
  if (scene.grid.visible && scene.grid.spacing > 0) push_grid(flat_vertices, scene.grid);
  for (const Line& l : scene.lines) {
    if (l.on_top) continue;
    push_flat(flat_vertices, l.a, l.colour);
    push_flat(flat_vertices, l.b, l.colour);
  }
  const size_t line_vertices = flat_vertices.size() / 9;
  push_quads(flat_vertices, scene.quads);
  if (flat_vertices.empty()) return;
  gl.UseProgram(flat_program);
  gl.UniformMatrix4fv(gl.GetUniformLocation(flat_program, "u_view_projection"), 1, GL_FALSE,
                      vp_m.data());
  gl.Uniform1i(gl.GetUniformLocation(flat_program, "u_texture"), 0);
  const GLint u_tex = gl.GetUniformLocation(flat_program, "u_textured");
  gl.BindVertexArray(flat_vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, flat_vbo);
  gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(flat_vertices.size() * 4),
                flat_vertices.data(), GL_STREAM_DRAW);
  gl.Uniform1i(u_tex, 0);
  if (line_vertices > 0) gl.DrawArrays(GL_LINES, 0, static_cast<GLsizei>(line_vertices));
  gl.Uniform1i(u_tex, 1);
  gl.ActiveTexture(GL_TEXTURE0);
  size_t first = line_vertices;
  for (const TexturedQuad& q : scene.quads) {
    auto it = textures.find(q.texture);
    if (it != textures.end()) {
      gl.BindTexture(GL_TEXTURE_2D, it->second);
      gl.DrawArrays(GL_TRIANGLES, static_cast<GLint>(first), 6);
    }
    first += 6;
  }
}

void Renderer::Impl::draw_overlay(const GlFunctions& gl, const Scene& scene, const Mat4& vp_m,
                                  int w, int h) {
  std::vector<float>& ov = overlay_vertices;
  ov.clear();
  std::vector<OverlayBatch> batches;
  auto begin_batch = [&](int mode) { batches.push_back({mode, ov.size() / 8, 0}); };
  auto end_batch = [&]() { batches.back().count = ov.size() / 8 - batches.back().first; };
  begin_batch(0);
  overlay_lines(ov, scene.lines, vp_m, w, h);
  end_batch();
  begin_batch(1);
  overlay_points(ov, scene.points, vp_m, w, h);
  end_batch();
  begin_batch(0);
  overlay_labels(ov, scene.labels, vp_m, w, h);
  if (scene.legend.visible) overlay_legend(ov, scene.legend, w, h);
  end_batch();
  if (ov.empty()) return;
  gl.Disable(GL_DEPTH_TEST);
  gl.UseProgram(overlay_program);
  gl.Uniform2f(gl.GetUniformLocation(overlay_program, "u_viewport_size"), static_cast<float>(w),
               static_cast<float>(h));
  const GLint u_mode = gl.GetUniformLocation(overlay_program, "u_mode");
  gl.BindVertexArray(overlay_vao);
  gl.BindBuffer(GL_ARRAY_BUFFER, overlay_vbo);
  gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(ov.size() * 4), ov.data(), GL_STREAM_DRAW);
  for (const OverlayBatch& b : batches) {
    if (b.count == 0) continue;
    gl.Uniform1i(u_mode, b.mode);
    gl.DrawArrays(GL_TRIANGLES, static_cast<GLint>(b.first), static_cast<GLsizei>(b.count));
  }
  gl.Enable(GL_DEPTH_TEST);
}

void Renderer::draw(const Scene& scene, const std::vector<View>& views) {
  size_t total = 0;
  for (const View& v : views) {
    draw(scene, v);
    total += impl_->triangles_drawn;
  }
  impl_->triangles_drawn = total;
}

void Renderer::draw(const Scene& scene, const View& view) {
  const GlFunctions& gl = gl_;
  const Viewport& vp = view.viewport;
  impl_->triangles_drawn = 0;
  if (vp.width <= 0 || vp.height <= 0) return;
  gl.Viewport(vp.x, vp.y, vp.width, vp.height);
  gl.Enable(GL_SCISSOR_TEST);
  gl.Scissor(vp.x, vp.y, vp.width, vp.height);
  if (view.clear) {
    gl.ClearColor(scene.background.r, scene.background.g, scene.background.b, scene.background.a);
    gl.ClearDepth(1.0);
    gl.DepthMask(GL_TRUE);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }
  const float aspect = static_cast<float>(vp.width) / static_cast<float>(vp.height);
  const Mat4 view_m = view_matrix(view.camera);
  const Mat4 proj = projection_matrix(view.camera, aspect);
  const Mat4 vp_m = proj * view_m;
  const Vec3 eye = view_m.block<3, 3>(0, 0).transpose() * (-view_m.block<3, 1>(0, 3));

  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_LEQUAL);
  gl.Disable(GL_CULL_FACE);
  gl.Enable(GL_BLEND);
  gl.BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);

  impl_->draw_meshes(gl, scene, vp, view_m, proj, eye);  // lit, depth-tested meshes and boxes
  impl_->draw_flat(gl, scene, vp_m);  // floor grid, depth-tested lines, textured quads
  impl_->draw_overlay(gl, scene, vp_m, vp.width, vp.height);  // screen space, on top
  gl.BindVertexArray(0);
  gl.UseProgram(0);
  gl.Disable(GL_SCISSOR_TEST);
}

}  // namespace caliper::render
