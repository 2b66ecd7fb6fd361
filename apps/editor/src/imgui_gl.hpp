/// \file imgui_gl.hpp
/// Draws Dear ImGui's draw lists with the project's GL loader (GL 3.3 core). Debian's libimgui
/// contains imgui_impl_opengl3, but its built-in loader (imgl3w) opens libGL.so.1 and looks
/// entry points up through GLX, which does not reach an OSMesa context; this small renderer
/// works with both context providers.
#pragma once

#include <imgui.h>

#include "render/gl_functions.hpp"

namespace caliper::editor {

class ImGuiGl {
 public:
  /// Creates the shader, buffers and font texture of the current ImGui context.
  /// Precondition: the GL context of `gl` is current; ImGui::CreateContext() was called.
  explicit ImGuiGl(const render::GlFunctions& gl);
  ~ImGuiGl();
  ImGuiGl(const ImGuiGl&) = delete;
  ImGuiGl& operator=(const ImGuiGl&) = delete;

  /// Draws `data` into the bound framebuffer (framebuffer size = DisplaySize *
  /// FramebufferScale).
  void render(const ImDrawData* data);

 private:
  const render::GlFunctions& gl_;
  GLuint program_ = 0, vao_ = 0, vbo_ = 0, ebo_ = 0, font_texture_ = 0;
  GLint u_projection_ = -1, u_texture_ = -1, u_textured_ = -1;
};

}  // namespace caliper::editor
