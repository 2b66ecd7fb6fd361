/// \file renderer.hpp
/// The OpenGL 3.3 core renderer: draws a const Scene for one or more Views into the currently
/// bound framebuffer of the current context. Meshes and textures are uploaded once and then
/// referred to by handle; update_mesh() re-uploads changed vertices (a slider drag).
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "render/gl_functions.hpp"
#include "render/image.hpp"
#include "render/scene.hpp"

namespace caliper::render {

/// GL objects of one uploaded mesh.
struct GpuMesh;

class Renderer {
 public:
  /// Compiles the embedded shaders. The context whose functions `gl` holds must be current
  /// whenever a Renderer method is called; `gl` must outlive the Renderer. Throws RenderError.
  explicit Renderer(const GlFunctions& gl);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Uploads a mesh (normals computed when MeshData::normals is empty). Throws RenderError when
  /// the sizes disagree (positions not 3V, an index out of range, colours not 3V or empty).
  MeshHandle upload_mesh(const MeshData& mesh);
  /// Replaces the data of `handle` (same or different sizes). Throws RenderError on a bad handle.
  void update_mesh(MeshHandle handle, const MeshData& mesh);
  /// Replaces only positions (3V floats, same V) and recomputes normals: the per-frame path.
  void update_positions(MeshHandle handle, const std::vector<float>& positions);
  /// Replaces only per-vertex colours (3V floats, same V; empty clears them).
  void update_colours(MeshHandle handle, const std::vector<float>& colours);
  void release_mesh(MeshHandle handle);

  /// Uploads an RGBA texture (instruction panels, video frames); update replaces its pixels.
  TextureHandle upload_texture(const Image& image);
  void update_texture(TextureHandle handle, const Image& image);
  void release_texture(TextureHandle handle);

  /// Draws `scene` into each view's viewport (stereo: one view per eye).
  void draw(const Scene& scene, const View& view);
  void draw(const Scene& scene, const std::vector<View>& views);

  /// Closed, consistently wound meshes (every body model) are drawn with back faces culled,
  /// which leaves the picture unchanged and halves the triangles set up per frame; all other
  /// meshes are drawn two-sided. Off: everything two-sided (a baseline for benchmarks, or to
  /// inspect a mesh from inside).
  void set_cull_closed_meshes(bool on);
  bool cull_closed_meshes() const;

  /// Closed meshes of kLodMinTriangles triangles or more (every body model) can be drawn from
  /// simplified index buffers (meshoptimizer's meshopt_simplify over the mesh's own vertices),
  /// each with its geometric error, measured on the shape given to upload_mesh or update_mesh
  /// (update_positions keeps them); prepare_levels() or the first draw that wants them makes
  /// them (about 50 ms for an open model). With level of detail on, a view draws the coarsest
  /// level whose error is under half a pixel at the mesh's nearest depth: the silhouette stays
  /// within half a pixel while Mesa's software rasterizer sets up 40 % of a whole body's
  /// triangles, but small shading detail (the eyes, the lips) coarsens. Off (the default):
  /// always the full mesh. The editor turns it on only while a slider is dragged; wireframes
  /// always show the full mesh.
  static constexpr std::size_t kLodMinTriangles = 8192;
  void set_level_of_detail(bool on);
  bool level_of_detail() const;
  /// Makes the simplified levels of `handle` now (nothing when it gets none or has them), e.g.
  /// when a model is loaded rather than at the first drag. Throws RenderError on a bad handle.
  void prepare_levels(MeshHandle handle);
  /// Triangles the last draw() submitted for the scene's meshes (before back-face culling).
  std::size_t triangles_drawn() const;

  const GlFunctions& gl() const { return gl_; }

 private:
  struct Impl;
  const GlFunctions& gl_;
  std::unique_ptr<Impl> impl_;
};

/// Area-weighted unit vertex normals of a triangle mesh (3V floats); zero-area fans give (0,1,0).
std::vector<float> vertex_normals(const std::vector<float>& positions,
                                  const std::vector<std::uint32_t>& indices);

}  // namespace caliper::render
