// GLFW window context provider, OpenGL 3.3 core profile.
#include "render/glfw_context.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace caliper::render {

namespace {
GlProc glfw_loader(const char* name, void*) {
  return reinterpret_cast<GlProc>(glfwGetProcAddress(name));
}
}  // namespace

GlfwWindowContext::GlfwWindowContext(int width, int height, const std::string& title,
                                     bool visible) {
  if (!glfwInit()) {
    throw RenderError(
        "GLFW could not start: no display found (set DISPLAY, or run under xvfb-run, or use "
        "--headless)");
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 4);
  glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (window_ == nullptr) {
    glfwTerminate();
    throw RenderError("GLFW could not create a " + std::to_string(width) + " x " +
                      std::to_string(height) +
                      " window with an OpenGL 3.3 core context (is Mesa's GLX installed?)");
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(1);
  try {
    gl_.load(glfw_loader, nullptr);
  } catch (...) {
    glfwDestroyWindow(window_);
    glfwTerminate();
    throw;
  }
}

GlfwWindowContext::~GlfwWindowContext() {
  glfwDestroyWindow(window_);
  glfwTerminate();
}

void GlfwWindowContext::make_current() {
  glfwMakeContextCurrent(window_);
}

int GlfwWindowContext::width() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return w;
}

int GlfwWindowContext::height() const {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  return h;
}

void GlfwWindowContext::swap_buffers() {
  glfwSwapBuffers(window_);
}

bool GlfwWindowContext::should_close() const {
  return glfwWindowShouldClose(window_) != 0;
}

void GlfwWindowContext::window_size(int& width, int& height) const {
  glfwGetWindowSize(window_, &width, &height);
}

}  // namespace caliper::render
