/// \file glfw_context.hpp
/// The GLFW window context provider (target caliper_render_window): an OpenGL 3.3 core
/// context in a window (GLX on Linux; under Xvfb Mesa's llvmpipe serves it).
#pragma once

#include <memory>
#include <string>

#include "render/context.hpp"

struct GLFWwindow;

namespace caliper::render {

/// A GLFW window with an OpenGL 3.3 core context. Owns GLFW's initialisation (glfwInit in the
/// constructor, glfwTerminate in the destructor): create one per process.
class GlfwWindowContext final : public GlContext {
 public:
  /// Throws RenderError when GLFW cannot start (no display) or the context cannot be created.
  GlfwWindowContext(int width, int height, const std::string& title, bool visible = true);
  ~GlfwWindowContext() override;

  void make_current() override;
  int width() const override;   ///< framebuffer pixels
  int height() const override;  ///< framebuffer pixels
  void swap_buffers() override;

  GLFWwindow* window() const { return window_; }
  bool should_close() const;
  /// Window size in screen coordinates (to remember it between runs).
  void window_size(int& width, int& height) const;

 private:
  GLFWwindow* window_ = nullptr;
};

}  // namespace caliper::render
