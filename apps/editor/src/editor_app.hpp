/// \file editor_app.hpp
/// One editor frame: the ImGui panels (they read the EditorCore and emit commands), the file
/// dialogs, the unsaved-work question, the scene snapshot of the avatar (overlay, colour maps,
/// comparison) and the drawing of both into the bound framebuffer. Platform-free: the GLFW main
/// loop and the headless OSMesa loop (and the UI tests) all call frame().
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "app/editor_core.hpp"
#include "file_dialog.hpp"
#include "imgui_gl.hpp"
#include "render/renderer.hpp"
#include "ui_probe.hpp"

namespace caliper::editor {

/// Orbit camera of the 3D view.
struct OrbitCamera {
  float azimuth_degrees = 25.0f;
  float elevation_degrees = 8.0f;
  float zoom = 1.0f;  ///< 1 frames the body; > 1 closer
};

/// Fills io.KeyMap with GLFW key codes, as Dear ImGui 1.86's GLFW backend does, for the
/// headless loop and the UI tests (which feed io.KeysDown themselves).
void set_glfw_key_map(ImGuiIO& io);

class EditorApp {
 public:
  /// Precondition: the GL context of `gl` is current and ImGui::CreateContext() was called.
  EditorApp(app::EditorCore& core, const render::GlFunctions& gl);
  ~EditorApp();

  /// Builds the UI for a framebuffer of fb_width x fb_height pixels (io.DisplaySize must be set
  /// by the caller, and io.DeltaTime), draws the 3D view and the UI into the bound framebuffer.
  void frame(int fb_width, int fb_height);

  /// Editor commands that are not app-core commands: "view front|side|three_quarter|back",
  /// "azimuth DEG", "zoom F", "screenshot FILE" (requested; the caller writes it),
  /// "panel on|off", "panel-width PX", "scale fixed|fit". Everything else goes to
  /// EditorCore::run_command(). Returns success.
  bool run_command(const std::string& line);

  /// A screenshot path requested by the UI or a script ("" when none); cleared by the caller.
  std::string& screenshot_request() { return screenshot_request_; }
  OrbitCamera& camera() { return camera_; }
  /// Framebuffer rectangle of the 3D view (bottom-left origin), valid after frame().
  render::Viewport scene_viewport() const { return scene_viewport_; }
  /// Drag the avatar view with the mouse (windowed mode): pixels moved.
  void orbit(float dx, float dy);

  /// Quit (Esc, Ctrl+Q, the window's close button): asks first when there is unsaved work.
  void request_quit();
  /// True once the user confirmed quitting (or nothing was unsaved): the caller exits.
  bool quit_requested() const { return quit_; }
  /// True while something moves without input (a key held down): the loop keeps drawing.
  bool animating() const;
  /// The interactive items of the last frame (tests press them through ImGui's input).
  const std::vector<UiItem>& ui_items() const { return probe_.items(); }
  /// The renderer of the last frame (tests read what it drew: triangles_drawn()).
  const render::Renderer& renderer() const { return *renderer_; }
  /// The file dialog (tests read its state).
  const FileDialog& file_dialog() const { return dialog_; }
  /// True while the unsaved-work question is shown.
  bool asking_about_unsaved_work() const { return pending_ != Pending::None; }
  float panel_width() const { return panel_width_; }

 private:
  enum class Pending { None, Quit, OpenProfile, OpenSession };
  void draw_panel();
  void draw_model_section();
  void draw_regressor_section();
  void draw_measurements();
  /// The arm length row's "taken hanging" checkbox, `indent` pixels in (under the slider),
  /// with a tooltip saying what it means, or why the model cannot take the arm hanging.
  void draw_arm_hanging_toggle(float indent);
  void draw_achieved_table();
  void draw_betas();
  void draw_display_section();
  void draw_files();
  void draw_messages();
  void draw_dialogs();
  void handle_shortcuts();
  /// Opens the dialog of `action`; opening a profile or session asks first when work is
  /// unsaved.
  void start_file_action(FileAction action);
  /// Opens the file dialog of `action` in the last folder a file was chosen in.
  void open_dialog(FileAction action);
  void finish_file_action(FileAction action, const std::string& path);
  void continue_pending();
  bool button(const char* label, bool enabled = true);
  void sync_meshes();
  render::Scene build_scene(bool comparison_side, const render::View& view) const;
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
  std::string deferred_screenshot_;
  bool show_panel_ = true;
  float panel_width_ = 460.0f;
  float status_height_ = 0;
  UiProbe probe_;
  FileDialog dialog_;
  std::filesystem::path last_folder_;
  Pending pending_ = Pending::None;
  bool pending_popup_open_ = false;
  bool save_then_continue_ = false;
  bool quit_ = false;
  /// Typed-value fields: their text while being edited (applied on Enter, Tab or focus loss).
  std::map<std::string, std::array<char, 48>> typed_text_;
  std::string active_field_;
};

}  // namespace caliper::editor
