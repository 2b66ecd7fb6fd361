// One editor frame. Sections: construction, commands, mesh upload, scene (avatar, measurement
// overlay, colour maps, comparison), panels (model, units, regressor and hierarchy,
// measurements, betas and plausibility, display, files, messages), keyboard shortcuts.
#include "editor_app.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "render/camera.hpp"
#include "render/colour_map.hpp"

namespace caliper::editor {

namespace {

/// ImGui's Begin/EndDisabled must pair even when the widget inside changes the condition (an
/// Undo click that empties the history): the condition is read once, when the scope opens.
class DisabledScope {
 public:
  explicit DisabledScope(bool disabled) : disabled_(disabled) {
    if (disabled_) ImGui::BeginDisabled();
  }
  ~DisabledScope() {
    if (disabled_) ImGui::EndDisabled();
  }
  DisabledScope(const DisabledScope&) = delete;
  DisabledScope& operator=(const DisabledScope&) = delete;

 private:
  bool disabled_;
};
std::vector<float> to_floats(const smpl::Vertices& v) {
  std::vector<float> out(static_cast<size_t>(v.size()));
  for (Eigen::Index i = 0; i < v.size(); ++i)
    out[static_cast<size_t>(i)] = static_cast<float>(v.data()[i]);
  return out;
}

/// Colour-map range of each mode, metres.
constexpr float kPlausibilityRange = 0.02f;   // 2 cm of displacement from components beyond 2 SD
constexpr float kUncertaintyRange = 0.02f;    // 2 cm positional SD
constexpr float kMinDifferenceRange = 0.01f;  // 1 cm: below that the map would show noise
}  // namespace

float EditorApp::difference_range() const {
  // The largest difference rounded up to whole centimetres (at least 1 cm).
  float m = 0;
  if (core_.comparison()) {
    for (float d : core_.comparison()->difference) m = std::max(m, d);
  }
  return std::max(kMinDifferenceRange, std::ceil(m * 100.0f) / 100.0f);
}

// ---------------------------------------------------------------------------------------------
// Construction and commands
EditorApp::EditorApp(app::EditorCore& core, const render::GlFunctions& gl) : core_(core), gl_(gl) {
  renderer_ = std::make_unique<render::Renderer>(gl);
  imgui_ = std::make_unique<ImGuiGl>(gl);
  ImGui::StyleColorsLight();
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 0;
  style.FrameRounding = 3;
  style.ItemSpacing.y = 5;
}

EditorApp::~EditorApp() = default;

bool EditorApp::run_command(const std::string& line) {
  std::istringstream in(line);
  std::string cmd, a;
  in >> cmd;
  if (cmd == "view") {
    in >> a;
    try {
      camera_.azimuth_degrees = render::view_azimuth_degrees(render::parse_standard_view(a));
    } catch (const std::exception& e) {
      core_.post(app::Message::Level::Error, e.what());
      return false;
    }
    return true;
  }
  if (cmd == "azimuth" || cmd == "zoom" || cmd == "elevation") {
    float v = 0;
    if (!(in >> v)) {
      core_.post(app::Message::Level::Error, "command '" + line + "': expected a number");
      return false;
    }
    if (cmd == "azimuth") camera_.azimuth_degrees = v;
    if (cmd == "elevation") camera_.elevation_degrees = std::clamp(v, -80.0f, 80.0f);
    if (cmd == "zoom") camera_.zoom = std::clamp(v, 0.2f, 10.0f);
    return true;
  }
  if (cmd == "screenshot") {
    in >> a;
    screenshot_request_ = a.empty() ? "screenshot.png" : a;
    return true;
  }
  if (cmd == "panel") {
    in >> a;
    show_panel_ = a != "off";
    return true;
  }
  return core_.run_command(line);
}

void EditorApp::orbit(float dx, float dy) {
  camera_.azimuth_degrees -= dx * 0.4f;
  camera_.elevation_degrees = std::clamp(camera_.elevation_degrees + dy * 0.3f, -80.0f, 80.0f);
}

// ---------------------------------------------------------------------------------------------
// Mesh upload
void EditorApp::sync_meshes() {
  if (!core_.has_model()) return;
  const app::AvatarView& av = core_.avatar();
  const smpl::BodyModel& model = *core_.model().model;
  const int mode = static_cast<int>(core_.view().colour);
  const int compare = static_cast<int>(core_.view().compare);
  const bool model_changed = uploaded_model_ != core_.current_model();
  if (model_changed || avatar_mesh_ == 0) {
    render::MeshData m;
    m.positions = to_floats(av.vertices);
    m.indices.assign(model.faces.data(), model.faces.data() + model.faces.size());
    if (avatar_mesh_ == 0) {
      avatar_mesh_ = renderer_->upload_mesh(m);
    } else {
      renderer_->update_mesh(avatar_mesh_, m);
    }
    uploaded_model_ = core_.current_model();
    uploaded_revision_ = core_.revision();
    uploaded_colour_mode_ = -1;
  } else if (uploaded_revision_ != core_.revision()) {
    renderer_->update_positions(avatar_mesh_, to_floats(av.vertices));
    uploaded_revision_ = core_.revision();
    uploaded_colour_mode_ = -1;
  }
  if (uploaded_colour_mode_ != mode || uploaded_compare_ != compare) {
    const auto& cmp = core_.comparison();
    if (compare == static_cast<int>(app::CompareMode::Difference) && cmp &&
        !cmp->difference.empty()) {
      renderer_->update_colours(avatar_mesh_,
                                render::colours_from_values(cmp->difference, 0, difference_range(),
                                                            render::kColourMapHeat));
    } else if (core_.view().colour == app::ColourMode::Plausibility) {
      renderer_->update_colours(
          avatar_mesh_, render::colours_from_values(av.implausible_displacement, 0,
                                                    kPlausibilityRange, render::kColourMapTraffic));
    } else if (core_.view().colour == app::ColourMode::Uncertainty) {
      renderer_->update_colours(avatar_mesh_,
                                render::colours_from_values(av.uncertainty, 0, kUncertaintyRange,
                                                            render::kColourMapHeat));
    } else {
      renderer_->update_colours(avatar_mesh_, {});
    }
    uploaded_colour_mode_ = mode;
    uploaded_compare_ = compare;
  }
  const auto& cmp = core_.comparison();
  if (cmp && (uploaded_pinned_ != static_cast<const void*>(&*cmp) ||
              uploaded_pinned_rows_ != static_cast<size_t>(cmp->vertices.rows()) ||
              pinned_mesh_ == 0 || model_changed)) {
    render::MeshData m;
    m.positions = to_floats(cmp->vertices);
    if (cmp->vertices.rows() == model.v_template.rows()) {
      m.indices.assign(model.faces.data(), model.faces.data() + model.faces.size());
    }
    if (pinned_mesh_ == 0) {
      pinned_mesh_ = renderer_->upload_mesh(m);
    } else {
      renderer_->update_mesh(pinned_mesh_, m);
    }
    uploaded_pinned_ = &*cmp;
    uploaded_pinned_rows_ = static_cast<size_t>(cmp->vertices.rows());
  }
}

// ---------------------------------------------------------------------------------------------
// Scene
render::Scene EditorApp::build_scene(bool comparison_side) const {
  render::Scene s;
  s.grid.extent = 1.5f;
  if (!core_.has_model()) return s;
  const app::AvatarView& av = core_.avatar();
  const app::ViewSettings& vs = core_.view();
  render::MeshInstance inst;
  if (comparison_side) {
    inst.mesh = pinned_mesh_;
    inst.colour = {0.62f, 0.70f, 0.82f, 1};
    s.meshes.push_back(inst);
    render::Label l;
    l.text = core_.comparison() ? core_.comparison()->label : "";
    l.screen = true;
    l.anchor = {12, 12, 0};
    s.labels.push_back(l);
    return s;
  }
  inst.mesh = avatar_mesh_;
  inst.wireframe = vs.wireframe;
  inst.wireframe_colour = {0.25f, 0.2f, 0.2f, 0.35f};
  const bool difference = vs.compare == app::CompareMode::Difference && core_.comparison() &&
                          !core_.comparison()->difference.empty();
  inst.vertex_colours = difference || vs.colour != app::ColourMode::Skin;
  s.meshes.push_back(inst);
  if (difference) {
    s.legend = {true, "difference (cm)", 0, difference_range() * 100, render::kColourMapHeat};
  } else if (vs.colour == app::ColourMode::Plausibility) {
    s.legend = {true, "beyond 2 SD (cm)", 0, kPlausibilityRange * 100, render::kColourMapTraffic};
  } else if (vs.colour == app::ColourMode::Uncertainty) {
    s.legend = {true, "posterior SD (cm)", 0, kUncertaintyRange * 100, render::kColourMapHeat};
  }
  if (vs.compare == app::CompareMode::SideBySide) {
    render::Label l;
    l.text = "current";
    l.screen = true;
    l.anchor = {12, 12, 0};
    s.labels.push_back(l);
  }
  if (!vs.overlay) return s;
  // Measurement overlay: the inputs of the current regressor / level, with their values.
  const LandmarkTable& lm = core_.model().landmarks;
  auto point = [&](const std::string& name, Eigen::Vector3d& p) {
    auto it = lm.find(name);
    if (it == lm.end()) return false;
    try {
      p = landmark_point(av.vertices, it->second);
    } catch (const std::exception&) {
      return false;
    }
    return true;
  };
  const render::Rgba line_colour{0.1f, 0.3f, 0.85f, 1};
  const render::Rgba dot_colour{0.85f, 0.15f, 0.1f, 1};
  for (const std::string& id : core_.editable_inputs()) {
    if (id == "weight") continue;
    const MeasurementDef* def = nullptr;
    for (const MeasurementDef& d : paper_measurements()) {
      if (d.id == id) def = &d;
    }
    if (def == nullptr) continue;
    Eigen::Vector3d a, b;
    if (!point(def->from, a)) continue;
    if (def->kind == MeasurementKind::Height) {
      // A vertical line from the landmark's height to the floor: straight down from the crotch
      // for the inseam, beside the legs (the subject's right) for the other heights.
      double x = a.x();
      if (id != "inseam_height") {
        const double knee = 0.3 * av.vertices.col(1).maxCoeff();
        double leg_min = 0;
        for (Eigen::Index v = 0; v < av.vertices.rows(); ++v) {
          if (av.vertices(v, 1) < knee) leg_min = std::min(leg_min, av.vertices(v, 0));
        }
        x = leg_min - 0.3;
      }
      b = Eigen::Vector3d(x, 0, a.z());
      a = Eigen::Vector3d(x, a.y(), a.z());
    } else if (!point(def->to, b)) {
      continue;
    }
    render::Line l;
    l.a = a.cast<float>();
    l.b = b.cast<float>();
    l.colour = line_colour;
    s.lines.push_back(l);
    s.points.push_back({l.a, dot_colour, 7});
    s.points.push_back({l.b, dot_colour, 7});
    auto shown = core_.shown_value(id);
    if (shown) {
      render::Label label;
      label.text = app::measurement_text(id, *shown, core_.view().units);
      label.anchor = ((l.a + l.b) / 2);
      label.colour = {0.05f, 0.1f, 0.4f, 1};
      label.scale = 1.6f;
      label.keep_clear = true;  // arm span and arm length have anchors a few pixels apart
      s.labels.push_back(label);
    }
  }
  if (auto w = core_.shown_value("weight")) {
    render::Label label;
    label.text = app::measurement_text("weight", *w, core_.view().units);
    label.screen = true;
    label.anchor = {12, 34, 0};
    s.labels.push_back(label);
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Frame
void EditorApp::frame(int fb_width, int fb_height) {
  ImGui::NewFrame();
  handle_shortcuts();
  if (show_panel_) draw_panel();
  ImGui::Render();

  sync_meshes();
  const ImGuiIO& io = ImGui::GetIO();
  const float scale = io.DisplayFramebufferScale.x > 0 ? io.DisplayFramebufferScale.x : 1.0f;
  const int panel_px = show_panel_ ? static_cast<int>(panel_width_ * scale) : 0;
  scene_viewport_ = {panel_px, 0, std::max(1, fb_width - panel_px), std::max(1, fb_height)};

  gl_.Disable(GL_SCISSOR_TEST);
  gl_.Viewport(0, 0, fb_width, fb_height);
  gl_.ClearColor(0.96f, 0.96f, 0.97f, 1.0f);
  gl_.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  if (core_.has_model()) {
    const render::Scene scene = build_scene(false);
    const smpl::Vertices& v = core_.avatar().vertices;
    const bool side = core_.view().compare == app::CompareMode::SideBySide && core_.comparison() &&
                      pinned_mesh_ != 0;
    render::Viewport main_vp = scene_viewport_;
    if (side) main_vp.width /= 2;
    const Eigen::Vector3f lo = v.colwise().minCoeff().cast<float>();
    const Eigen::Vector3f hi = v.colwise().maxCoeff().cast<float>();
    render::View view;
    view.viewport = main_vp;
    view.camera =
        render::frame_box(lo, hi, camera_.azimuth_degrees,
                          static_cast<float>(main_vp.width) / static_cast<float>(main_vp.height),
                          camera_.elevation_degrees);
    const render::Vec3 dir = view.camera.eye - view.camera.target;
    view.camera.eye = view.camera.target + dir / camera_.zoom;
    view.camera.near_plane = 0.02f;
    renderer_->draw(scene, view);
    if (side) {
      render::View other = view;
      other.viewport.x = main_vp.x + main_vp.width;
      renderer_->draw(build_scene(true), other);
    }
  }
  imgui_->render(ImGui::GetDrawData());
}

// ---------------------------------------------------------------------------------------------
// Panels
void EditorApp::draw_panel() {
  const ImGuiIO& io = ImGui::GetIO();
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(ImVec2(panel_width_, io.DisplaySize.y));
  ImGui::Begin("The Virtual Caliper", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);

  // Model and sex.
  if (ImGui::CollapsingHeader("Model", ImGuiTreeNodeFlags_DefaultOpen)) {
    const auto& models = core_.models();
    const std::string current = core_.has_model() ? core_.model().label : std::string("(none)");
    if (ImGui::BeginCombo("model", current.c_str())) {
      for (size_t i = 0; i < models.size(); ++i) {
        const bool selected = static_cast<int>(i) == core_.current_model();
        if (ImGui::Selectable(models[i].label.c_str(), selected))
          core_.select_model(static_cast<int>(i));
      }
      ImGui::EndCombo();
    }
    bool first = true;
    for (const char* sex : {"female", "male", "neutral"}) {
      if (!first) ImGui::SameLine();
      first = false;
      const bool on = core_.has_model() && core_.model().model->meta.gender == sex;
      if (ImGui::RadioButton(sex, on) && !on) core_.select_sex(sex);
    }
    ImGui::SetNextItemWidth(300);
    ImGui::InputText("##modelpath", model_path_buffer_, sizeof model_path_buffer_);
    ImGui::SameLine();
    if (ImGui::Button("Open model")) core_.load_model_file(model_path_buffer_);
  }

  // Units, regressor, hierarchy.
  if (ImGui::CollapsingHeader("Regressor", ImGuiTreeNodeFlags_DefaultOpen)) {
    int units = core_.view().units == app::UnitSystem::Metric ? 0 : 1;
    if (ImGui::RadioButton("cm / kg", units == 0)) core_.view().units = app::UnitSystem::Metric;
    ImGui::SameLine();
    if (ImGui::RadioButton("in / lb", units == 1)) core_.view().units = app::UnitSystem::Imperial;
    const app::RegressorChoice choices[] = {app::RegressorChoice::R2, app::RegressorChoice::R4,
                                            app::RegressorChoice::R5, app::RegressorChoice::R6,
                                            app::RegressorChoice::NoiseAware};
    if (ImGui::BeginCombo("regressor", app::to_string(core_.state().regressor).c_str())) {
      for (auto c : choices) {
        if (ImGui::Selectable(app::to_string(c).c_str(), c == core_.state().regressor))
          core_.set_regressor(c);
      }
      ImGui::EndCombo();
    }
    if (core_.state().hierarchical && core_.state().regressor != app::RegressorChoice::NoiseAware) {
      ImGui::TextDisabled("hierarchical level %d uses %s", core_.state().level,
                          core_.state().level == 1   ? "R2"
                          : core_.state().level == 2 ? "R4"
                                                     : "R6");
    }
    bool hierarchical = core_.state().hierarchical;
    if (ImGui::Checkbox("hierarchical", &hierarchical)) core_.set_hierarchical(hierarchical);
    if (hierarchical) {
      ImGui::SameLine();
      for (int l = 1; l <= 3; ++l) {
        ImGui::SameLine();
        char label[16];
        std::snprintf(label, sizeof label, "level %d", l);
        if (ImGui::RadioButton(label, core_.state().level == l)) core_.set_level(l);
      }
    }
  }
  if (ImGui::CollapsingHeader("Measurements", ImGuiTreeNodeFlags_DefaultOpen)) draw_measurements();
  if (ImGui::CollapsingHeader("Shape and plausibility", ImGuiTreeNodeFlags_DefaultOpen))
    draw_betas();
  if (ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) {
    app::ViewSettings& vs = core_.view();
    ImGui::Checkbox("wireframe (W)", &vs.wireframe);
    ImGui::SameLine();
    ImGui::Checkbox("measurements (M)", &vs.overlay);
    int colour = static_cast<int>(vs.colour);
    const char* colours[] = {"skin", "plausibility", "uncertainty"};
    if (ImGui::Combo("colour", &colour, colours, 3))
      vs.colour = static_cast<app::ColourMode>(colour);
    if (ImGui::Button("Pin for comparison")) core_.pin_comparison("pinned");
    ImGui::SameLine();
    int compare = static_cast<int>(vs.compare);
    const DisabledScope no_comparison(!core_.comparison().has_value());
    if (ImGui::RadioButton("off", compare == 0)) vs.compare = app::CompareMode::Off;
    ImGui::SameLine();
    if (ImGui::RadioButton("side", compare == 1)) vs.compare = app::CompareMode::SideBySide;
    ImGui::SameLine();
    if (ImGui::RadioButton("difference", compare == 2)) vs.compare = app::CompareMode::Difference;
  }
  if (ImGui::CollapsingHeader("Files", ImGuiTreeNodeFlags_DefaultOpen)) draw_files();
  ImGui::End();
  draw_messages();
}

void EditorApp::draw_measurements() {
  if (!core_.has_model()) {
    ImGui::TextDisabled("open a model first");
    return;
  }
  const std::vector<std::string> editable = core_.editable_inputs();
  const app::UnitSystem units = core_.view().units;
  for (const std::string& id : choice_inputs(app::RegressorChoice::R6)) {
    const bool can_edit = std::find(editable.begin(), editable.end(), id) != editable.end();
    const auto value = core_.shown_value(id);
    if (!value) continue;
    ImGui::PushID(id.c_str());
    const std::string unit = app::unit_label(id, units);
    double shown = app::to_display(id, *value, units);
    if (!can_edit) {
      ImGui::TextDisabled("%s: %.1f %s (avatar)", app::measurement_name(id).c_str(), shown,
                          unit.c_str());
      ImGui::PopID();
      continue;
    }
    ImGui::Text("%s", app::measurement_name(id).c_str());
    MeasurementRange r = measurement_range(id);
    float f = static_cast<float>(shown);
    const float lo = static_cast<float>(app::to_display(id, r.warning_min, units));
    const float hi = static_cast<float>(app::to_display(id, r.warning_max, units));
    ImGui::SetNextItemWidth(230);
    const std::string format = "%.1f " + unit;
    if (ImGui::SliderFloat("##slider", &f, lo, hi, format.c_str())) {
      core_.drag_value(id, app::from_display(id, f, units));
    }
    if (ImGui::IsItemActivated()) core_.begin_drag();
    if (ImGui::IsItemDeactivated()) core_.end_drag();
    ImGui::SameLine();
    ImGui::SetNextItemWidth(110);
    double typed = shown;
    if (ImGui::InputDouble("##typed", &typed, 0, 0, "%.1f", ImGuiInputTextFlags_EnterReturnsTrue)) {
      core_.set_display_value(id, typed);
    }
    ImGui::PopID();
  }
  if (const auto w = core_.avatar().achieved.find("weight"); w != core_.avatar().achieved.end()) {
    ImGui::TextDisabled(
        "avatar: weight %.1f %s, volume %.1f %s", app::to_display("weight", w->second, units),
        app::unit_label("weight", units).c_str(),
        app::to_display(
            "volume",
            core_.avatar().achieved.count("volume") ? core_.avatar().achieved.at("volume") : 0.0,
            units),
        app::unit_label("volume", units).c_str());
  }
}

void EditorApp::draw_betas() {
  if (!core_.has_model()) return;
  const app::AvatarView& av = core_.avatar();
  const Plausibility& p = av.plausibility;
  const ImVec4 ok(0.1f, 0.55f, 0.2f, 1), warn(0.85f, 0.5f, 0.0f, 1), bad(0.85f, 0.1f, 0.1f, 1);
  ImGui::TextColored(p.plausible ? ok : bad, "Mahalanobis %.2f  (p = %.3g)  %s", p.mahalanobis,
                     p.p_value, p.plausible ? "plausible" : "IMPLAUSIBLE");
  const int k = p.dof;
  for (int b = 0; b < k; ++b) {
    const double v = av.betas(b);
    const ImVec4 c = std::abs(v) > 3 ? bad : std::abs(v) > 2 ? warn : ok;
    char label[48];
    if (av.beta_sd.size() > b) {
      std::snprintf(label, sizeof label, "b%-2d %+6.2f +- %.2f", b, v, av.beta_sd(b));
    } else {
      std::snprintf(label, sizeof label, "b%-2d %+6.2f", b, v);
    }
    ImGui::PushStyleColor(ImGuiCol_PlotHistogram, c);
    ImGui::ProgressBar(static_cast<float>(std::min(1.0, std::abs(v) / 4.0)), ImVec2(140, 0), "");
    ImGui::PopStyleColor();
    ImGui::SameLine();
    ImGui::TextColored(c, "%s", label);
  }
}

void EditorApp::draw_files() {
  ImGui::SetNextItemWidth(300);
  ImGui::InputText("file", path_buffer_, sizeof path_buffer_);
  if (ImGui::Button("Open profile")) core_.open_profile(path_buffer_);
  ImGui::SameLine();
  if (ImGui::Button("Save profile")) core_.save_profile(path_buffer_);
  ImGui::SameLine();
  if (ImGui::Button("Open session")) core_.open_session(path_buffer_);
  if (ImGui::Button("Export")) core_.export_mesh(path_buffer_);
  ImGui::SameLine();
  // Every export format: choosing one puts its extension on the file name.
  ImGui::SetNextItemWidth(70);
  if (ImGui::BeginCombo("##format", "as...")) {
    for (const auto& f : app::export_formats()) {
      if (ImGui::Selectable((f.extension + "  " + f.description).c_str())) {
        std::string path = path_buffer_;
        const size_t slash = path.find_last_of('/'), dot = path.find_last_of('.');
        if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) {
          path.erase(dot);
        }
        path += f.extension;
        std::snprintf(path_buffer_, sizeof path_buffer_, "%s", path.c_str());
      }
    }
    ImGui::EndCombo();
  }
  ImGui::SameLine();
  if (ImGui::Button("Screenshot")) screenshot_request_ = path_buffer_;
  ImGui::SameLine();
  {
    const DisabledScope no_undo(!core_.can_undo());
    if (ImGui::Button("Undo")) core_.undo();
  }
  ImGui::SameLine();
  {
    const DisabledScope no_redo(!core_.can_redo());
    if (ImGui::Button("Redo")) core_.redo();
  }
}

void EditorApp::draw_messages() {
  // A status window along the bottom of the 3D view: the last messages, errors in red.
  const auto& msgs = core_.messages();
  if (msgs.empty()) return;
  const ImGuiIO& io = ImGui::GetIO();
  const size_t first = msgs.size() > 3 ? msgs.size() - 3 : 0;
  const float height = 16.0f + 18.0f * static_cast<float>(msgs.size() - first);
  ImGui::SetNextWindowPos(ImVec2(panel_width_, io.DisplaySize.y - height));
  ImGui::SetNextWindowSize(ImVec2(io.DisplaySize.x - panel_width_, height));
  ImGui::SetNextWindowBgAlpha(0.85f);
  ImGui::Begin("##status", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing);
  for (size_t i = first; i < msgs.size(); ++i) {
    const app::Message& m = msgs[i];
    const ImVec4 c = m.level == app::Message::Level::Error     ? ImVec4(0.8f, 0.1f, 0.1f, 1)
                     : m.level == app::Message::Level::Warning ? ImVec4(0.75f, 0.45f, 0.0f, 1)
                                                               : ImVec4(0.3f, 0.3f, 0.3f, 1);
    ImGui::TextColored(c, "%s", m.text.c_str());
  }
  ImGui::End();
}

// ---------------------------------------------------------------------------------------------
// Keyboard shortcuts. Letter and digit keys are GLFW key codes (their ASCII upper-case value),
// which is how Dear ImGui 1.86's GLFW backend fills io.KeysDown.
void EditorApp::handle_shortcuts() {
  const ImGuiIO& io = ImGui::GetIO();
  if (io.WantTextInput) return;
  const bool ctrl = io.KeyCtrl;
  if (ctrl && ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Z))) {
    if (io.KeyShift)
      core_.redo();
    else
      core_.undo();
  }
  if (ctrl && ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Y))) core_.redo();
  if (ctrl && ImGui::IsKeyPressed('S')) core_.save_profile(path_buffer_);
  if (ctrl && ImGui::IsKeyPressed('O')) core_.open_profile(path_buffer_);
  if (ctrl && ImGui::IsKeyPressed('E')) core_.export_mesh(path_buffer_);
  if (ctrl && ImGui::IsKeyPressed('P')) screenshot_request_ = "screenshot.png";
  if (ctrl) return;
  if (ImGui::IsKeyPressed('W')) core_.view().wireframe = !core_.view().wireframe;
  if (ImGui::IsKeyPressed('M')) core_.view().overlay = !core_.view().overlay;
  if (ImGui::IsKeyPressed('U')) {
    core_.view().units = core_.view().units == app::UnitSystem::Metric ? app::UnitSystem::Imperial
                                                                       : app::UnitSystem::Metric;
  }
  if (ImGui::IsKeyPressed('1')) core_.set_level(1);
  if (ImGui::IsKeyPressed('2')) core_.set_level(2);
  if (ImGui::IsKeyPressed('3')) core_.set_level(3);
  if (ImGui::IsKeyPressed('F')) camera_.azimuth_degrees = 0;
  if (ImGui::IsKeyPressed('S')) camera_.azimuth_degrees = 90;
  if (ImGui::IsKeyDown(ImGui::GetKeyIndex(ImGuiKey_LeftArrow)))
    camera_.azimuth_degrees -= 90 * io.DeltaTime;
  if (ImGui::IsKeyDown(ImGui::GetKeyIndex(ImGuiKey_RightArrow)))
    camera_.azimuth_degrees += 90 * io.DeltaTime;
  if (ImGui::IsKeyDown(ImGui::GetKeyIndex(ImGuiKey_UpArrow)))
    camera_.zoom = std::min(10.0f, camera_.zoom * (1 + io.DeltaTime));
  if (ImGui::IsKeyDown(ImGui::GetKeyIndex(ImGuiKey_DownArrow)))
    camera_.zoom = std::max(0.2f, camera_.zoom / (1 + io.DeltaTime));
}

}  // namespace caliper::editor
