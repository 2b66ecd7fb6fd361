// The live app on OpenXR (see openxr_system.hpp): the pivot calibration of a controller tip, or
// a measuring session with the optional operator window and recording.
#include "openxr_system.hpp"

#include <cstdio>
#include <iostream>

#include "controller_config.hpp"
#include "openxr_graphics_gl.hpp"
#include "openxr_program.hpp"
#include "operator_window.hpp"
#include "pivot.hpp"

namespace caliper::vr {
namespace {

/// The pivot calibration live: until the trigger is released after a long enough hold.
int run_pivot_calibration(const LiveOptions& o, OpenXrProgram& xr) {
  if (o.calibrate_tip != "left" && o.calibrate_tip != "right")
    throw std::invalid_argument("--calibrate-tip needs left or right");
  std::cout << "Pivot calibration of the " << o.calibrate_tip
            << " controller: rest its tip on a fixed point, hold the trigger, and rotate the "
               "controller for "
               "five seconds while the tip stays put. Release the trigger to finish.\n";
  PivotCollector pivot(o.calibrate_tip == "left" ? Tip::Left : Tip::Right);
  render::Scene empty;
  while (std::optional<PoseFrame> f = xr.next_frame()) {
    std::optional<PivotCalibration> r = pivot.feed(*f);
    xr.submit(empty);
    if (!r) continue;
    ControllerConfig cc = read_controller_config(o.controllers_path);
    TipOffsets t = cc.offsets(xr.interaction_profile());
    (o.calibrate_tip == "left" ? t.left : t.right) = r->tip_offset;
    cc.profiles[xr.interaction_profile()] = t;
    write_controller_config(o.controllers_path, cc);
    std::printf(
        "tip offset %.4f %.4f %.4f m, RMS residual %.2f mm over %d poses (%.0f degrees of "
        "rotation); "
        "saved for %s in %s\n",
        r->tip_offset.x(), r->tip_offset.y(), r->tip_offset.z(), r->rms_residual * 1e3,
        r->num_samples, r->max_rotation_degrees, xr.interaction_profile().c_str(),
        o.controllers_path.c_str());
    return 0;
  }
  return 3;
}

/// The measuring session live, until the user ends it, the runtime quits or is lost.
int run_session(const LiveOptions& o, std::unique_ptr<OpenXrProgram> program,
                OpenGlXlibGraphics& gl) {
  OpenXrProgram& xr = *program;
  VrAppOptions ao = o.make_app_options(xr.interaction_profile());
  const std::string journal = ao.journal_path;
  std::unique_ptr<Audio> audio = o.open_audio();
  VrApp app(std::move(ao), *audio, &gl.renderer());
  PoseSource* source = &xr;
  std::unique_ptr<RecordingPoseSource> recorder;
  if (!o.record_path.empty()) {
    PoseLogHeader h;  // profile and frame rate are filled in with the first frame
    h.role = o.role;
    h.source = "openxr";
    h.weight = o.weight;
    h.sex = o.sex;
    recorder = std::make_unique<RecordingPoseSource>(std::move(program), o.record_path, h);
    source = recorder.get();
  }
  std::optional<OperatorWindow> window;
  if (o.operator_window) window.emplace(gl.window());
  render::Scene scene;
  const ControllerConfig controllers = read_controller_config(o.controllers_path);
  std::string profile = xr.interaction_profile();
  try {
    while (std::optional<PoseFrame> f = source->next_frame()) {
      if (xr.interaction_profile() != profile) {  // the runtime told us which controllers are used
        profile = xr.interaction_profile();
        app.set_tips(controllers.offsets(profile));
      }
      app.advance(*f, source);
      app.build_scene(scene);
      xr.submit(scene);
      if (window)
        for (const OperatorCommand& c : window->frame(app, gl.renderer(), scene)) {
          if (recorder) recorder->record_command(c);
          app.command(c);
        }
      if (window) gl.window().swap_buffers();
      if (app.finished()) o.write_outputs(app);
      if (app.end_requested()) break;
    }
  } catch (const PoseSourceLost& e) {
    // Like the end of the pose source: the journal holds every accepted sample.
    std::cerr << "caliper-vr: " << e.what() << "\n";
    if (recorder) recorder->mark_lost(e.what());
  }
  return o.finish(app, *audio, journal);
}

}  // namespace

int run_openxr(const LiveOptions& o) {
  std::unique_ptr<OpenGlXlibGraphics> graphics = OpenGlXlibGraphics::create(o.operator_window);
  OpenGlXlibGraphics& gl = *graphics;
  auto program = std::make_unique<OpenXrProgram>(std::move(graphics));
  if (!o.calibrate_tip.empty()) return run_pivot_calibration(o, *program);
  return run_session(o, std::move(program), gl);
}

}  // namespace caliper::vr
