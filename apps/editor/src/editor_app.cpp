// One editor frame. Sections: construction, commands, mesh upload, scene (avatar, measurement
// overlay with human names, height ruler, colour maps, comparison), panels (model, regressor and
// hierarchy, measurements, typed vs avatar table, shape and plausibility, display, files,
// status), dialogs (files, unsaved work), keyboard shortcuts.
#include "editor_app.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <sstream>
#include <utility>

#include "render/camera.hpp"
#include "render/colour_map.hpp"
#include "render/text.hpp"

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

std::string display(const app::EditorCore& core, const std::string& id, double si) {
  return app::value_text(id, si, core.view().units);
}

/// A typed number with an optional unit: "170", "170.5", "170,5" (decimal comma), "1.68 m",
/// "5 ft"? (no: feet-inches are not parsed), "66 in". Returns SI or nothing.
std::optional<double> parse_typed(const std::string& id, std::string text, app::UnitSystem units) {
  std::replace(text.begin(), text.end(), ',', '.');
  const char* s = text.c_str();
  char* end = nullptr;
  const double v = std::strtod(s, &end);
  if (end == s || !std::isfinite(v)) return std::nullopt;
  std::string unit(end);
  unit.erase(0, unit.find_first_not_of(" \t"));
  unit.erase(unit.find_last_not_of(" \t") + 1);
  if (unit.empty()) return app::from_display(id, v, units);
  return app::to_si_with_suffix(id, v, unit);
}

/// Colour-map range of each mode, metres.
constexpr float kPlausibilityRange = 0.02f;   // 2 cm of displacement from components beyond 2 SD
constexpr float kUncertaintyRange = 0.02f;    // 2 cm positional SD
constexpr float kMinDifferenceRange = 0.01f;  // 1 cm: below that the map would show noise
/// The fixed-scale view frames a box this tall (metres): the tallest plausible adult fits.
constexpr float kFixedScaleHeight = 2.2f;
constexpr float kMinPanelWidth = 300.0f;
constexpr float kMinSceneWidth = 200.0f;
/// World labels of the overlay are drawn at this glyph scale (1 = 7 px letters).
constexpr float kLabelScale = 1.6f;
}  // namespace

