// caliper-editor: type or drag body measurements and watch the avatar (Pujades et al., The
// Virtual Caliper, TVCG 2019, Sec. 4). A GLFW window with Dear ImGui, or --headless: a scripted
// run under OSMesa that writes a screenshot (tests and docs). See docs/editor.md.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/cli_style.hpp"
#include "app/editor_core.hpp"
#include "caliper/assets.hpp"
#include "config.hpp"
#include "editor_app.hpp"
#include "key_taps.hpp"
#include "render/glfw_context.hpp"
#include "render/render_mesh.hpp"

namespace {

namespace fs = std::filesystem;
using caliper::app::EditorCore;

struct Options {
  bool headless = false;
  std::string script;
  int frames = -1;  // -1: run until closed (window) / 2 (headless)
  std::string screenshot;
  int width = 0, height = 0;
  std::vector<std::string> models;
  std::string models_dir;
  bool no_open_models = false;
  bool strict = false;
  bool no_config = false;
  double exit_after = -1;     // seconds of wall time, then quit (benchmarks); < 0: never
  bool no_idle_wait = false;  // draw every frame even when nothing changes (benchmark baseline)
};

/// The options on a CLI11 app in the programs' common style (app/cli_style.hpp).
void declare_options(CLI::App& cli, Options& o, std::string& size) {
  namespace app = caliper::app;
  app::apply_style(cli, {{"caliper-editor [options]"},
                         "Type or drag body measurements and watch the avatar (docs/editor.md).",
                         "examples:\n"
                         "  caliper-editor\n"
                         "  caliper-editor --headless --script demo.txt --screenshot shot.png\n\n"
                         "exit codes: 0 ok, 1 a script command failed (--strict), 2 error"});
  app::add_value(cli, "--model", o.models, "FILE",
                 "open an SMPL-family or project .npz/.pkl model (repeatable)", true);
  app::add_value(cli, "--models-dir", o.models_dir, "DIR",
                 "folder with the open models caliper-{female,male,neutral}.npz\n"
                 "(default: models/ in $CALIPER_ASSETS, the build tree or the\n"
                 "install prefix's share/virtual-caliper/assets)");
  app::add_flag(cli, "--no-open-models", o.no_open_models, "do not look for the open models");
  app::add_flag(cli, "--headless", o.headless, "no window: render off-screen with OSMesa");
  app::add_value(cli, "--script", o.script, "FILE",
                 "run editor commands from FILE, one per frame (docs/editor.md)");
  app::add_value(cli, "--frames", o.frames, "N",
                 "stop after N frames (after the script) (default: run until closed; 2 headless)")
      ->check(app::non_negative());
  app::add_value(cli, "--screenshot", o.screenshot, "PNG", "write the last frame to PNG");
  app::add_value(cli, "--size", size, "WxH",
                 "window / image size in pixels, each side at least 64\n"
                 "(default 1600x1000 or the remembered size)")
      ->check([](const std::string& s) {
        int w = 0, h = 0;
        char end = 0;
        return std::sscanf(s.c_str(), "%dx%d%c", &w, &h, &end) == 2 && w >= 64 && h >= 64
                   ? std::string()
                   : "expects WIDTHxHEIGHT in pixels, each at least 64, e.g. 1600x1000";
      });
  app::add_flag(cli, "--strict", o.strict, "exit with status 1 if a script command failed");
  app::add_flag(cli, "--no-config", o.no_config, "neither read nor write the settings file");
  app::add_value(cli, "--exit-after", o.exit_after, "SECONDS",
                 "quit after this much wall time (benchmarks) (default: never)")
      ->check(app::non_negative());
  app::add_flag(cli, "--no-idle-wait", o.no_idle_wait,
                "redraw continuously instead of waiting for input (benchmarks)");
}

/// Reads the command line into `o`; false when it asked for --help (then printed). Throws
/// app::CommandLineError naming what was wrong.
bool parse(int argc, char** argv, Options& o) {
  CLI::App cli("", "caliper-editor");
  std::string size;
  declare_options(cli, o, size);
  const caliper::app::CommandLine line =
      caliper::app::parse_command_line(cli, std::vector<std::string>(argv + 1, argv + argc));
  if (line.help) {
    std::fputs(cli.help().c_str(), stdout);
    return false;
  }
  caliper::app::no_positional(line);
  if (!size.empty()) std::sscanf(size.c_str(), "%dx%d", &o.width, &o.height);
  return true;
}

/// Folders searched for the open models, in order: --models-dir, then the models/ folder of the
/// project's assets (caliper::find_assets_dir(): $CALIPER_ASSETS, the build tree, the install
/// prefix), as for the caliper command.
std::vector<fs::path> model_dirs(const Options& o) {
  std::vector<fs::path> dirs;
  if (!o.models_dir.empty()) dirs.emplace_back(o.models_dir);
  if (const auto assets = caliper::find_assets_dir()) dirs.push_back(fs::path(*assets) / "models");
  return dirs;
}

void load_models(EditorCore& core, const Options& o) {
  for (const std::string& m : o.models) core.load_model_file(m);
  if (o.no_open_models || !o.models.empty()) return;
  for (const fs::path& dir : model_dirs(o)) {
    bool any = false;
    for (const char* sex : {"female", "male", "neutral"}) {
      const fs::path p = caliper::default_model_path(dir.string(), sex);
      if (fs::exists(p)) {
        any = true;
        const int before = core.current_model();
        if (core.load_model_file(p.string()) && before >= 0) core.select_model(before);
      }
    }
    if (any) return;
  }
  core.post(caliper::app::Message::Level::Warning,
            "no open model found (models/caliper-*.npz in --models-dir or the assets folder; "
            "set CALIPER_ASSETS): open a model file");
}

std::vector<std::string> read_script(const std::string& path) {
  std::vector<std::string> lines;
  if (path.empty()) return lines;
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot open script " + path);
  std::string line;
  while (std::getline(f, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    lines.push_back(line.substr(first));
  }
  return lines;
}

/// Runs line `frame` of `script` (nothing when the script is shorter); when the command fails,
/// prints the core's message on stderr and returns false.
bool run_script_line(caliper::editor::EditorApp& app, const EditorCore& core,
                     const std::vector<std::string>& script, int frame) {
  if (frame >= static_cast<int>(script.size()) ||
      app.run_command(script[static_cast<size_t>(frame)]))
    return true;
  std::fprintf(stderr, "caliper-editor: %s\n", core.messages().back().text.c_str());
  return false;
}

int run_headless(EditorCore& core, const Options& o, const std::vector<std::string>& script) {
  const int w = o.width > 0 ? o.width : 1600, h = o.height > 0 ? o.height : 1000;
  caliper::render::OffscreenRenderer off(w, h, 4);
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;
  io.DisplaySize = ImVec2(static_cast<float>(w), static_cast<float>(h));
  io.DeltaTime = 1.0f / 60.0f;
  caliper::editor::set_glfw_key_map(io);
  int failures = 0;
  {
    caliper::editor::EditorApp app(core, off.context().gl());
    const int frames = static_cast<int>(script.size()) + (o.frames >= 0 ? o.frames : 2);
    for (int f = 0; f < frames; ++f) {
      if (!run_script_line(app, core, script, f)) ++failures;
      off.bind();
      app.frame(w, h);
      off.resolve();
      if (!app.screenshot_request().empty()) {
        caliper::render::write_png(off.context().read_pixels(), app.screenshot_request());
        app.screenshot_request().clear();
      }
    }
    if (!o.screenshot.empty())
      caliper::render::write_png(off.context().read_pixels(), o.screenshot);
  }
  ImGui::DestroyContext();
  return (o.strict && failures > 0) ? 1 : 0;
}

// Input glue for the window. Dear ImGui 1.86 reads the key state once per frame (io.KeysDown),
// so a key pressed and released between two frames (a quick Enter tap) would never be seen
// down: such releases are held back until the frame after the press. Every input event also
// marks the loop busy, so it draws a few frames and then waits for the next event.
struct InputGlue {
  GLFWkeyfun imgui_key = nullptr;
  GLFWcharfun imgui_char = nullptr;
  GLFWmousebuttonfun imgui_button = nullptr;
  GLFWscrollfun imgui_scroll = nullptr;
  GLFWcursorposfun prev_cursor = nullptr;
  caliper::editor::KeyTaps taps;
  bool event = false;
};
InputGlue g_input;

void on_key(GLFWwindow* w, int key, int scancode, int action, int mods) {
  g_input.event = true;
  if (!g_input.taps.on_key(key, scancode, action, mods)) return;
  if (g_input.imgui_key) g_input.imgui_key(w, key, scancode, action, mods);
}
void on_char(GLFWwindow* w, unsigned int c) {
  g_input.event = true;
  if (g_input.imgui_char) g_input.imgui_char(w, c);
}
void on_button(GLFWwindow* w, int button, int action, int mods) {
  g_input.event = true;
  if (g_input.imgui_button) g_input.imgui_button(w, button, action, mods);
}
void on_scroll(GLFWwindow* w, double x, double y) {
  g_input.event = true;
  if (g_input.imgui_scroll) g_input.imgui_scroll(w, x, y);
}
void on_cursor(GLFWwindow* w, double x, double y) {
  g_input.event = true;
  if (g_input.prev_cursor) g_input.prev_cursor(w, x, y);
}
void on_window(GLFWwindow*) {
  g_input.event = true;
}
void on_size(GLFWwindow*, int, int) {
  g_input.event = true;
}

/// Frames drawn after an input event before the loop waits again (ImGui settles hover states,
/// popups and auto-sized windows within two or three frames).
constexpr int kFramesAfterInput = 4;
/// The longest wait without an event (seconds): the loop wakes up, finds nothing to do and
/// waits again without drawing.
constexpr double kIdleWakeSeconds = 0.5;

/// A remembered or default size larger than the screen (1600x1000 on a 1366x768 laptop) would
/// put the panel's bottom and the status bar off-screen: shrinks the window to the primary
/// monitor's work area (w x h: its current size).
void fit_to_work_area(GLFWwindow* win, int w, int h) {
  GLFWmonitor* monitor = glfwGetPrimaryMonitor();
  if (!monitor) return;
  int x = 0, y = 0, area_w = 0, area_h = 0;
  glfwGetMonitorWorkarea(monitor, &x, &y, &area_w, &area_h);
  // Room for the window manager's title bar and borders.
  constexpr int kDecoration = 40;
  if (area_w > 0 && area_h > kDecoration && (w > area_w || h > area_h - kDecoration)) {
    glfwSetWindowSize(win, std::min(w, area_w), std::min(h, area_h - kDecoration));
    glfwSetWindowPos(win, x, y + kDecoration / 2);
  }
}

/// Puts the input glue (g_input) between GLFW and ImGui's callbacks, which must be installed.
void install_input_glue(GLFWwindow* win) {
  g_input.imgui_key = glfwSetKeyCallback(win, on_key);
  g_input.imgui_char = glfwSetCharCallback(win, on_char);
  g_input.imgui_button = glfwSetMouseButtonCallback(win, on_button);
  g_input.imgui_scroll = glfwSetScrollCallback(win, on_scroll);
  g_input.prev_cursor = glfwSetCursorPosCallback(win, on_cursor);
  glfwSetWindowRefreshCallback(win, on_window);
  glfwSetFramebufferSizeCallback(win, on_size);
}

/// Mouse input that ImGui's windows did not take: a left drag orbits, the wheel zooms.
void mouse_to_camera(caliper::editor::EditorApp& app, const ImGuiIO& io) {
  if (!io.WantCaptureMouse && ImGui::IsMouseDragging(ImGuiMouseButton_Left)) {
    app.orbit(io.MouseDelta.x, io.MouseDelta.y);
  }
  if (!io.WantCaptureMouse && io.MouseWheel != 0) {
    app.camera().zoom *= io.MouseWheel > 0 ? 1.1f : 1 / 1.1f;
  }
}

/// Writes the screenshot the app asked for (if any) from the window and posts the outcome to the
/// core; returns true when there was a request.
bool save_requested_screenshot(caliper::render::GlfwWindowContext& window,
                               caliper::editor::EditorApp& app, EditorCore& core) {
  if (app.screenshot_request().empty()) return false;
  try {
    caliper::render::write_png(window.read_pixels(), app.screenshot_request());
    core.post(caliper::app::Message::Level::Info, "saved screenshot " + app.screenshot_request());
  } catch (const std::exception& e) {
    core.post(caliper::app::Message::Level::Error,
              "could not save the screenshot " + app.screenshot_request() + ": " + e.what());
  }
  app.screenshot_request().clear();
  return true;
}

/// Draws the window's frames until it is closed, quit, --exit-after has passed since `started`,
/// or the script and --frames are done; returns the number of failed script lines.
int window_loop(caliper::render::GlfwWindowContext& window, caliper::editor::EditorApp& app,
                EditorCore& core, const Options& o, const std::vector<std::string>& script,
                std::chrono::steady_clock::time_point started) {
  GLFWwindow* win = window.window();
  ImGuiIO& io = ImGui::GetIO();
  int failures = 0;
  int frame = 0;
  int busy = kFramesAfterInput;
  std::uint64_t seen_revision = core.revision();
  size_t seen_messages = core.messages().size();
  while (true) {
    const bool scripted = frame < static_cast<int>(script.size()) || o.frames >= 0;
    if (busy > 0 || scripted || o.no_idle_wait || app.animating()) {
      glfwPollEvents();
    } else {
      glfwWaitEventsTimeout(kIdleWakeSeconds);
    }
    if (g_input.event) {
      busy = kFramesAfterInput;
      g_input.event = false;
    }
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (o.exit_after >= 0 && elapsed >= o.exit_after) break;
    if (window.should_close()) {  // the close button: ask first when work is unsaved
      glfwSetWindowShouldClose(win, GLFW_FALSE);
      app.request_quit();
      busy = kFramesAfterInput;
    }
    if (app.quit_requested()) break;
    if (busy <= 0 && !scripted && !o.no_idle_wait && !app.animating()) continue;
    ImGui_ImplGlfw_NewFrame();
    io.DeltaTime = std::min(io.DeltaTime, 1.0f / 20.0f);  // no jump after an idle wait
    if (!run_script_line(app, core, script, frame)) ++failures;
    mouse_to_camera(app, io);
    app.frame(window.width(), window.height());
    ++frame;
    --busy;
    // Releases held back for a quick tap reach ImGui now, after it saw the key down.
    for (const caliper::editor::KeyTaps::Key& k : g_input.taps.frame_done()) {
      if (g_input.imgui_key) g_input.imgui_key(win, k.key, k.scancode, GLFW_RELEASE, k.mods);
      busy = std::max(busy, 2);
    }
    if (core.revision() != seen_revision || core.messages().size() != seen_messages) {
      seen_revision = core.revision();
      seen_messages = core.messages().size();
      busy = std::max(busy, 2);
    }
    const bool last = o.frames >= 0 && frame >= static_cast<int>(script.size()) + o.frames;
    if (save_requested_screenshot(window, app, core)) busy = std::max(busy, 2);
    if (last && !o.screenshot.empty())
      caliper::render::write_png(window.read_pixels(), o.screenshot);
    window.swap_buffers();
    if (last) break;
  }
  return failures;
}

/// The editor in a window (GLFW, ImGui), with the saved configuration (units, window size)
/// read at the start and written at the end. Returns the exit status.
int run_window(EditorCore& core, const Options& o, const std::vector<std::string>& script) {
  const std::string cfg_path = o.no_config ? "" : caliper::editor::config_path();
  caliper::editor::EditorConfig cfg = caliper::editor::load_config(cfg_path);
  if (auto u = caliper::app::parse_unit_system(cfg.units)) core.view().units = *u;
  const int w = o.width > 0 ? o.width : cfg.window_width;
  const int h = o.height > 0 ? o.height : cfg.window_height;
  caliper::render::GlfwWindowContext window(w, h, "The Virtual Caliper - editor");
  if (o.width <= 0) fit_to_work_area(window.window(), w, h);
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui_ImplGlfw_InitForOpenGL(window.window(), true);
  install_input_glue(window.window());
  const auto started = std::chrono::steady_clock::now();
  int failures = 0;
  {
    caliper::editor::EditorApp app(core, window.gl());
    failures = window_loop(window, app, core, o, script, started);
    window.window_size(cfg.window_width, cfg.window_height);
    cfg.units = caliper::app::to_string(core.view().units);
    if (!cfg_path.empty()) caliper::editor::save_config(cfg_path, cfg);
  }
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  return (o.strict && failures > 0) ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    Options o;
    try {
      if (!parse(argc, argv, o)) return 0;
    } catch (const caliper::app::CommandLineError& e) {
      std::fputs(caliper::app::usage_error_line("caliper-editor", e.what()).c_str(), stderr);
      return 2;
    }
    const std::vector<std::string> script = read_script(o.script);
    EditorCore core;
    load_models(core, o);
    return o.headless ? run_headless(core, o, script) : run_window(core, o, script);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "caliper-editor: %s\n", e.what());
    return 2;
  }
}
