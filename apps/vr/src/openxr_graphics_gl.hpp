/// \file openxr_graphics_gl.hpp
/// The OpenGL graphics plugin on Xlib (XR_KHR_opengl_enable): a GLFW/GLX context, which is
/// also the operator's desktop window when asked for, the shared GL 3.3 renderer, the
/// XrGraphicsBindingOpenGLXlibKHR of that context, and per eye a framebuffer with a depth
/// buffer onto which each acquired swapchain image is attached.
#pragma once

#include <memory>

#include "openxr_graphics.hpp"
#include "render/glfw_context.hpp"

namespace caliper::vr {

class OpenGlXlibGraphics : public XrGraphicsPlugin {
 public:
  /// Nothing is opened before initialize_device() (so that a missing runtime is reported
  /// before any window opens). `operator_window`: show the context's window.
  static std::unique_ptr<OpenGlXlibGraphics> create(bool operator_window);
  /// The context's window (valid after initialize_device()).
  virtual render::GlfwWindowContext& window() = 0;
};

/// The OpenGL projection (clip depth -1..1) of an OpenXR field of view: asymmetric, from the
/// tangents of its four angles, with the near and far planes in metres.
render::Mat4 gl_projection(const XrFovf& fov, float near_plane, float far_plane);

/// The swapchain format the GL plugin prefers: GL_SRGB8_ALPHA8 or GL_RGBA8, whichever the
/// runtime lists first; else the runtime's first format; 0 for an empty list.
int64_t gl_color_format(const std::vector<int64_t>& runtime_formats);

}  // namespace caliper::vr
