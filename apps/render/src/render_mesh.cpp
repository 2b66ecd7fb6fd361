#include "render/render_mesh.hpp"

#include <cstdio>

#include "render/camera.hpp"

namespace caliper::render {

MeshData mesh_data(const smpl::Vertices& vertices, const smpl::Faces& faces) {
  MeshData m;
  m.positions.resize(static_cast<size_t>(vertices.size()));
  for (Eigen::Index i = 0; i < vertices.size(); ++i) {
    m.positions[static_cast<size_t>(i)] = static_cast<float>(vertices.data()[i]);
  }
  m.indices.resize(static_cast<size_t>(faces.size()));
  for (Eigen::Index i = 0; i < faces.size(); ++i) {
    if (faces.data()[i] < 0) {
      throw RenderError("mesh faces: negative vertex index " + std::to_string(faces.data()[i]));
    }
    m.indices[static_cast<size_t>(i)] = static_cast<std::uint32_t>(faces.data()[i]);
  }
  return m;
}

OffscreenRenderer::OffscreenRenderer(int width, int height, int samples)
    : width_(width), height_(height), samples_(samples < 1 ? 1 : samples) {
  context_ = make_osmesa_context(width, height);
  renderer_ = std::make_unique<Renderer>(context_->gl());
  const GlFunctions& gl = context_->gl();
  if (samples_ > 1) {
    gl.GenFramebuffers(1, &fbo_);
    gl.GenRenderbuffers(1, &colour_rb_);
    gl.GenRenderbuffers(1, &depth_rb_);
    gl.BindRenderbuffer(GL_RENDERBUFFER, colour_rb_);
    gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_RGBA8, width, height);
    gl.BindRenderbuffer(GL_RENDERBUFFER, depth_rb_);
    gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_DEPTH24_STENCIL8, width,
                                      height);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_rb_);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER,
                               depth_rb_);
    if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw RenderError("multisampled framebuffer with " + std::to_string(samples_) +
                        " samples is incomplete: use samples = 1");
    }
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  gl.check("OffscreenRenderer setup");
}

OffscreenRenderer::~OffscreenRenderer() {
  context_->make_current();
  const GlFunctions& gl = context_->gl();
  renderer_.reset();
  if (fbo_ != 0) {
    gl.DeleteFramebuffers(1, &fbo_);
    gl.DeleteRenderbuffers(1, &colour_rb_);
    gl.DeleteRenderbuffers(1, &depth_rb_);
  }
}

void OffscreenRenderer::bind() {
  context_->make_current();
  context_->gl().BindFramebuffer(GL_FRAMEBUFFER, fbo_);
}

void OffscreenRenderer::resolve() {
  const GlFunctions& gl = context_->gl();
  if (fbo_ != 0) {
    gl.BindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    gl.BlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT,
                       GL_NEAREST);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  }
  gl.Finish();
}

Image OffscreenRenderer::render(const Scene& scene, const std::vector<View>& views) {
  bind();
  for (View v : views) {
    if (v.viewport.width == 0 || v.viewport.height == 0) v.viewport = {0, 0, width_, height_};
    renderer_->draw(scene, v);
  }
  resolve();
  context_->gl().check("OffscreenRenderer::render");
  return context_->read_pixels();
}

Image OffscreenRenderer::render(const Scene& scene, const Camera& camera) {
  View v;
  v.camera = camera;
  return render(scene, std::vector<View>{v});
}

Camera mesh_camera(const smpl::Vertices& vertices, const RenderOptions& o) {
  if (vertices.rows() == 0) throw RenderError("render_mesh: the mesh has no vertices");
  const Eigen::Vector3d lo = vertices.colwise().minCoeff(), hi = vertices.colwise().maxCoeff();
  const float az =
      o.azimuth_degrees ? *o.azimuth_degrees : view_azimuth_degrees(parse_standard_view(o.view));
  const float aspect = static_cast<float>(o.width) / static_cast<float>(o.height);
  if (o.fill) {
    std::vector<Vec3> points(static_cast<size_t>(vertices.rows()));
    for (Eigen::Index i = 0; i < vertices.rows(); ++i)
      points[static_cast<size_t>(i)] = vertices.row(i).transpose().cast<float>();
    return frame_points_tight(points, az, aspect, o.elevation_degrees);
  }
  return frame_box(lo.cast<float>(), hi.cast<float>(), az, aspect, o.elevation_degrees);
}

Scene mesh_scene(const smpl::Vertices& vertices, MeshHandle mesh, const RenderOptions& o) {
  Scene s;
  s.background = o.background;
  MeshInstance inst;
  inst.mesh = mesh;
  inst.colour = o.colour;
  inst.vertex_colours = !o.vertex_colours.empty();
  inst.wireframe = o.wireframe;
  s.meshes.push_back(inst);
  s.grid.visible = o.floor_grid;
  if (vertices.rows() > 0) {
    s.grid.height = static_cast<float>(vertices.col(1).minCoeff());
    s.grid.extent = 1.5f;
  }
  s.legend = o.legend;
  s.lines = o.lines;
  s.points = o.points;
  s.labels = o.labels;
  return s;
}

Image render_mesh_image(const smpl::Vertices& vertices, const smpl::Faces& faces,
                        const RenderOptions& o) {
  OffscreenRenderer r(o.width, o.height, o.samples);
  MeshData m = mesh_data(vertices, faces);
  m.colours = o.vertex_colours;
  const MeshHandle h = r.renderer().upload_mesh(m);
  return r.render(mesh_scene(vertices, h, o), mesh_camera(vertices, o));
}

void render_mesh_png(const smpl::Vertices& vertices, const smpl::Faces& faces,
                     const std::string& path, const RenderOptions& options) {
  write_png(render_mesh_image(vertices, faces, options), path);
}

std::vector<std::string> render_turntable_pngs(const smpl::Vertices& vertices,
                                               const smpl::Faces& faces, const std::string& prefix,
                                               int frames, const RenderOptions& options) {
  if (frames < 1) throw RenderError("turntable: frames must be at least 1");
  OffscreenRenderer r(options.width, options.height, options.samples);
  MeshData m = mesh_data(vertices, faces);
  m.colours = options.vertex_colours;
  const MeshHandle h = r.renderer().upload_mesh(m);
  const Scene scene = mesh_scene(vertices, h, options);
  std::vector<std::string> paths;
  for (int f = 0; f < frames; ++f) {
    RenderOptions o = options;
    o.fill = false;  // one distance for every frame
    o.azimuth_degrees = 360.0f * static_cast<float>(f) / static_cast<float>(frames);
    char suffix[32];
    std::snprintf(suffix, sizeof suffix, "_%03d.png", f);
    paths.push_back(prefix + suffix);
    write_png(r.render(scene, mesh_camera(vertices, o)), paths.back());
  }
  return paths;
}

}  // namespace caliper::render