void set_glfw_key_map(ImGuiIO& io) {
  io.KeyMap[ImGuiKey_Tab] = GLFW_KEY_TAB;
  io.KeyMap[ImGuiKey_LeftArrow] = GLFW_KEY_LEFT;
  io.KeyMap[ImGuiKey_RightArrow] = GLFW_KEY_RIGHT;
  io.KeyMap[ImGuiKey_UpArrow] = GLFW_KEY_UP;
  io.KeyMap[ImGuiKey_DownArrow] = GLFW_KEY_DOWN;
  io.KeyMap[ImGuiKey_PageUp] = GLFW_KEY_PAGE_UP;
  io.KeyMap[ImGuiKey_PageDown] = GLFW_KEY_PAGE_DOWN;
  io.KeyMap[ImGuiKey_Home] = GLFW_KEY_HOME;
  io.KeyMap[ImGuiKey_End] = GLFW_KEY_END;
  io.KeyMap[ImGuiKey_Insert] = GLFW_KEY_INSERT;
  io.KeyMap[ImGuiKey_Delete] = GLFW_KEY_DELETE;
  io.KeyMap[ImGuiKey_Backspace] = GLFW_KEY_BACKSPACE;
  io.KeyMap[ImGuiKey_Space] = GLFW_KEY_SPACE;
  io.KeyMap[ImGuiKey_Enter] = GLFW_KEY_ENTER;
  io.KeyMap[ImGuiKey_Escape] = GLFW_KEY_ESCAPE;
  io.KeyMap[ImGuiKey_KeyPadEnter] = GLFW_KEY_KP_ENTER;
  io.KeyMap[ImGuiKey_A] = GLFW_KEY_A;
  io.KeyMap[ImGuiKey_C] = GLFW_KEY_C;
  io.KeyMap[ImGuiKey_V] = GLFW_KEY_V;
  io.KeyMap[ImGuiKey_X] = GLFW_KEY_X;
  io.KeyMap[ImGuiKey_Y] = GLFW_KEY_Y;
  io.KeyMap[ImGuiKey_Z] = GLFW_KEY_Z;
}

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
  std::error_code ec;
  last_folder_ = std::filesystem::current_path(ec);
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
  if (cmd == "azimuth" || cmd == "zoom" || cmd == "elevation" || cmd == "panel-width") {
    float v = 0;
    if (!(in >> v)) {
      core_.post(app::Message::Level::Error, "command '" + line + "': expected a number");
      return false;
    }
    if (cmd == "azimuth") camera_.azimuth_degrees = v;
    if (cmd == "elevation") camera_.elevation_degrees = std::clamp(v, -80.0f, 80.0f);
    if (cmd == "zoom") camera_.zoom = std::clamp(v, 0.2f, 10.0f);
    if (cmd == "panel-width") panel_width_ = std::max(kMinPanelWidth, v);
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

void EditorApp::request_quit() {
  if (!core_.has_unsaved_changes()) {
    quit_ = true;
    return;
  }
  pending_ = Pending::Quit;
}

bool EditorApp::animating() const {
  const ImGuiIO& io = ImGui::GetIO();
  for (int k : {GLFW_KEY_LEFT, GLFW_KEY_RIGHT, GLFW_KEY_UP, GLFW_KEY_DOWN}) {
    if (io.KeysDown[k]) return true;
  }
  return false;
}

bool EditorApp::button(const char* label, bool enabled) {
  bool pressed = false;
  {
    const DisabledScope off(!enabled);
    pressed = ImGui::Button(label);
    probe_.track(label);
  }
  return pressed;
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
    renderer_->prepare_levels(avatar_mesh_);  // for slider drags, now rather than at the first
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
namespace {

/// Screen position (pixels from the viewport's top-left) of a world point, or false behind the
/// camera.
bool to_screen(const render::Mat4& view_projection, const render::Vec3& p,
               const render::Viewport& vp, float& x, float& y) {
  const Eigen::Vector4f c = view_projection * Eigen::Vector4f(p.x(), p.y(), p.z(), 1);
  if (c.w() <= 1e-6f) return false;
  x = (c.x() / c.w() + 1) * 0.5f * static_cast<float>(vp.width);
  y = (1 - c.y() / c.w()) * 0.5f * static_cast<float>(vp.height);
  return true;
}

/// Turns world labels into screen labels that do not overlap: each label keeps its anchor's
/// height when it can and moves down (then up) just enough to clear the labels placed before.
void place_labels(std::vector<render::Label>& labels, const render::View& view) {
  const float aspect =
      static_cast<float>(view.viewport.width) / static_cast<float>(view.viewport.height);
  const render::Mat4 vp_m =
      render::projection_matrix(view.camera, aspect) * render::view_matrix(view.camera);
  struct Box {
    float x0, y0, x1, y1;
  };
  std::vector<Box> placed;
  std::vector<render::Label> out;
  std::vector<std::pair<float, size_t>> order;
  for (size_t i = 0; i < labels.size(); ++i) {
    float x = 0, y = 0;
    if (labels[i].screen || !to_screen(vp_m, labels[i].anchor, view.viewport, x, y)) continue;
    order.push_back({y, i});
  }
  std::sort(order.begin(), order.end());
  const float pad = 4;
  for (const auto& [y_anchor, i] : order) {
    render::Label l = labels[i];
    float x = 0, y = 0;
    to_screen(vp_m, l.anchor, view.viewport, x, y);
    const float w = render::text_width(l.text, l.scale), h = render::text_height(l.text, l.scale);
    x = std::clamp(x + 6, 4.0f, std::max(4.0f, static_cast<float>(view.viewport.width) - w - 6));
    y -= h / 2;
    auto overlaps = [&](float yy) {
      for (const Box& b : placed) {
        if (x < b.x1 + pad && x + w + pad > b.x0 && yy < b.y1 + pad && yy + h + pad > b.y0)
          return true;
      }
      return false;
    };
    // Try positions moving away from the anchor, alternately down and up.
    float best = y;
    for (int step = 0; step < 200; ++step) {
      const int distance = (step + 1) / 2;  // 0, 1, 1, 2, 2, ...: each distance up and down
      const float dy = static_cast<float>(distance) * 3.0f * (step % 2 == 1 ? 1.0f : -1.0f);
      const float cand = step == 0 ? y : y + dy;
      if (!overlaps(cand)) {
        best = cand;
        break;
      }
    }
    placed.push_back({x - 3, best - 3, x + w + 3, best + h + 1});
    l.screen = true;
    l.anchor = {x, best, 0};
    out.push_back(l);
  }
  labels.erase(std::remove_if(labels.begin(), labels.end(),
                              [](const render::Label& l) { return !l.screen; }),
               labels.end());
  labels.insert(labels.end(), out.begin(), out.end());
}

/// A label in screen pixels at (12, y) from the scene's top left corner.
render::Label corner_label(const std::string& text, float y) {
  render::Label l;
  l.text = text;
  l.screen = true;
  l.anchor = {12, y, 0};
  return l;
}

/// Adds a height ruler standing on the floor grid behind the avatar's right side: a tick every
/// 10 cm (imperial: every 4 in), a label every 50 cm (every foot), and a line level with the top
/// of the head (`vertices`: the avatar's, floor at y = 0).
void add_height_ruler(render::Scene& s, const smpl::Vertices& vertices, app::UnitSystem units) {
  const bool imperial = units == app::UnitSystem::Imperial;
  const double step = imperial ? 0.1016 : 0.1;  // 4 in or 10 cm
  const int label_every = imperial ? 3 : 5;
  const float rx = -0.75f, rz = -0.35f;
  render::Line post;
  post.a = {rx, 0, rz};
  post.b = {rx, 2.1f, rz};
  post.colour = {0.35f, 0.35f, 0.4f, 1};
  s.lines.push_back(post);
  for (int i = 1; i * step <= 2.1; ++i) {
    const float y = static_cast<float>(i * step);
    const bool major = i % label_every == 0;
    render::Line tick;
    tick.a = {rx, y, rz};
    tick.b = {rx + (major ? 0.08f : 0.04f), y, rz};
    tick.colour = post.colour;
    s.lines.push_back(tick);
    if (major) {
      render::Label l;
      char buf[32];
      if (imperial)
        std::snprintf(buf, sizeof buf, "%d ft", i / label_every);
      else
        std::snprintf(buf, sizeof buf, "%.1f m", y);
      l.text = buf;
      l.anchor = {rx - 0.22f, y, rz};
      l.scale = 1.3f;
      l.colour = {0.3f, 0.3f, 0.35f, 1};
      s.labels.push_back(l);
    }
  }
  // The avatar's height, level with the top of the head.
  const float top = static_cast<float>(vertices.col(1).maxCoeff());
  render::Line head;
  head.a = {rx, top, rz};
  head.b = {0, top, rz};
  head.colour = {0.85f, 0.35f, 0.1f, 1};
  s.lines.push_back(head);
}

/// The two ends of the overlay line of measurement `def` (input `id`) on `av`, or nothing when
/// a landmark is missing or cannot be evaluated. Heights are a vertical line to the floor:
/// straight down from the crotch for the inseam, beside the legs (the subject's right) for the
/// other heights.
std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> overlay_ends(const LandmarkTable& lm,
                                                                        const app::AvatarView& av,
                                                                        const MeasurementDef& def,
                                                                        const std::string& id) {
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
  Eigen::Vector3d a, b;
  if (!point(def.from, a)) return std::nullopt;
  if (def.kind == MeasurementKind::Height) {
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
  } else if (!point(def.to, b)) {
    return std::nullopt;
  }
  return std::make_pair(a, b);
}

/// Adds the measurement overlay: a line with end dots for each input of the current regressor /
/// level, labelled with its human name and the avatar's value, and the weight (with the typed
/// one when they differ) in the corner at `weight_y`.
void add_measurement_overlay(render::Scene& s, const app::EditorCore& core, float weight_y) {
  const app::AvatarView& av = core.avatar();
  const render::Rgba line_colour{0.1f, 0.3f, 0.85f, 1};
  const render::Rgba dot_colour{0.85f, 0.15f, 0.1f, 1};
  for (const std::string& id : core.editable_inputs()) {
    if (id == "weight") continue;
    const MeasurementDef* def = nullptr;
    for (const MeasurementDef& d : paper_measurements()) {
      if (d.id == id) def = &d;
    }
    if (def == nullptr) continue;
    const auto ends = overlay_ends(core.model().landmarks, av, *def, id);
    if (!ends) continue;
    render::Line l;
    l.a = ends->first.cast<float>();
    l.b = ends->second.cast<float>();
    l.colour = line_colour;
    s.lines.push_back(l);
    s.points.push_back({l.a, dot_colour, 7});
    s.points.push_back({l.b, dot_colour, 7});
    auto it = av.achieved.find(id);
    if (it != av.achieved.end()) {
      render::Label label;
      label.text = app::measurement_label(id) + " " + display(core, id, it->second);
      if (id == "arm_length" && core.state().arm_taken_hanging) {
        // The line is the arm out sideways; the value typed was taken hanging.
        const MeasurementMap typed = core.achieved_as_typed();
        if (auto h = typed.find(id); h != typed.end())
          label.text += ", hanging " + display(core, id, h->second);
      }
      label.anchor = ((l.a + l.b) / 2);
      label.colour = {0.05f, 0.1f, 0.4f, 1};
      label.scale = kLabelScale;
      s.labels.push_back(label);
    }
  }
  if (auto w = av.achieved.find("weight"); w != av.achieved.end()) {
    std::string text = "Weight " + display(core, "weight", w->second);
    if (auto typed = core.state().values.find("weight");
        typed != core.state().values.end() && std::abs(typed->second - w->second) >= 0.05) {
      text += " (typed " + display(core, "weight", typed->second) + ")";
    }
    s.labels.push_back(corner_label(text, weight_y));
  }
}

}  // namespace

render::Scene EditorApp::build_scene(bool comparison_side, const render::View& view) const {
  render::Scene s;
  s.grid.extent = 1.5f;
  if (!core_.has_model()) return s;
  const app::ViewSettings& vs = core_.view();
  render::MeshInstance inst;
  if (comparison_side) {
    inst.mesh = pinned_mesh_;
    inst.colour = {0.62f, 0.70f, 0.82f, 1};
    s.meshes.push_back(inst);
    s.labels.push_back(corner_label(core_.comparison() ? core_.comparison()->label : "", 12));
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
  const bool side_by_side = vs.compare == app::CompareMode::SideBySide;
  if (side_by_side) s.labels.push_back(corner_label("current", 12));
  if (vs.fixed_scale) add_height_ruler(s, core_.avatar().vertices, vs.units);
  if (vs.overlay) add_measurement_overlay(s, core_, side_by_side ? 34.0f : 12.0f);
  place_labels(s.labels, view);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Frame
void EditorApp::frame(int fb_width, int fb_height) {
  probe_.clear();
  if (!deferred_screenshot_.empty()) {
    screenshot_request_ = deferred_screenshot_;
    deferred_screenshot_.clear();
  }
  ImGui::NewFrame();
  handle_shortcuts();
  if (show_panel_) draw_panel();
  draw_messages();
  draw_dialogs();
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
    const smpl::Vertices& v = core_.avatar().vertices;
    const bool side = core_.view().compare == app::CompareMode::SideBySide && core_.comparison() &&
                      pinned_mesh_ != 0;
    render::Viewport main_vp = scene_viewport_;
    if (side) main_vp.width /= 2;
    Eigen::Vector3f lo = v.colwise().minCoeff().cast<float>();
    Eigen::Vector3f hi = v.colwise().maxCoeff().cast<float>();
    if (core_.view().fixed_scale) {
      // One scale for every body: a box from the floor to kFixedScaleHeight, as wide as the
      // ruler and a wide arm span.
      lo = Eigen::Vector3f(-1.0f, 0.0f, -0.4f);
      hi = Eigen::Vector3f(1.0f, kFixedScaleHeight, 0.4f);
    }
    render::View view;
    view.viewport = main_vp;
    view.camera =
        render::frame_box(lo, hi, camera_.azimuth_degrees,
                          static_cast<float>(main_vp.width) / static_cast<float>(main_vp.height),
                          camera_.elevation_degrees);
    const render::Vec3 dir = view.camera.eye - view.camera.target;
    view.camera.eye = view.camera.target + dir / camera_.zoom;
    view.camera.near_plane = 0.02f;
    // While a slider is dragged the body is drawn from its simplified levels (under half a pixel
    // of geometric error); the full mesh returns with the drag's end (docs/performance.md).
    renderer_->set_level_of_detail(core_.dragging());
    renderer_->draw(build_scene(false, view), view);
    if (side) {
      render::View other = view;
      other.viewport.x = main_vp.x + main_vp.width;
      renderer_->draw(build_scene(true, other), other);
    }
  }
  imgui_->render(ImGui::GetDrawData());
}

// ---------------------------------------------------------------------------------------------
// Panels
void EditorApp::draw_panel() {
  const ImGuiIO& io = ImGui::GetIO();
  const float max_width = std::max(kMinPanelWidth, io.DisplaySize.x - kMinSceneWidth);
  panel_width_ = std::clamp(panel_width_, kMinPanelWidth, max_width);
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(ImVec2(panel_width_, io.DisplaySize.y));
  ImGui::SetNextWindowSizeConstraints(ImVec2(kMinPanelWidth, io.DisplaySize.y),
                                      ImVec2(max_width, io.DisplaySize.y));
  // Movable: no; resizable by its right edge; scrolls when it is taller than the window.
  ImGui::Begin("The Virtual Caliper", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_AlwaysVerticalScrollbar);
  panel_width_ = ImGui::GetWindowWidth();
  draw_model_section();
  draw_regressor_section();
  if (ImGui::CollapsingHeader("Measurements", ImGuiTreeNodeFlags_DefaultOpen)) {
    draw_measurements();
    draw_achieved_table();
  }
  if (ImGui::CollapsingHeader("Shape and plausibility", ImGuiTreeNodeFlags_DefaultOpen))
    draw_betas();
  draw_display_section();
  if (ImGui::CollapsingHeader("Files and history", ImGuiTreeNodeFlags_DefaultOpen)) draw_files();
  ImGui::End();
}

void EditorApp::draw_model_section() {
  if (!ImGui::CollapsingHeader("Model", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const auto& models = core_.models();
  const std::string current = core_.has_model() ? core_.model().label : std::string("(none)");
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x - 120);
  if (ImGui::BeginCombo("body model", current.c_str())) {
    for (size_t i = 0; i < models.size(); ++i) {
      const bool selected = static_cast<int>(i) == core_.current_model();
      if (ImGui::Selectable(models[i].label.c_str(), selected))
        core_.select_model(static_cast<int>(i));
      probe_.track(models[i].label.c_str());
    }
    ImGui::EndCombo();
  }
  probe_.track("body model");
  bool first = true;
  for (const char* sex : {"female", "male", "neutral"}) {
    if (!first) ImGui::SameLine();
    first = false;
    const bool on = core_.has_model() && core_.model().model->meta.gender == sex;
    if (ImGui::RadioButton(sex, on) && !on) core_.select_sex(sex);
    probe_.track(sex);
  }
  ImGui::SameLine();
  if (button("Open model...")) start_file_action(FileAction::OpenModel);
}

void EditorApp::draw_regressor_section() {
  if (!ImGui::CollapsingHeader("Units and regressor", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const int units = core_.view().units == app::UnitSystem::Metric ? 0 : 1;
  if (ImGui::RadioButton("cm / kg", units == 0)) core_.view().units = app::UnitSystem::Metric;
  probe_.track("cm / kg");
  ImGui::SameLine();
  if (ImGui::RadioButton("in / lb", units == 1)) core_.view().units = app::UnitSystem::Imperial;
  probe_.track("in / lb");

  const app::Document& doc = core_.state();
  bool hierarchical = doc.hierarchical;
  if (ImGui::Checkbox("Hierarchical adjustment (start with 2 inputs, add more)", &hierarchical))
    core_.set_hierarchical(hierarchical);
  probe_.track("Hierarchical adjustment (start with 2 inputs, add more)");
  if (doc.hierarchical) {
    const char* levels[] = {"Level 1: height, weight (R2)", "Level 2: + inseam, arm span (R4)",
                            "Level 3: + arm length, hip width (R6)"};
    for (int l = 1; l <= 3; ++l) {
      ImGui::Indent();
      if (ImGui::RadioButton(levels[l - 1], doc.level == l) && doc.level != l) core_.set_level(l);
      probe_.track(levels[l - 1]);
      ImGui::Unindent();
    }
  }
  // The regressor list: picking one uses it at once (hierarchical adjustment off).
  const app::RegressorChoice choices[] = {app::RegressorChoice::R2, app::RegressorChoice::R4,
                                          app::RegressorChoice::R5, app::RegressorChoice::R6,
                                          app::RegressorChoice::NoiseAware};
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x - 90);
  const std::string shown =
      doc.hierarchical ? std::string("(set by the level)") : app::describe_regressor(doc.regressor);
  if (ImGui::BeginCombo("regressor", shown.c_str())) {
    for (auto c : choices) {
      const std::string label = app::describe_regressor(c);
      if (ImGui::Selectable(label.c_str(), !doc.hierarchical && c == doc.regressor))
        core_.use_regressor(c);
      probe_.track(label.c_str());
    }
    ImGui::EndCombo();
  }
  probe_.track("regressor");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "A regressor turns the measurements you type into the body's shape.\n"
        "R2-R6 are linear regressors with 2-6 inputs (more inputs, closer fit).\n"
        "Picking one turns the hierarchical adjustment off.");
  const app::RegressorChoice active = core_.active_regressor();
  std::string why;
  if (doc.hierarchical && active == app::RegressorChoice::NoiseAware)
    why = " on the level-" + std::to_string(doc.level) + " inputs";
  else if (doc.hierarchical)
    why = " (hierarchical level " + std::to_string(doc.level) + ")";
  ImGui::TextWrapped("In use: %s%s", app::describe_regressor(active).c_str(), why.c_str());
}

void EditorApp::draw_measurements() {
  if (!core_.has_model()) {
    ImGui::TextDisabled("open a model first");
    return;
  }
  const std::vector<std::string> editable = core_.editable_inputs();
  const app::UnitSystem units = core_.view().units;
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
  ImGui::TextWrapped("Drag a slider or type a value (Enter, Tab or a click elsewhere applies it)");
  ImGui::PopStyleColor();
  for (const std::string& id : editable) {
    const auto value = core_.shown_value(id);
    if (!value) continue;
    ImGui::PushID(id.c_str());
    const std::string unit = app::unit_label(id, units);
    const double shown = app::to_display(id, *value, units);
    const std::string name = app::measurement_label(id);  // also the fields' ids
    const float avail = ImGui::GetContentRegionAvail().x;
    const float name_w = std::min(170.0f, avail * 0.38f);
    const float typed_w = 96.0f;
    ImGui::AlignTextToFramePadding();
    ImGui::TextUnformatted(app::input_label(core_.state(), id).c_str());
    if (ImGui::IsItemHovered()) {  // the hint only when shown, not on every frame
      if (const std::string hint = app::measurement_hint(id); !hint.empty())
        ImGui::SetTooltip("%s", hint.c_str());
    }
    ImGui::SameLine(name_w);
    const MeasurementRange r = measurement_range(id);
    float f = static_cast<float>(shown);
    const float lo = static_cast<float>(app::to_display(id, r.warning_min, units));
    const float hi = static_cast<float>(app::to_display(id, r.warning_max, units));
    ImGui::SetNextItemWidth(std::max(60.0f, avail - name_w - typed_w - 8));
    const std::string format = "%.1f " + unit;
    const std::string slider_id = "##slider " + name;
    if (ImGui::SliderFloat(slider_id.c_str(), &f, lo, hi, format.c_str()))
      core_.drag_value(id, app::from_display(id, f, units));
    if (ImGui::IsItemActivated()) core_.begin_drag();
    if (ImGui::IsItemDeactivated()) core_.end_drag();
    probe_.track(slider_id.c_str());
    ImGui::SameLine();
    ImGui::SetNextItemWidth(typed_w);
    auto& text = typed_text_[id];
    if (active_field_ != id)
      std::snprintf(text.data(), text.size(), "%.1f %s", shown, unit.c_str());
    const std::string typed_id = "##typed " + name;
    ImGui::InputText(typed_id.c_str(), text.data(), text.size(), ImGuiInputTextFlags_AutoSelectAll);
    probe_.track(typed_id.c_str());
    if (ImGui::IsItemActive()) {
      active_field_ = id;
    } else if (active_field_ == id) {
      active_field_.clear();
    }
    // Enter, Tab and a click elsewhere all end the edit: apply what was typed.
    if (ImGui::IsItemDeactivatedAfterEdit()) {
      if (const auto si = parse_typed(id, text.data(), units)) {
        core_.set_value(id, *si);
      } else {
        core_.post(app::Message::Level::Error, name + ": '" + std::string(text.data()) +
                                                   "' is not a number (e.g. 172.5 " + unit +
                                                   "); the avatar is unchanged");
      }
    }
    if (id == "arm_length") draw_arm_hanging_toggle(name_w);
    ImGui::PopID();
  }
}

void EditorApp::draw_arm_hanging_toggle(float indent) {
  const std::string why = core_.hanging_arm_unavailable();  // the map is worked out once
  bool hanging = core_.state().arm_taken_hanging;
  ImGui::SetCursorPosX(ImGui::GetCursorPosX() + indent);
  {
    const DisabledScope off(!why.empty() && !hanging);
    if (ImGui::Checkbox("taken hanging", &hanging)) core_.set_arm_taken_hanging(hanging);
    probe_.track("taken hanging");
  }
  if (!ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) return;
  if (why.empty()) {
    ImGui::SetTooltip(
        "Tick when the arm length was taken with a tape on the relaxed hanging arm:\n"
        "shoulder tip (acromion) over the elbow to the wrist, about 7 cm more than with\n"
        "the arm out sideways. The model's own map turns it into the arm length the\n"
        "regressors take. Ticking converts the value, so the avatar stays as it is.");
  } else {
    ImGui::SetTooltip(
        "This model cannot map an arm length taken hanging onto its own:\n%s\n"
        "Give the arm length out sideways (shoulder tip to wrist, arm stretched out).",
        why.c_str());
  }
}

void EditorApp::draw_achieved_table() {
  if (!core_.has_model()) return;
  const app::AvatarView& av = core_.avatar();
  const app::UnitSystem units = core_.view().units;
  const std::vector<std::string> editable = core_.editable_inputs();
  // The avatar's arm as a hanging one when the arm length is taken hanging (as typed).
  const MeasurementMap achieved_values = core_.achieved_as_typed();
  ImGui::Spacing();
  ImGui::TextUnformatted("Typed values and the avatar's own measurements");
  if (!ImGui::BeginTable("achieved", 4,
                         ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerH |
                             ImGuiTableFlags_SizingStretchProp))
    return;
  ImGui::TableSetupColumn("Measurement", ImGuiTableColumnFlags_WidthStretch, 2.2f);
  ImGui::TableSetupColumn("Typed", ImGuiTableColumnFlags_WidthStretch, 1.0f);
  ImGui::TableSetupColumn("Avatar", ImGuiTableColumnFlags_WidthStretch, 1.0f);
  ImGui::TableSetupColumn("Difference", ImGuiTableColumnFlags_WidthStretch, 1.1f);
  ImGui::TableHeadersRow();
  std::vector<std::string> rows = choice_inputs(app::RegressorChoice::R6);
  for (const MeasurementDef& d : paper_measurements()) {
    if (std::find(rows.begin(), rows.end(), d.id) == rows.end()) rows.push_back(d.id);
  }
  rows.push_back("volume");
  for (const std::string& id : rows) {
    auto a = achieved_values.find(id);
    const bool is_input = std::find(editable.begin(), editable.end(), id) != editable.end();
    const std::string label = app::input_label(core_.state(), id);
    if (a == achieved_values.end()) {
      // During a slider drag only the distances are measured; weight and volume follow at its
      // end. Their rows stay, so that the panel below does not jump while dragging.
      if (av.achieved_complete) continue;
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(label.c_str());
      ImGui::TableNextColumn();
      if (is_input) {
        ImGui::Text("%.1f %s", app::to_display(id, core_.state().values.at(id), units),
                    app::unit_label(id, units).c_str());
      } else {
        ImGui::TextDisabled("-");
      }
      ImGui::TableNextColumn();
      ImGui::TextDisabled("...");
      ImGui::TableNextColumn();
      ImGui::TextDisabled("(after the drag)");
      continue;
    }
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(label.c_str());
    ImGui::TableNextColumn();
    const std::string unit = app::unit_label(id, units);
    const double achieved = app::to_display(id, a->second, units);
    if (is_input) {
      const double typed = app::to_display(id, core_.state().values.at(id), units);
      ImGui::Text("%.1f %s", typed, unit.c_str());
      ImGui::TableNextColumn();
      ImGui::Text("%.1f %s", achieved, unit.c_str());
      ImGui::TableNextColumn();
      // Rounded as shown, so that a tiny negative difference does not print as "-0.0".
      const double diff = std::round((achieved - typed) * 10.0) / 10.0 + 0.0;
      // Within half a display unit the avatar matches what was typed.
      const ImVec4 c =
          std::abs(diff) < 0.5 ? ImVec4(0.1f, 0.5f, 0.2f, 1) : ImVec4(0.75f, 0.35f, 0.0f, 1);
      ImGui::TextColored(c, "%+.1f %s", diff, unit.c_str());
    } else {
      ImGui::TextDisabled("-");
      ImGui::TableNextColumn();
      ImGui::Text("%.1f %s", achieved, unit.c_str());
      ImGui::TableNextColumn();
    }
  }
  ImGui::EndTable();
}

void EditorApp::draw_betas() {
  if (!core_.has_model()) return;
  const app::AvatarView& av = core_.avatar();
  const Plausibility& p = av.plausibility;
  const ImVec4 ok(0.1f, 0.55f, 0.2f, 1), warn(0.8f, 0.45f, 0.0f, 1), bad(0.8f, 0.1f, 0.1f, 1);
  const std::string verdict =
      p.plausible ? "Plausible body shape" : "Unusual body shape (outside the usual range)";
  ImGui::TextColored(p.plausible ? ok : bad, "%s", verdict.c_str());
  ImGui::TextWrapped(
      "Distance from the average body (Mahalanobis distance): %.2f. It counts the shape "
      "components b0-b%d in standard deviations (SD) of the population; 0 is the average body.",
      p.mahalanobis, std::max(0, p.dof - 1));
  char share[64];
  if (p.p_value >= 0.001)
    std::snprintf(share, sizeof share, "%.1f %% of people", 100.0 * p.p_value);
  else
    std::snprintf(share, sizeof share, "fewer than 1 in 1000 people");
  ImGui::TextWrapped(
      "p = %.3g: %s have a shape at least this far from the average. A shape is called "
      "plausible when p >= 0.001 and no component is beyond 3 SD.",
      p.p_value, share);
  if (!p.beyond_3sd.empty()) {
    std::string list;
    for (int b : p.beyond_3sd) {
      char buf[48];
      std::snprintf(buf, sizeof buf, "%sb%d (%+.1f SD)", list.empty() ? "" : ", ", b, av.betas(b));
      list += buf;
    }
    ImGui::PushStyleColor(ImGuiCol_Text, bad);
    ImGui::TextWrapped("Beyond 3 SD: %s. Check the typed values in the table above.", list.c_str());
    ImGui::PopStyleColor();
  } else if (!p.beyond_2sd.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, warn);
    ImGui::TextWrapped("%d component(s) beyond 2 SD (uncommon, not implausible).",
                       static_cast<int>(p.beyond_2sd.size()));
    ImGui::PopStyleColor();
  }
  const int k = p.dof;
  for (int b = 0; b < k; ++b) {
    const double v = av.betas(b);
    const ImVec4 c = std::abs(v) > 3 ? bad : std::abs(v) > 2 ? warn : ok;
    char label[64];
    if (av.beta_sd.size() > b) {
      std::snprintf(label, sizeof label, "b%-2d %+6.2f SD (uncertainty %.2f)", b, v, av.beta_sd(b));
    } else {
      std::snprintf(label, sizeof label, "b%-2d %+6.2f SD", b, v);
    }
    ImGui::PushStyleColor(ImGuiCol_PlotHistogram, c);
    ImGui::ProgressBar(static_cast<float>(std::min(1.0, std::abs(v) / 4.0)), ImVec2(120, 0), "");
    ImGui::PopStyleColor();
    ImGui::SameLine();
    ImGui::TextColored(c, "%s", label);
  }
}

void EditorApp::draw_display_section() {
  if (!ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) return;
  app::ViewSettings& vs = core_.view();
  ImGui::Checkbox("wireframe (W)", &vs.wireframe);
  probe_.track("wireframe (W)");
  ImGui::SameLine();
  ImGui::Checkbox("measurements (M)", &vs.overlay);
  probe_.track("measurements (M)");
  ImGui::Checkbox("fixed scale with height ruler (H)", &vs.fixed_scale);
  probe_.track("fixed scale with height ruler (H)");
  int colour = static_cast<int>(vs.colour);
  const char* colours[] = {"skin", "plausibility", "uncertainty (noise-aware)"};
  ImGui::SetNextItemWidth(220);
  if (ImGui::Combo("colour", &colour, colours, 3)) vs.colour = static_cast<app::ColourMode>(colour);
  probe_.track("colour");
  if (button("Pin for comparison")) core_.pin_comparison("pinned");
  ImGui::SameLine();
  const int compare = static_cast<int>(vs.compare);
  const DisabledScope no_comparison(!core_.comparison().has_value());
  if (ImGui::RadioButton("off", compare == 0)) vs.compare = app::CompareMode::Off;
  probe_.track("off");
  ImGui::SameLine();
  if (ImGui::RadioButton("side", compare == 1)) vs.compare = app::CompareMode::SideBySide;
  probe_.track("side");
  ImGui::SameLine();
  if (ImGui::RadioButton("difference", compare == 2)) vs.compare = app::CompareMode::Difference;
  probe_.track("difference");
}

void EditorApp::draw_files() {
  if (button("Open profile...")) start_file_action(FileAction::OpenProfile);
  ImGui::SameLine();
  if (button("Save profile...")) start_file_action(FileAction::SaveProfile);
  ImGui::SameLine();
  if (button("Open session...")) start_file_action(FileAction::OpenSession);
  if (button("Export...", core_.has_model())) start_file_action(FileAction::Export);
  ImGui::SameLine();
  if (button("Screenshot...")) start_file_action(FileAction::Screenshot);
  ImGui::SameLine();
  if (button("Undo", core_.can_undo())) core_.undo();
  ImGui::SameLine();
  if (button("Redo", core_.can_redo())) core_.redo();
  ImGui::SameLine();
  if (button("Reset", core_.has_model())) core_.reset();
  if (button("Quit")) request_quit();
  ImGui::SameLine();
  ImGui::TextDisabled(core_.has_unsaved_changes() ? "unsaved changes" : "all changes saved");
}

void EditorApp::draw_messages() {
  // A status bar along the bottom of the 3D view: the last two messages, wrapped, errors red.
  const auto& msgs = core_.messages();
  if (msgs.empty()) return;
  const ImGuiIO& io = ImGui::GetIO();
  const float left = show_panel_ ? panel_width_ : 0.0f;
  const float width = std::max(100.0f, io.DisplaySize.x - left);
  const size_t first = msgs.size() > 2 ? msgs.size() - 2 : 0;
  ImGui::SetNextWindowPos(ImVec2(left, io.DisplaySize.y - status_height_));
  ImGui::SetNextWindowSize(ImVec2(width, 0));  // height: fitted to the wrapped text
  ImGui::SetNextWindowBgAlpha(0.9f);
  ImGui::Begin("##status", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                   ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoBringToFrontOnFocus);
  ImGui::PushTextWrapPos(width - ImGui::GetStyle().WindowPadding.x);
  for (size_t i = first; i < msgs.size(); ++i) {
    const app::Message& m = msgs[i];
    const ImVec4 c = m.level == app::Message::Level::Error     ? ImVec4(0.8f, 0.1f, 0.1f, 1)
                     : m.level == app::Message::Level::Warning ? ImVec4(0.75f, 0.45f, 0.0f, 1)
                                                               : ImVec4(0.3f, 0.3f, 0.3f, 1);
    ImGui::PushStyleColor(ImGuiCol_Text, c);
    ImGui::TextUnformatted(m.text.c_str());
    ImGui::PopStyleColor();
  }
  ImGui::PopTextWrapPos();
  status_height_ = ImGui::GetWindowHeight();
  ImGui::End();
}

// ---------------------------------------------------------------------------------------------
// Dialogs
void EditorApp::start_file_action(FileAction action) {
  if ((action == FileAction::OpenProfile || action == FileAction::OpenSession) &&
      core_.has_unsaved_changes()) {
    pending_ = action == FileAction::OpenProfile ? Pending::OpenProfile : Pending::OpenSession;
    return;
  }
  open_dialog(action);
}

void EditorApp::open_dialog(FileAction action) {
  dialog_.open(action, file_action_info(action, app::EditorCore::export_extensions()),
               last_folder_);
}

void EditorApp::finish_file_action(FileAction action, const std::string& path) {
  bool ok = true;
  switch (action) {
    case FileAction::OpenProfile:
      ok = core_.open_profile(path);
      break;
    case FileAction::OpenSession:
      ok = core_.open_session(path);
      break;
    case FileAction::OpenModel:
      ok = core_.load_model_file(path);
      break;
    case FileAction::SaveProfile:
      ok = core_.save_profile(path);
      break;
    case FileAction::Export:
      ok = core_.export_mesh(path);
      break;
    case FileAction::Screenshot:
      deferred_screenshot_ = path;  // next frame, without the dialog in the picture
      break;
  }
  if (save_then_continue_ && action == FileAction::SaveProfile) {
    save_then_continue_ = false;
    if (ok) continue_pending();
    pending_ = Pending::None;
  }
}

void EditorApp::continue_pending() {
  const Pending p = pending_;
  pending_ = Pending::None;
  if (p == Pending::Quit) quit_ = true;
  if (p == Pending::OpenProfile) open_dialog(FileAction::OpenProfile);
  if (p == Pending::OpenSession) open_dialog(FileAction::OpenSession);
}

void EditorApp::draw_dialogs() {
  if (dialog_.is_open()) {
    if (const auto chosen = dialog_.draw(probe_)) {
      last_folder_ = dialog_.folder();
      finish_file_action(dialog_.action(), chosen->string());
    } else if (!dialog_.is_open() && save_then_continue_) {
      save_then_continue_ = false;  // the save was cancelled: so is what waited for it
      pending_ = Pending::None;
    }
    return;
  }
  if (pending_ == Pending::None || save_then_continue_) return;
  const char* id = "Unsaved changes###unsaved";
  if (!pending_popup_open_) {
    ImGui::OpenPopup(id);
    pending_popup_open_ = true;
  }
  const ImGuiIO& io = ImGui::GetIO();
  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x / 2, io.DisplaySize.y / 2), ImGuiCond_Appearing,
                          ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(std::min(480.0f, io.DisplaySize.x - 40), 0));
  if (!ImGui::BeginPopupModal(id, nullptr, ImGuiWindowFlags_NoSavedSettings)) {
    pending_popup_open_ = false;
    pending_ = Pending::None;
    return;
  }
  const char* what = pending_ == Pending::Quit          ? "Quitting"
                     : pending_ == Pending::OpenProfile ? "Opening a profile"
                                                        : "Opening a session";
  ImGui::TextWrapped(
      "The measurements changed since they were last saved. %s replaces them. Save them first?",
      what);
  bool close = false;
  const bool save = ImGui::Button("Save profile first...");
  probe_.track("Save profile first...");
  ImGui::SameLine();
  const bool discard = ImGui::Button("Discard changes");
  probe_.track("Discard changes");
  ImGui::SameLine();
  const bool cancel = ImGui::Button("Cancel##unsaved");
  probe_.track("Cancel##unsaved");
  if (save) {
    close = true;
    save_then_continue_ = true;
    dialog_.open(FileAction::SaveProfile,
                 file_action_info(FileAction::SaveProfile, app::EditorCore::export_extensions()),
                 last_folder_);
  } else if (discard) {
    close = true;
    continue_pending();
  } else if (cancel || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape), false)) {
    close = true;
    pending_ = Pending::None;
  }
  if (close) {
    ImGui::CloseCurrentPopup();
    pending_popup_open_ = false;
  }
  ImGui::EndPopup();
}

