// caliper-editor: type or drag body measurements and watch the avatar (Pujades et al., The
// Virtual Caliper, TVCG 2019, Sec. 4). A GLFW window with Dear ImGui, or --headless: a scripted
// run under OSMesa that writes a screenshot (tests and docs). See docs/editor.md.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <imgui.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/editor_core.hpp"
#include "caliper/assets.hpp"
#include "config.hpp"
#include "editor_app.hpp"
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
};

void usage() {
  std::printf(
      "usage: caliper-editor [options]\n"
      "  --model FILE          open an SMPL-family or project .npz/.pkl model (repeatable)\n"
      "  --models-dir DIR      folder with the open models caliper-{female,male,neutral}.npz\n"
      "                        (default: models/ in $CALIPER_ASSETS, the build tree or the\n"
      "                        install prefix's share/virtual-caliper/assets)\n"
      "  --no-open-models      do not look for the open models\n"
      "  --headless            no window: render off-screen with OSMesa\n"
      "  --script FILE         run editor commands from FILE, one per frame (docs/editor.md)\n"
      "  --frames N            stop after N frames (after the script)\n"
      "  --screenshot PNG      write the last frame to PNG\n"
      "  --size WxH            window / image size (default 1600x1000 or the remembered size)\n"
      "  --strict              exit with status 1 if a script command failed\n"
      "  --no-config           neither read nor write the settings file\n");
}

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    if (a == "--headless")
      o.headless = true;
    else if (a == "--script")
      o.script = next();
    else if (a == "--frames")
      o.frames = std::stoi(next());
    else if (a == "--screenshot")
      o.screenshot = next();
    else if (a == "--model")
      o.models.push_back(next());
    else if (a == "--models-dir")
      o.models_dir = next();
    else if (a == "--no-open-models")
      o.no_open_models = true;
    else if (a == "--strict")
      o.strict = true;
    else if (a == "--no-config")
      o.no_config = true;
    else if (a == "--size") {
      const std::string s = next();
      if (std::sscanf(s.c_str(), "%dx%d", &o.width, &o.height) != 2 || o.width < 64 ||
          o.height < 64) {
        throw std::invalid_argument("--size expects WIDTHxHEIGHT, e.g. 1600x1000");
      }
    } else if (a == "--help" || a == "-h") {
      usage();
      return false;
    } else {
      throw std::invalid_argument("unknown option " + a + " (see --help)");
    }
  }
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
      const fs::path p = dir / (std::string("caliper-") + sex + ".npz");
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

int run_headless(EditorCore& core, const Options& o, const std::vector<std::string>& script) {
  const int w = o.width > 0 ? o.width : 1600, h = o.height > 0 ? o.height : 1000;
  caliper::render::OffscreenRenderer off(w, h, 4);
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;
  io.DisplaySize = ImVec2(static_cast<float>(w), static_cast<float>(h));
  io.DeltaTime = 1.0f / 60.0f;
  int failures = 0;
  {
    caliper::editor::EditorApp app(core, off.context().gl());
    const int frames = static_cast<int>(script.size()) + (o.frames >= 0 ? o.frames : 2);
    for (int f = 0; f < frames; ++f) {
      if (f < static_cast<int>(script.size()) && !app.run_command(script[static_cast<size_t>(f)])) {
        ++failures;
        std::fprintf(stderr, "caliper-editor: %s\n", core.messages().back().text.c_str());
      }
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

int run_window(EditorCore& core, const Options& o, const std::vector<std::string>& script) {
  const std::string cfg_path = o.no_config ? "" : caliper::editor::config_path();
  caliper::editor::EditorConfig cfg = caliper::editor::load_config(cfg_path);
  if (auto u = caliper::app::parse_unit_system(cfg.units)) core.view().units = *u;
  const int w = o.width > 0 ? o.width : cfg.window_width;
  const int h = o.height > 0 ? o.height : cfg.window_height;
  caliper::render::GlfwWindowContext window(w, h, "The Virtual Caliper - editor");
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;
  ImGui_ImplGlfw_InitForOpenGL(window.window(), true);
  int failures = 0;
  {
    caliper::editor::EditorApp app(core, window.gl());
    int frame = 0;
    while (!window.should_close()) {
      glfwPollEvents();
      ImGui_ImplGlfw_NewFrame();
      if (frame < static_cast<int>(script.size()) &&
          !app.run_command(script[static_cast<size_t>(frame)])) {
        ++failures;
        std::fprintf(stderr, "caliper-editor: %s\n", core.messages().back().text.c_str());
      }
      if (!io.WantCaptureMouse && ImGui::IsMouseDragging(ImGuiMouseButton_Left)) {
        app.orbit(io.MouseDelta.x, io.MouseDelta.y);
      }
      if (!io.WantCaptureMouse && io.MouseWheel != 0) {
        app.camera().zoom *= io.MouseWheel > 0 ? 1.1f : 1 / 1.1f;
      }
      app.frame(window.width(), window.height());
      ++frame;
      const bool last = o.frames >= 0 && frame >= static_cast<int>(script.size()) + o.frames;
      if (!app.screenshot_request().empty()) {
        caliper::render::write_png(window.read_pixels(), app.screenshot_request());
        core.post(caliper::app::Message::Level::Info, "screenshot " + app.screenshot_request());
        app.screenshot_request().clear();
      }
      if (last && !o.screenshot.empty())
        caliper::render::write_png(window.read_pixels(), o.screenshot);
      window.swap_buffers();
      if (last) break;
    }
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
    if (!parse(argc, argv, o)) return 0;
    const std::vector<std::string> script = read_script(o.script);
    EditorCore core;
    load_models(core, o);
    return o.headless ? run_headless(core, o, script) : run_window(core, o, script);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "caliper-editor: %s\n", e.what());
    return 2;
  }
}
