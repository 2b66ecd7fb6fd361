/// \file context.hpp
/// GL context providers behind one interface: an OSMesa off-screen buffer (no display needed,
/// Mesa llvmpipe) and a GLFW window (render/glfw_context.hpp, target caliper_render_window).
/// Both give an OpenGL 3.3 core profile context and the loaded GlFunctions table.
#pragma once

#include <memory>

#include "render/gl_functions.hpp"
#include "render/image.hpp"
#include "smpl/non_copyable.hpp"

namespace caliper::render {

/// One OpenGL 3.3 core context with a default framebuffer of width() x height() pixels.
class GlContext : smpl::NonCopyable {
 public:
  virtual ~GlContext() = default;

  /// Makes this context current on the calling thread.
  virtual void make_current() = 0;
  /// Default framebuffer size in pixels.
  virtual int width() const = 0;
  virtual int height() const = 0;
  /// Presents the frame (window) or finishes rendering (off-screen).
  virtual void swap_buffers() = 0;
  /// The loaded entry points of this context.
  const GlFunctions& gl() const { return gl_; }

  /// Reads the default framebuffer into an RGBA image, top row first.
  Image read_pixels();

 protected:
  GlFunctions gl_;
};

/// Off-screen OSMesa context (RGBA8 colour, 24-bit depth, 8-bit stencil), 3.3 core profile.
/// Throws RenderError when OSMesa cannot create such a context (message says why).
std::unique_ptr<GlContext> make_osmesa_context(int width, int height);

}  // namespace caliper::render