// ---------------------------------------------------------------------------------------------
// Keyboard shortcuts. Letter and digit keys are GLFW key codes (their ASCII upper-case value),
// which is how Dear ImGui 1.86's GLFW backend fills io.KeysDown.
void EditorApp::handle_shortcuts() {
  const ImGuiIO& io = ImGui::GetIO();
  if (dialog_.is_open() || pending_ != Pending::None) return;  // the dialog takes the keys
  if (io.WantTextInput) return;
  const bool ctrl = io.KeyCtrl;
  auto pressed = [](int key) { return ImGui::IsKeyPressed(key, false); };
  // Esc first closes an open list (ImGui does that); only then it asks to quit.
  const bool popup = ImGui::IsPopupOpen("", ImGuiPopupFlags_AnyPopupId);
  if ((pressed(GLFW_KEY_ESCAPE) && !popup) || (ctrl && pressed(GLFW_KEY_Q))) {
    request_quit();
    return;
  }
  if (ctrl && ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Z))) {
    if (io.KeyShift)
      core_.redo();
    else
      core_.undo();
  }
  if (ctrl && ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Y))) core_.redo();
  if (ctrl && pressed(GLFW_KEY_S)) start_file_action(FileAction::SaveProfile);
  if (ctrl && pressed(GLFW_KEY_O)) start_file_action(FileAction::OpenProfile);
  if (ctrl && pressed(GLFW_KEY_E) && core_.has_model()) start_file_action(FileAction::Export);
  if (ctrl && pressed(GLFW_KEY_P)) start_file_action(FileAction::Screenshot);
  if (ctrl) return;
  if (pressed(GLFW_KEY_W)) core_.view().wireframe = !core_.view().wireframe;
  if (pressed(GLFW_KEY_M)) core_.view().overlay = !core_.view().overlay;
  if (pressed(GLFW_KEY_H)) core_.view().fixed_scale = !core_.view().fixed_scale;
  if (pressed(GLFW_KEY_U)) {
    core_.view().units = core_.view().units == app::UnitSystem::Metric ? app::UnitSystem::Imperial
                                                                       : app::UnitSystem::Metric;
  }
  if (pressed(GLFW_KEY_1)) core_.set_level(1);
  if (pressed(GLFW_KEY_2)) core_.set_level(2);
  if (pressed(GLFW_KEY_3)) core_.set_level(3);
  if (pressed(GLFW_KEY_F)) camera_.azimuth_degrees = 0;
  if (pressed(GLFW_KEY_S)) camera_.azimuth_degrees = 90;
  if (ImGui::IsKeyDown(GLFW_KEY_LEFT)) camera_.azimuth_degrees -= 90 * io.DeltaTime;
  if (ImGui::IsKeyDown(GLFW_KEY_RIGHT)) camera_.azimuth_degrees += 90 * io.DeltaTime;
  if (ImGui::IsKeyDown(GLFW_KEY_UP))
    camera_.zoom = std::min(10.0f, camera_.zoom * (1 + io.DeltaTime));
  if (ImGui::IsKeyDown(GLFW_KEY_DOWN))
    camera_.zoom = std::max(0.2f, camera_.zoom / (1 + io.DeltaTime));
}

}  // namespace caliper::editor
