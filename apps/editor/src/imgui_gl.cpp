#include "imgui_gl.hpp"

#include <cstdint>
#include <string>

#include "render/shader_sources.hpp"

namespace caliper::editor {
namespace {

/// A byte offset into the bound buffer, as GL takes it (glVertexAttribPointer, glDrawElements).
const void* gl_offset(std::uintptr_t bytes) {
  return reinterpret_cast<const void*>(bytes);  // NOLINT(performance-no-int-to-ptr): GL's API
}

}  // namespace

ImGuiGl::ImGuiGl(const render::GlFunctions& gl) : gl_(gl) {
  // The renderer's flat program: a projection matrix, the colour times the texture.
  program_ = render::link_program(gl, render::shaders::kFlatVert, render::shaders::kFlatFrag,
                                  "imgui", render::shaders::kUnlitVertex);
  u_projection_ = gl.GetUniformLocation(program_, "u_view_projection");
  u_texture_ = gl.GetUniformLocation(program_, "u_texture");
  u_textured_ = gl.GetUniformLocation(program_, "u_textured");
  gl.GenVertexArrays(1, &vao_);
  gl.GenBuffers(1, &vbo_);
  gl.GenBuffers(1, &ebo_);
  gl.BindVertexArray(vao_);
  gl.BindBuffer(GL_ARRAY_BUFFER, vbo_);
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo_);
  const auto stride = static_cast<GLsizei>(sizeof(ImDrawVert));
  gl.EnableVertexAttribArray(0);
  gl.EnableVertexAttribArray(1);
  gl.EnableVertexAttribArray(2);
  // The layout of shaders/unlit_vertex.glsl: position, colour, texture coordinate.
  gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, stride, gl_offset(IM_OFFSETOF(ImDrawVert, pos)));
  gl.VertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, stride,
                         gl_offset(IM_OFFSETOF(ImDrawVert, col)));
  gl.VertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, stride, gl_offset(IM_OFFSETOF(ImDrawVert, uv)));
  gl.BindVertexArray(0);

  ImGuiIO& io = ImGui::GetIO();
  io.BackendRendererName = "caliper_imgui_gl33";
  unsigned char* pixels = nullptr;
  int w = 0, h = 0;
  io.Fonts->GetTexDataAsRGBA32(&pixels, &w, &h);
  gl.GenTextures(1, &font_texture_);
  gl.BindTexture(GL_TEXTURE_2D, font_texture_);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, pixels);
  // NOLINTNEXTLINE(performance-no-int-to-ptr): ImGui carries the GL texture name as its pointer
  io.Fonts->SetTexID(reinterpret_cast<ImTextureID>(static_cast<std::uintptr_t>(font_texture_)));
  gl.check("ImGui renderer setup");
}

ImGuiGl::~ImGuiGl() {
  gl_.DeleteTextures(1, &font_texture_);
  gl_.DeleteBuffers(1, &vbo_);
  gl_.DeleteBuffers(1, &ebo_);
  gl_.DeleteVertexArrays(1, &vao_);
  gl_.DeleteProgram(program_);
}

void ImGuiGl::render(const ImDrawData* data) {
  const int fb_w = static_cast<int>(data->DisplaySize.x * data->FramebufferScale.x);
  const int fb_h = static_cast<int>(data->DisplaySize.y * data->FramebufferScale.y);
  if (fb_w <= 0 || fb_h <= 0) return;
  const render::GlFunctions& gl = gl_;
  gl.Enable(GL_BLEND);
  gl.BlendEquation(GL_FUNC_ADD);
  gl.BlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  gl.Disable(GL_CULL_FACE);
  gl.Disable(GL_DEPTH_TEST);
  gl.Enable(GL_SCISSOR_TEST);
  gl.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  gl.Viewport(0, 0, fb_w, fb_h);
  const float l = data->DisplayPos.x, r = data->DisplayPos.x + data->DisplaySize.x;
  const float t = data->DisplayPos.y, b = data->DisplayPos.y + data->DisplaySize.y;
  const float proj[16] = {
      2.0f / (r - l),    0, 0, 0, 0, 2.0f / (t - b), 0, 0, 0, 0, -1, 0, (r + l) / (l - r),
      (t + b) / (b - t), 0, 1};
  gl.UseProgram(program_);
  gl.Uniform1i(u_texture_, 0);
  gl.Uniform1i(u_textured_, 1);
  gl.UniformMatrix4fv(u_projection_, 1, GL_FALSE, proj);
  gl.BindVertexArray(vao_);
  gl.ActiveTexture(GL_TEXTURE0);
  const ImVec2 off = data->DisplayPos, scale = data->FramebufferScale;
  for (int n = 0; n < data->CmdListsCount; ++n) {
    const ImDrawList* list = data->CmdLists[n];
    gl.BindBuffer(GL_ARRAY_BUFFER, vbo_);
    gl.BufferData(
        GL_ARRAY_BUFFER,
        static_cast<GLsizeiptr>(list->VtxBuffer.Size) * static_cast<GLsizeiptr>(sizeof(ImDrawVert)),
        list->VtxBuffer.Data, GL_STREAM_DRAW);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo_);
    gl.BufferData(
        GL_ELEMENT_ARRAY_BUFFER,
        static_cast<GLsizeiptr>(list->IdxBuffer.Size) * static_cast<GLsizeiptr>(sizeof(ImDrawIdx)),
        list->IdxBuffer.Data, GL_STREAM_DRAW);
    for (int c = 0; c < list->CmdBuffer.Size; ++c) {
      const ImDrawCmd& cmd = list->CmdBuffer[c];
      if (cmd.UserCallback != nullptr) {
        cmd.UserCallback(list, &cmd);
        continue;
      }
      const float x0 = (cmd.ClipRect.x - off.x) * scale.x, y0 = (cmd.ClipRect.y - off.y) * scale.y;
      const float x1 = (cmd.ClipRect.z - off.x) * scale.x, y1 = (cmd.ClipRect.w - off.y) * scale.y;
      if (x1 <= x0 || y1 <= y0) continue;
      gl.Scissor(static_cast<GLint>(x0), static_cast<GLint>(static_cast<float>(fb_h) - y1),
                 static_cast<GLsizei>(x1 - x0), static_cast<GLsizei>(y1 - y0));
      gl.BindTexture(GL_TEXTURE_2D,
                     static_cast<GLuint>(reinterpret_cast<std::uintptr_t>(cmd.GetTexID())));
      gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(cmd.ElemCount),
                      sizeof(ImDrawIdx) == 2 ? GL_UNSIGNED_SHORT : GL_UNSIGNED_INT,
                      gl_offset(cmd.IdxOffset * sizeof(ImDrawIdx)));
    }
  }
  gl.Disable(GL_SCISSOR_TEST);
  gl.BindVertexArray(0);
  gl.UseProgram(0);
}

}  // namespace caliper::editor
