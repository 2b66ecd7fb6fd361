/// \file render_mesh.hpp
/// One-call off-screen pictures of a mesh (front, side, three-quarter, back, turntable frames)
/// for the command line (`caliper render`, `caliper create --png`), the model generator's
/// figures and the docs. Uses an OSMesa context: no display is needed.
///
/// Example:
///   caliper::render::RenderOptions o;  o.view = "three_quarter";  o.width = 600;
///   caliper::render::render_mesh_png(body.vertices, model.faces, "out.png", o);
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "render/context.hpp"
#include "render/renderer.hpp"
#include "render/scene.hpp"
#include "smpl/body_model.hpp"

namespace caliper::render {

/// What render_mesh_image() draws.
struct RenderOptions {
  int width = 600;                         ///< pixels
  int height = 800;                        ///< pixels
  std::string view = "front";              ///< front | side | three_quarter | back
  std::optional<float> azimuth_degrees;    ///< overrides `view` (0 front, 90 subject's left side)
  float elevation_degrees = 8.0f;          ///< camera height angle above the body's centre
  Rgba colour{0.80f, 0.68f, 0.58f, 1.0f};  ///< skin colour when no vertex colours are given
  Rgba background{0.96f, 0.96f, 0.97f, 1.0f};
  bool floor_grid = true;             ///< grid at the mesh's lowest point
  bool wireframe = false;             ///< overlay triangle edges
  std::vector<float> vertex_colours;  ///< 3V RGB in [0, 1] (colour_map.hpp), or empty
  Legend legend;                      ///< colour legend (for vertex colour maps)
  std::vector<Line> lines;            ///< measurement lines (world space, metres)
  std::vector<Point> points;          ///< landmarks
  std::vector<Label> labels;          ///< values next to lines, captions
  int samples = 4;                    ///< multisampling (1 = off)
  /// Frame the mesh tightly for this view (frame_points_tight on its vertices: the body fills the
  /// picture's height) instead of its bounding sphere (frame_box: the same distance from every
  /// side, as a turntable needs). render_turntable_pngs ignores it.
  bool fill = false;
};

/// Float positions and 32-bit indices of an smpl mesh, ready for Renderer::upload_mesh().
MeshData mesh_data(const smpl::Vertices& vertices, const smpl::Faces& faces);

/// A reusable off-screen renderer: one OSMesa context of a fixed size with a Renderer and a
/// multisampled framebuffer. Create one and call render() many times (turntables, batches).
class OffscreenRenderer {
 public:
  /// Throws RenderError when no OSMesa 3.3 core context can be created.
  OffscreenRenderer(int width, int height, int samples = 4);
  ~OffscreenRenderer();
  OffscreenRenderer(const OffscreenRenderer&) = delete;
  OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

  /// Draws `scene` for `views` (viewport 0 = the whole image when its size is 0) and reads
  /// the image back (top row first).
  Image render(const Scene& scene, const std::vector<View>& views);
  Image render(const Scene& scene, const Camera& camera);

  Renderer& renderer() { return *renderer_; }
  GlContext& context() { return *context_; }
  int width() const { return width_; }
  int height() const { return height_; }

  /// Binds the multisampled framebuffer (draw to it with your own GL calls, e.g. ImGui) and
  /// resolve() copies it to the context's buffer; render() does both itself.
  void bind();
  void resolve();

 private:
  int width_, height_, samples_;
  std::unique_ptr<GlContext> context_;
  std::unique_ptr<Renderer> renderer_;
  unsigned fbo_ = 0, colour_rb_ = 0, depth_rb_ = 0;
};

/// The scene and camera render_mesh_image() uses (handy to add more to it).
/// `mesh` is the handle of the uploaded mesh.
Scene mesh_scene(const smpl::Vertices& vertices, MeshHandle mesh, const RenderOptions& options);
Camera mesh_camera(const smpl::Vertices& vertices, const RenderOptions& options);

/// Renders one picture of the mesh. Throws RenderError (no context, bad sizes) or
/// std::invalid_argument (unknown view name).
Image render_mesh_image(const smpl::Vertices& vertices, const smpl::Faces& faces,
                        const RenderOptions& options = {});
/// Same, written to `path` as PNG.
void render_mesh_png(const smpl::Vertices& vertices, const smpl::Faces& faces,
                     const std::string& path, const RenderOptions& options = {});
/// `frames` pictures at azimuths 0, 360/frames, ... written to `<prefix>_000.png`, ...
/// Returns the paths written.
std::vector<std::string> render_turntable_pngs(const smpl::Vertices& vertices,
                                               const smpl::Faces& faces, const std::string& prefix,
                                               int frames, const RenderOptions& options = {});

}  // namespace caliper::render
