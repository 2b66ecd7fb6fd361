/// \file editor_app.hpp
/// One editor frame: the ImGui panels (they read the EditorCore and emit commands), the scene
/// snapshot of the avatar (overlay, colour maps, comparison) and the drawing of both into the
/// bound framebuffer. Platform-free: the GLFW main loop and the headless OSMesa loop both call
/// frame().
#pragma once

#include <memory>
#include <string>

#include "app/editor_core.hpp"
#include "imgui_gl.hpp"
#include "render/renderer.hpp"

namespace caliper::editor {

/// Orbit camera of the 3D view.
struct OrbitCamera {
  float azimuth_degrees = 25.0f;
  float elevation_degrees = 8.0f;
  float zoom = 1.0f;  ///< 1 frames the body; > 1 closer
};

class EditorApp {
 public:
  /// Precondition: the GL context of `gl` is current and ImGui::CreateContext() was called.
  EditorApp(app::EditorCore& core, const render::GlFunctions& gl);
  ~EditorApp();

  /// Builds the UI for a framebuffer of fb_width x fb_height pixels (io.DisplaySize must be set
  /// by the caller, and io.DeltaTime), draws the 3D view and the UI into the bound framebuffer.
  void frame(int fb_width, int fb_height);

  /// Editor commands that are not app-core commands: "view front|side|three_quarter|back",
  /// "azimuth DEG", "zoom F", "screenshot FILE" (requested; the caller writes it), "panel on|off".
  /// Everything else goes to EditorCore::run_command(). Returns success.
  bool run_command(const std::string& line);

  /// A screenshot path requested by the UI or a script ("" when none); cleared by the caller.
  std::string& screenshot_request() { return screenshot_request_; }
  OrbitCamera& camera() { return camera_; }
  /// Framebuffer rectangle of the 3D view (bottom-left origin), valid after frame().
  render::Viewport scene_viewport() const { return scene_viewport_; }
  /// Drag the avatar view with the mouse (windowed mode): pixels moved.
  void orbit(float dx, float dy);

 private:
  void draw_panel();
  void draw_measurements();
  void draw_betas();
  void draw_files();
  void draw_messages();
  void handle_shortcuts();
  void sync_meshes();
  render::Scene build_scene(bool comparison_side) const;
  float difference_range() const;  ///< metres: colour-map maximum of the difference map

  app::EditorCore& core_;
  const render::GlFunctions& gl_;
  std::unique_ptr<render::Renderer> renderer_;
  std::unique_ptr<ImGuiGl> imgui_;
  render::MeshHandle avatar_mesh_ = 0, pinned_mesh_ = 0;
  std::uint64_t uploaded_revision_ = ~0ull;
  int uploaded_model_ = -2;
  int uploaded_colour_mode_ = -1;
  int uploaded_compare_ = -1;
  const void* uploaded_pinned_ = nullptr;
  std::size_t uploaded_pinned_rows_ = 0;
  OrbitCamera camera_;
  render::Viewport scene_viewport_;
  std::string screenshot_request_;
  bool show_panel_ = true;
  float panel_width_ = 440.0f;
  char path_buffer_[512] = "profile.json";
  char model_path_buffer_[512] = "";
};

}  // namespace caliper::editor
