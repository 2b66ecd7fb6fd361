/// \file render_bridge.hpp
/// The `caliper` command's use of the off-screen renderer (apps/render, OSMesa): one PNG of a
/// mesh from a named view, or turntable frames. When the command was built without the
/// renderer, these throw RuntimeError saying so.
#pragma once

#include <string>
#include <vector>

#include "smpl/body_model.hpp"

namespace caliper::cli {

/// True when the renderer was compiled in.
bool renderer_available();

/// Renders `vertices`/`faces` (rest pose, metres) to a PNG at `path` from `view` (front, side,
/// three_quarter, back) at width x height pixels. Throws RuntimeError/RenderError on failure.
void render_png(const smpl::Vertices& vertices, const smpl::Faces& faces, const std::string& path,
                const std::string& view, int width, int height);

/// `frames` turntable pictures `<prefix>_000.png`, ...; returns the paths written.
std::vector<std::string> render_turntable(const smpl::Vertices& vertices, const smpl::Faces& faces,
                                          const std::string& prefix, int frames, int width,
                                          int height);

}  // namespace caliper::cli
