#include "render_bridge.hpp"

#include "cli_support.hpp"

#ifdef CALIPER_CLI_HAVE_RENDER
#include "render/render_mesh.hpp"
#endif

namespace caliper::cli {

#ifdef CALIPER_CLI_HAVE_RENDER

bool renderer_available() {
  return true;
}

void render_png(const smpl::Vertices& vertices, const smpl::Faces& faces, const std::string& path,
                const std::string& view, int width, int height) {
  render::RenderOptions o;
  o.view = view;
  o.fill = true;  // the body fills the picture's height (issue 17)
  o.width = width;
  o.height = height;
  render::render_mesh_png(vertices, faces, path, o);
}

std::vector<std::string> render_turntable(const smpl::Vertices& vertices, const smpl::Faces& faces,
                                          const std::string& prefix, int frames, int width,
                                          int height) {
  render::RenderOptions o;
  o.width = width;
  o.height = height;
  return render::render_turntable_pngs(vertices, faces, prefix, frames, o);
}

#else

bool renderer_available() {
  return false;
}

void render_png(const smpl::Vertices&, const smpl::Faces&, const std::string& path,
                const std::string&, int, int) {
  throw RuntimeError(path +
                     ": this caliper was built without the renderer (apps/render); "
                     "cannot write PNG pictures");
}

std::vector<std::string> render_turntable(const smpl::Vertices&, const smpl::Faces&,
                                          const std::string& prefix, int, int, int) {
  throw RuntimeError(prefix +
                     ": this caliper was built without the renderer (apps/render); "
                     "cannot write PNG pictures");
}

#endif

}  // namespace caliper::cli
