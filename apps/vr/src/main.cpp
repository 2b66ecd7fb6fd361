// caliper-vr: the VR measuring app (docs/vr.md).
//   caliper-vr [options]                 OpenXR (a headset and a runtime: SteamVR, Monado, ...)
//   caliper-vr --replay LOG [options]    the same app driven by a pose log, headless (OSMesa)
//   caliper-vr --simulate LOG [options]  writes the pose log of a simulated person

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "app/cli_style.hpp"
#include "caliper/assets.hpp"
#include "caliper/cpu_time.hpp"
#include "caliper/errors.hpp"
#include "caliper/measurements.hpp"
#include "caliper/protocol.hpp"
#include "caliper/simulator.hpp"
#include "controller_config.hpp"
#include "openxr_system.hpp"
#include "operator_window.hpp"
#include "pivot.hpp"
#include "render/context.hpp"
#include "render/glfw_context.hpp"
#include "render/renderer.hpp"
#include "smpl/atomic_file.hpp"
#include "smpl/io.hpp"
#include "vr_app.hpp"

namespace {

using namespace caliper;
using namespace caliper::vr;

constexpr int kExitError = 1;
constexpr int kExitUsage = 2;
constexpr int kExitIncomplete = 3;
constexpr int kExitNoRuntime = 4;

struct Args {
  std::map<std::string, std::string> values;
  std::vector<std::string> flags;
  std::vector<std::string> argv;  ///< the arguments as given (for the --resume command)
  bool has(const std::string& k) const {
    return values.count(k) || std::count(flags.begin(), flags.end(), k);
  }
  std::string get(const std::string& k, const std::string& fallback = "") const {
    auto it = values.find(k);
    return it == values.end() ? fallback : it->second;
  }
};

/// One option of caliper-vr: its name, value name ("" for a flag), help group and description.
struct VrOption {
  const char* name;
  const char* value;
  const char* group;
  const char* help;
};

const VrOption kOptions[] = {
    {"--replay", "FILE", "options", "replay a pose log headless (no headset, no display)"},
    {"--simulate", "FILE", "options",
     "write the pose log of a simulated person doing the protocol"},
    {"--calibrate-tip", "HAND", "options",
     "measure the tip offset of the left/right controller (pivot calibration)"},
    {"--assets", "DIR", "options",
     "the project's assets (default: $CALIPER_ASSETS, else the build\ntree's or the install "
     "prefix's share/virtual-caliper/assets)"},
    {"--protocol", "FILE", "options",
     "measuring protocol (default: assets/protocol/virtual-caliper.json)"},
    {"--controllers", "FILE", "options",
     "tip offsets per interaction profile (default: assets/protocol/controllers.json)"},
    {"--role", "self|operator", "options", "who measures (default: the log's role, else self)"},
    {"--journal", "FILE", "options",
     "session journal (default: OUT/journal.jsonl, or ./caliper-journal.jsonl)"},
    {"--resume", "FILE", "options", "continue the session of this journal where it stopped"},
    {"--force", "", "options",
     "start a new session even when the journal (or the --record) file\nexists (it is "
     "overwritten; without --force caliper-vr refuses and\nnames --resume)"},
    {"--out", "DIR", "options", "write DIR/session.json and DIR/avatar.glb at the end"},
    {"--record", "FILE", "options", "record every frame's poses and buttons as a pose log"},
    {"--weight", "KG", "options",
     "typed weight in kg, 10 to 300 (else from the operator window or the log;\n--simulate: the "
     "simulated person's weight, default 65)"},
    {"--sex", "female|male", "options",
     "typed sex (else from the operator window or the log; --simulate: default female)"},
    {"--model", "FILE", "options", "body model (default: DIR/caliper-<sex>.npz)"},
    {"--models-dir", "DIR", "options", "folder of the body models (default: assets/models)"},
    {"--regressor", "R2|R4|R5|R6", "options", "regressor (default R5)"},
    {"--regressors", "FILE", "options", "fitted regressors (JSON, caliper train --save)"},
    {"--mapping", "FILE", "options", "measurement mapping (JSON or CSV)"},
    {"--max-frames", "N", "options", "stop after N frames (a simulated crash)"},
    {"--no-audio", "", "options", "no confirmation tones"},
    {"--operator-window", "", "options",
     "also open the operator's desktop window (replay: instead of OSMesa;\nneeds a display, "
     "e.g. xvfb-run)"},
    {"--eye-size", "WxH", "replay", "size of each eye's image in pixels (default 320x356)"},
    {"--draw-every", "N", "replay", "rasterise every N-th frame (default 1; 0 = only snapshots)"},
    {"--frames-dir", "DIR", "replay", "save key frames as PNG (floor targets, panel, mirror)"},
    {"--timing", "FILE", "replay", "per-frame CPU times as CSV"},
    {"--embodiment-report", "FILE", "replay", "how well the avatar followed the tracking (JSON)"},
    {"--betas", "\"b0 b1 ...\"", "simulation (--simulate)",
     "the simulated person's shape components, space-separated (default: all 0)"},
    {"--noise", "M", "simulation (--simulate)",
     "controller tip noise, standard deviation per axis in metres (default 0)"},
    {"--seed", "N", "simulation (--simulate)", "random seed (default 1)"},
    {"--frame-rate", "HZ", "simulation (--simulate)", "frames per second (default 90)"},
    {"--dropout", "STEP", "simulation (--simulate)",
     "the step whose first hold loses one controller's tracking for 0.15 s"},
    {"--third-take", "STEP", "simulation (--simulate)",
     "the step whose second take is 3 % too long, so that a third is asked for"},
    {"--early-release", "STEP", "simulation (--simulate)",
     "the step whose first hold is released after 0.4 s"},
    {"--redo", "STEP", "simulation (--simulate)",
     "operator role: the step after whose first take the operator presses redo"},
    {"--profile", "PATH", "simulation (--simulate)",
     "the controllers' interaction profile (default: the HTC Vive wand)"},
    {"--typed-in-log", "yes|no", "simulation (--simulate)",
     "write the typed weight and sex into the log (default yes)"},
    {"--motions", "", "simulation (--simulate)",
     "after the measurements: wave, reach up, cross arms, squat, turn\n(every simulated "
     "session ends with the right controller's menu button)"},
};

/// Reads the command line with CLI11 in the programs' common style (app/cli_style.hpp).
/// Returns false when it asked for --help (then printed); throws app::CommandLineError.
bool parse_args(int argc, char** argv, Args& a) {
  CLI::App cli("", "caliper-vr");
  caliper::app::apply_style(
      cli, {{"caliper-vr [options]                 measure with a headset through OpenXR",
             "caliper-vr --replay LOG [options]    replay a pose log, headless (OSMesa)",
             "caliper-vr --simulate LOG [options]  write the pose log of a simulated person"},
            "The VR measuring app (docs/vr.md).",
            "exit codes: 0 ok, 1 error, 2 usage error, 3 session not finished (resume it),\n"
            "4 no OpenXR runtime"});
  std::map<std::string, std::string> values;  // node-based: CLI11 keeps references
  std::map<std::string, bool> flags;
  for (const VrOption& o : kOptions) {
    CLI::Option* opt = *o.value
                           ? caliper::app::add_value(cli, o.name, values[o.name], o.value, o.help)
                           : caliper::app::add_flag(cli, o.name, flags[o.name], o.help);
    opt->group(o.group);
  }
  const caliper::app::CommandLine line =
      caliper::app::parse_command_line(cli, std::vector<std::string>(argv + 1, argv + argc));
  if (line.help) {
    std::cout << cli.help();
    return false;
  }
  caliper::app::no_positional(line);
  // The arguments as given, "--name=value" as "--name value" (resume_command() copies them).
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const size_t eq = arg.find('=');
    if (arg.rfind("--", 0) != 0 || eq == std::string::npos) {
      a.argv.push_back(arg);
    } else {
      a.argv.push_back(arg.substr(0, eq));
      a.argv.push_back(arg.substr(eq + 1));
    }
  }
  for (const VrOption& o : kOptions) {
    if (cli.get_option(o.name)->count() == 0) continue;
    if (*o.value)
      a.values[o.name] = values[o.name];
    else
      a.flags.emplace_back(o.name);
  }
  return true;
}

double number(const Args& a, const std::string& k, double fallback) {
  if (!a.values.count(k)) return fallback;
  try {
    size_t used = 0;
    const double v = std::stod(a.get(k), &used);
    if (used != a.get(k).size() || !std::isfinite(v)) throw std::invalid_argument("");
    return v;
  } catch (const std::exception&) {
    throw std::invalid_argument(k + " needs a number, got \"" + a.get(k) + "\"");
  }
}

/// "WxH" with 1 <= W, H <= 16384 (a GL framebuffer's practical limit; both eyes side by side
/// make 2W): no overflow of 2 * W or W * H, no stray characters.
void parse_eye_size(const std::string& s, int& w, int& h) {
  constexpr long kMaxSide = 16384;
  const size_t x = s.find('x');
  const auto side = [&](const std::string& t) {
    if (t.empty() || t.size() > 6 || t.find_first_not_of("0123456789") != std::string::npos)
      return -1L;
    return std::stol(t);
  };
  const long pw = x == std::string::npos ? -1 : side(s.substr(0, x));
  const long ph = x == std::string::npos ? -1 : side(s.substr(x + 1));
  if (pw < 1 || ph < 1 || pw > kMaxSide || ph > kMaxSide)
    throw std::invalid_argument("--eye-size \"" + s +
                                "\": needs WxH with each side 1 to 16384 pixels, e.g. 1440x1600");
  w = static_cast<int>(pw);
  h = static_cast<int>(ph);
}

/// An integer option in [lo, hi] (checked before any cast: no undefined behaviour for 1e300).
long integer(const Args& a, const std::string& k, long fallback, long lo, long hi) {
  const double v = number(a, k, static_cast<double>(fallback));
  if (v != std::floor(v) || v < static_cast<double>(lo) || v > static_cast<double>(hi))
    throw std::invalid_argument(k + " needs a whole number from " + std::to_string(lo) + " to " +
                                std::to_string(hi) + ", got \"" + a.get(k) + "\"");
  return static_cast<long>(v);
}

/// --weight in kg, refused before any work when outside the human range (the range the
/// session applies to a typed weight): a weight of 1e308 kg is a usage error, not a session that
/// waits for a weight that never comes.
double typed_weight(const Args& a, double fallback) {
  const double kg = number(a, "--weight", fallback);
  const caliper::MeasurementRange r = caliper::measurement_range("weight");
  if (kg < r.error_min || kg > r.error_max) {
    std::ostringstream s;
    s << "--weight \"" << a.get("--weight") << "\" is not a plausible weight; give kilograms from "
      << r.error_min << " to " << r.error_max << ", e.g. --weight 65";
    throw std::invalid_argument(s.str());
  }
  return kg;
}

/// A recording never replaces an earlier one by accident (as the journal, app_options()).
void check_record_path(const Args& a) {
  if (!a.has("--record") || a.has("--force")) return;
  std::error_code ec;
  if (std::filesystem::exists(a.get("--record"), ec))
    throw std::runtime_error(a.get("--record") +
                             " already exists; record to another file, or add --force to "
                             "overwrite it");
}

std::string assets_dir(const Args& a) {
  if (a.has("--assets")) return a.get("--assets");
  if (const auto found = caliper::find_assets_dir()) return *found;  // $CALIPER_ASSETS, ...
  return CALIPER_VR_SOURCE_ASSETS;
}

/// The measuring protocol's file: --protocol, else ASSETS/protocol/virtual-caliper.json.
std::string protocol_path(const Args& a, const std::string& assets) {
  return a.get("--protocol", assets + "/protocol/virtual-caliper.json");
}

/// The controllers' tip-offset file: --controllers, else ASSETS/protocol/controllers.json.
std::string controllers_path(const Args& a, const std::string& assets) {
  return a.get("--controllers", assets + "/protocol/controllers.json");
}

/// The folder of the body models: --models-dir, else ASSETS/models.
std::string models_dir(const Args& a, const std::string& assets) {
  return a.get("--models-dir", assets + "/models");
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * static_cast<double>(v.size())))];
}

/// Common app options from the command line; `recorded` holds the typed values of a replayed
/// log's header (used when the command line does not give them).
VrAppOptions app_options(const Args& a, const std::string& role, const std::string& profile,
                         const PoseLogHeader* recorded = nullptr) {
  const std::string assets = assets_dir(a);
  VrAppOptions o;
  const std::string protocol = protocol_path(a, assets);
  o.protocol = read_protocol(protocol);
  o.protocol_dir = std::filesystem::path(protocol).parent_path().string();
  const std::string controllers = controllers_path(a, assets);
  o.tips = read_controller_config(controllers).offsets(profile);
  o.session.role = role;
  if (a.has("--weight")) o.session.weight = typed_weight(a, 0.0);
  if (a.has("--sex")) o.session.sex = a.get("--sex");
  if (recorded && !o.session.weight) o.session.weight = recorded->weight;
  if (recorded && o.session.sex.empty()) o.session.sex = recorded->sex;
  o.avatar.model_path = a.get("--model");
  o.avatar.models_dir = models_dir(a, assets);
  o.avatar.regressor = a.get("--regressor", "R5");
  o.avatar.regressors_path = a.get("--regressors");
  o.avatar.mapping_path = a.get("--mapping");
  o.output_dir = a.get("--out");
  if (a.has("--resume")) {
    o.journal_path = a.get("--resume");
    o.resume = read_journal(o.journal_path);
  } else {
    o.journal_path = a.get("--journal", o.output_dir.empty() ? "caliper-journal.jsonl"
                                                             : o.output_dir + "/journal.jsonl");
    // A new session never wipes the journal of an earlier one by accident.
    std::error_code ec;
    if (std::filesystem::exists(o.journal_path, ec) && !a.has("--force")) {
      std::string resume = "caliper-vr";
      if (a.has("--replay")) resume += " --replay " + a.get("--replay");
      resume += " --resume " + o.journal_path;
      if (!o.output_dir.empty()) resume += " --out " + o.output_dir;
      throw std::runtime_error(
          o.journal_path + " already holds a session journal; continue that session with:\n  " +
          resume + "\nor start a new one with --force (the old journal is then overwritten)");
    }
    if (!o.output_dir.empty()) std::filesystem::create_directories(o.output_dir);
  }
  return o;
}

std::unique_ptr<Audio> open_audio(const Args& a) {
  if (a.has("--no-audio")) return std::make_unique<SilentAudio>();
  try {
    return make_openal_audio();
  } catch (const AudioError& e) {
    std::cerr << "caliper-vr: no sound (" << e.what()
              << "); confirmations are visual and haptic only.\n";
    return std::make_unique<SilentAudio>();
  }
}

/// The posture of the driven body for the documentation snapshots: "raised" (both wrists above
/// the head joint), "crossed" (each wrist on the other side of the body's midline, in front of
/// the chest), "bent" (pelvis 20 cm lower than standing, both elbows bent over 60 degrees), or "".
std::string embodiment_posture(const BodyIk& ik) {
  using namespace ik_joint;
  const IkPose& p = ik.pose();
  const std::vector<Eigen::Vector3d>& j = p.joints;
  const Eigen::Quaterniond to_body(Eigen::AngleAxisd(-p.body_yaw, Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d l = to_body * (j[kLeftWrist] - j[kPelvis]);
  const Eigen::Vector3d r = to_body * (j[kRightWrist] - j[kPelvis]);
  if (j[kLeftWrist].y() > j[kHead].y() && j[kRightWrist].y() > j[kHead].y()) return "raised";
  if (l.x() < -0.05 && r.x() > 0.05 && l.z() > 0.1 && r.z() > 0.1) return "crossed";
  const auto bend = [&](int s, int e, int w) {
    return std::acos(
        std::clamp((j[e] - j[s]).normalized().dot((j[w] - j[e]).normalized()), -1.0, 1.0));
  };
  const double drop = ik.rig().rest[kPelvis].y() -
                      (j[kPelvis].y() - (j[kLeftAnkle].y() - ik.rig().rest[kLeftAnkle].y()));
  if (drop > 0.2 && bend(kLeftShoulder, kLeftElbow, kLeftWrist) > 1.05 &&
      bend(kRightShoulder, kRightElbow, kRightWrist) > 1.05)
    return "bent";
  return "";
}

/// Quotes one shell word when it needs it.
std::string shell_word(const std::string& w) {
  if (!w.empty() && w.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                        "0123456789-_./=:,+@%") == std::string::npos)
    return w;
  std::string q = "'";
  for (char c : w) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// The command that continues this run's session: the same options, `--resume JOURNAL` (which
/// is also the journal appended to), no --max-frames, and a new --record file so that the first
/// recording is kept.
std::string resume_command(const Args& a, const std::string& journal) {
  std::string cmd = "caliper-vr";
  for (size_t i = 0; i < a.argv.size(); ++i) {
    const std::string& k = a.argv[i];
    const bool has_value = a.values.count(k) && i + 1 < a.argv.size();
    if (k == "--resume" || k == "--journal" || k == "--max-frames") {
      i += has_value ? 1 : 0;
      continue;
    }
    cmd += " " + shell_word(k);
    if (!has_value) continue;
    std::string v = a.argv[++i];
    if (k == "--record") {
      const std::filesystem::path p(v);
      v = (p.parent_path() / (p.stem().string() + "-resumed" + p.extension().string())).string();
    }
    cmd += " " + shell_word(v);
  }
  return cmd + " --resume " + shell_word(journal);
}

/// Writes the outputs once, when the session is complete (printing each file), so that a
/// later crash or lost runtime cannot lose them.
void write_outputs_once(VrApp& app) {
  if (app.outputs_written()) return;
  for (const std::string& f : app.write_outputs()) std::cout << "wrote " << f << "\n";
  if (app.finished()) std::cout << "The session is complete. " << kEndHint << std::endl;
}

/// Finishes a run: outputs (unless written at completion), the audio queue, and the plain-words
/// summary. Returns the exit code.
int finish(VrApp& app, Audio& audio, const std::string& journal_path, const Args& a) {
  audio.drain(10.0);
  write_outputs_once(app);
  const SessionResult r = app.session().result();
  for (const auto& kv : r.measurements) {
    std::printf("  %-22s %9.4f %s", kv.first.c_str(), kv.second, kv.first == "weight" ? "kg" : "m");
    if (auto t = r.takes.find(kv.first); t != r.takes.end())
      std::printf("  (%zu takes)", t->second.size());
    std::printf("\n");
  }
  std::cout << "accepted samples: " << app.accepted_this_run()
            << ", rejected: " << app.rejected_this_run() << ", audio: " << audio.description()
            << "\n";
  std::cout.flush();
  if (!app.session().done()) {
    const ProtocolStep* s = app.session().current_step();
    const Phase phase = app.session().view().phase;
    const std::string where = s ? "at step \"" + s->id + "\""
                              : phase == Phase::WaitingForStart
                                  ? "before the operator pressed Start"
                                  : "at the floor calibration";
    std::cerr << "caliper-vr: the session stopped before it was finished (" << where
              << "). Every accepted sample is in the journal " << journal_path
              << "; continue with:\n  " << resume_command(a, journal_path) << "\n";
    if (a.has("--replay"))
      std::cerr << "(replaying: give --replay the log of the rest of the session)\n";
    return kExitIncomplete;
  }
  if (!app.avatar_error().empty())
    std::cerr << "caliper-vr: no avatar: " << app.avatar_error() << "\n";
  return 0;
}

/// The replay's image size and pacing: --eye-size, --draw-every, --max-frames, --frames-dir.
struct ReplaySettings {
  int eye_w = 320;         ///< each eye's image width in pixels
  int eye_h = 356;         ///< each eye's image height in pixels
  int draw_every = 1;      ///< rasterise every N-th frame (0: only snapshots)
  long max_frames = -1;    ///< stop after this many frames (-1: at the log's end)
  std::string frames_dir;  ///< where the key-frame snapshots go ("" for none)
};

/// Reads the replay settings from the command line and creates the snapshot folder.
ReplaySettings replay_settings(const Args& a) {
  ReplaySettings s;
  if (a.has("--eye-size")) parse_eye_size(a.get("--eye-size"), s.eye_w, s.eye_h);
  s.draw_every = static_cast<int>(integer(a, "--draw-every", 1, 0, 1000000));
  s.max_frames = integer(a, "--max-frames", -1, -1, 1000000000000L);
  s.frames_dir = a.get("--frames-dir");
  if (!s.frames_dir.empty()) std::filesystem::create_directories(s.frames_dir);
  return s;
}

/// Where a replay draws: both eyes side by side in an OSMesa framebuffer, or the operator's
/// desktop window (--operator-window; needs a display, CI uses Xvfb).
struct ReplayDisplay {
  std::unique_ptr<render::GlContext> ctx;       ///< the current GL context
  render::GlfwWindowContext* window = nullptr;  ///< the operator's window, or null (headless)
};

/// Opens the replay's display, 2 * eye_w by eye_h pixels, and makes its context current.
ReplayDisplay open_replay_display(bool operator_window, int eye_w, int eye_h) {
  ReplayDisplay d;
  if (operator_window) {
    auto w = std::make_unique<render::GlfwWindowContext>(2 * eye_w, eye_h,
                                                         "The Virtual Caliper - operator", true);
    d.window = w.get();
    d.ctx = std::move(w);
  } else {
    d.ctx = render::make_osmesa_context(2 * eye_w, eye_h);
  }
  d.ctx->make_current();
  return d;
}

/// The replayed log as a pose source; with --record, wrapped in a recorder of every frame.
std::unique_ptr<PoseSource> replay_source(const Args& a, PoseLog log, const std::string& role,
                                          const VrApp& app) {
  std::unique_ptr<PoseSource> source = std::make_unique<ReplayPoseSource>(std::move(log));
  if (!a.has("--record")) return source;
  PoseLogHeader h;
  h.role = role;
  h.source = "caliper-vr --replay " + a.get("--replay");
  h.weight = app.session().options().weight;
  h.sex = app.session().options().sex;
  return std::make_unique<RecordingPoseSource>(std::move(source), a.get("--record"), h);
}

/// The next frame of `source`, or nothing at its end or when it is lost (said on stderr).
std::optional<PoseFrame> next_replay_frame(PoseSource& source) {
  try {
    return source.next_frame();
  } catch (const PoseSourceLost& e) {
    std::cerr << "caliper-vr: " << e.what() << "\n";
    return std::nullopt;
  }
}

/// What a replay draws with: the GL context, its renderer, the operator's window (when open)
/// and the scene the app builds each frame.
struct ReplayCanvas {
  render::GlContext& ctx;             ///< the current GL context
  render::Renderer& renderer;         ///< draws `scene` into the context
  std::optional<OperatorWindow>& op;  ///< the operator's window, when open
  std::string frames_dir;             ///< where snapshots go
  render::Scene scene;                ///< this frame's scene

  /// Draws this frame (the operator's window, whose commands go to `app`, or both eyes' `views`)
  /// and presents it.
  void draw(VrApp& app, const std::vector<render::View>& views) {
    if (op) {
      for (const OperatorCommand& c : op->frame(app, renderer, scene)) app.command(c);
    } else {
      renderer.draw(scene, views);
    }
    ctx.swap_buffers();
  }

  /// Draws `views` (or the operator's window) and writes the image as frames_dir/NAME.png
  /// (vr-operator-* for the operator's window).
  void save(VrApp& app, const std::string& name, const std::vector<render::View>& views) {
    if (op) {
      op->frame(app, renderer, scene);
    } else {
      renderer.draw(scene, views);
    }
    ctx.gl().Finish();
    const std::string file = op ? "vr-operator-" + name.substr(3) : name;
    render::write_png(ctx.read_pixels(),
                      (std::filesystem::path(frames_dir) / (file + ".png")).string());
  }
};

/// The documentation snapshots of a replay (--frames-dir): floor targets, instruction panel,
/// mirror, first person and the driven body's postures, each saved once when its moment comes.
class ReplaySnapshots {
 public:
  /// Saves every snapshot whose moment the app has reached in this frame.
  void take(VrApp& app, ReplayCanvas& canvas, const std::vector<render::View>& views, int eye_w,
            int eye_h) {
    const auto save = [&](const std::string& name, const std::vector<render::View>& v) {
      canvas.save(app, name, v);
      saved_[name] = true;
    };
    const SessionView& v = app.session().view();
    const ProtocolStep* s = app.session().current_step();
    if (!saved_.count("vr-floor-targets") && v.phase == Phase::Floor && v.floor_target == 2 &&
        v.holding && v.hold_progress >= 0.5)
      save("vr-floor-targets", views);
    if (!saved_.count("vr-instruction-panel") && s && s->id == "arm_span_fingertips" &&
        app.step_time() >= 0.9)
      save("vr-instruction-panel", views);
    if (app.finished() && finished_at_ < 0.0) finished_at_ = app.time();
    if (!saved_.count("vr-mirror") && finished_at_ >= 0.0 && app.time() - finished_at_ >= 0.2 &&
        app.avatar()) {
      save("vr-mirror", views);
      if (!canvas.op) save("vr-first-person", {app.first_person_view(2 * eye_w, eye_h)});
    }
    // The driven body in three postures, each once it has been held for half a second.
    if (const BodyIk* ik = app.body_ik(); ik && app.embodiment().frames > 0) {
      const std::string posture = embodiment_posture(*ik);
      if (posture != held_posture_) {
        held_posture_ = posture;
        held_since_ = app.time();
      }
      const std::string name = "vr-mirror-" + posture;
      if (!posture.empty() && !saved_.count(name) && app.time() - held_since_ >= 0.5) {
        save(name, views);
        if (!canvas.op && posture == "crossed")
          save("vr-first-person-crossed", {app.first_person_view(2 * eye_w, eye_h)});
      }
    }
  }
  /// The names of the snapshots saved so far, sorted.
  const std::map<std::string, bool>& saved() const { return saved_; }

 private:
  std::map<std::string, bool> saved_;
  std::string held_posture_;
  double held_since_ = 0.0;
  double finished_at_ = -1.0;
};

/// Per-frame costs of a replay: the app's CPU time and the drawing's wall time, in seconds.
struct ReplayTimes {
  long frames = 0;                ///< frames replayed
  std::vector<double> app_cpu;    ///< thread CPU time of the frame logic and scene building
  std::vector<double> draw_wall;  ///< wall time of rasterising and presenting
};

/// Prints the replay's frame count and costs, and the embodiment figures when a body was driven.
void print_replay_summary(const ReplayTimes& t, const ReplaySettings& s, const EmbodimentStats& e) {
  std::printf(
      "replayed %ld frames: app CPU per frame median %.3f ms, p95 %.3f ms (thread CPU time of the "
      "frame logic and scene building, without rasterisation); draw %.1f ms median (OSMesa, "
      "%dx%d)\n",
      t.frames, 1e3 * median(t.app_cpu), 1e3 * percentile(t.app_cpu, 0.95),
      1e3 * median(t.draw_wall), 2 * s.eye_w, s.eye_h);
  if (e.frames > 0) {
    std::printf(
        "embodiment: %ld frames; wrist to controller-derived wrist max %.2f mm over %ld reachable "
        "wrists; hands inside the torso in %ld frames; %ld joint-limit violations; largest joint "
        "move %.1f mm in %.4f s; IK %.4f ms CPU per frame (mean)\n",
        e.frames, 1e3 * e.max_wrist_error, e.reachable_wrists, e.hands_in_torso, e.limit_violations,
        1e3 * e.max_joint_step, e.max_step_dt,
        1e3 * e.ik_cpu_seconds / static_cast<double>(e.frames));
  }
}

/// The --embodiment-report: how well the avatar followed the tracking, overall and per frame,
/// and the names of the snapshots saved.
Json embodiment_report(const EmbodimentStats& e, const std::map<std::string, bool>& saved) {
  const Json::Object totals = {
      {"frames", e.frames},
      {"reachable_wrists", e.reachable_wrists},
      {"max_wrist_error_m", e.max_wrist_error},
      {"hands_in_torso_frames", e.hands_in_torso},
      {"limit_violations", e.limit_violations},
      {"max_joint_step_m", e.max_joint_step},
      {"max_joint_step_dt_s", e.max_step_dt},
      {"ik_cpu_ms_per_frame",
       e.frames > 0 ? 1e3 * e.ik_cpu_seconds / static_cast<double>(e.frames) : 0.0}};
  Json j = Json::object();
  for (const auto& [key, value] : totals) j.set(key, value);
  Json t = Json::array(), we = Json::array(), in = Json::array(), st = Json::array(),
       lv = Json::array();
  for (const EmbodimentStats::Frame& f : e.per_frame) {
    t.push_back(f.time);
    we.push_back(f.wrist_error);
    in.push_back(f.hand_in_torso);
    st.push_back(f.joint_step);
    lv.push_back(f.limit_violations);
  }
  Json per = Json::object();
  per.set("time", t);
  per.set("wrist_error_m", we);
  per.set("hand_in_torso", in);
  per.set("joint_step_m", st);
  per.set("limit_violations", lv);
  j.set("per_frame", per);
  Json shots = Json::array();
  for (const auto& kv : saved) shots.push_back(kv.first);
  j.set("snapshots", shots);
  return j;
}

/// Writes the per-frame app CPU times as CSV (frame,app_cpu_ms), atomically.
void write_timing(const std::string& path, const std::vector<double>& app_cpu) {
  std::ostringstream t;
  t << "frame,app_cpu_ms\n";
  for (size_t i = 0; i < app_cpu.size(); ++i) t << i << "," << 1e3 * app_cpu[i] << "\n";
  smpl::write_file_atomic(path, t.str());
}

/// The app driven by a pose log, headless (or in the operator's window): replays every frame,
/// saves the snapshots, prints the costs and writes the reports. Returns the exit code.
int run_replay(const Args& a) {
  check_record_path(a);
  PoseLog log = read_pose_log(a.get("--replay"));
  const std::string role = a.get("--role", log.header.role.empty() ? "self" : log.header.role);
  std::string profile = log.header.interaction_profile;
  const PoseLogHeader recorded = log.header;
  VrAppOptions o = app_options(a, role, profile, &recorded);
  const ControllerConfig controllers = read_controller_config(controllers_path(a, assets_dir(a)));
  const ReplaySettings s = replay_settings(a);
  ReplayDisplay display = open_replay_display(a.has("--operator-window"), s.eye_w, s.eye_h);
  render::Renderer renderer(display.ctx->gl());
  std::unique_ptr<Audio> audio = open_audio(a);
  const std::string journal_path = o.journal_path;
  VrApp app(std::move(o), *audio, &renderer);
  std::optional<OperatorWindow> op;
  if (display.window) op.emplace(*display.window);
  ReplayCanvas canvas{*display.ctx, renderer, op, s.frames_dir, {}};
  std::unique_ptr<PoseSource> source = replay_source(a, std::move(log), role, app);
  ReplaySnapshots snapshots;
  ReplayTimes times;
  while (s.max_frames < 0 || times.frames < s.max_frames) {
    const double c0 = thread_cpu_seconds();
    const std::optional<PoseFrame> f = next_replay_frame(*source);
    if (!f) break;
    if (source->interaction_profile() != profile) {  // as live: the runtime named the controllers
      profile = source->interaction_profile();
      app.set_tips(controllers.offsets(profile));
    }
    app.advance(*f, source.get());
    app.build_scene(canvas.scene);
    const std::vector<render::View> views = app.stereo_views(s.eye_w, s.eye_h);
    times.app_cpu.push_back(thread_cpu_seconds() - c0);
    if (s.draw_every > 0 && times.frames % s.draw_every == 0) {
      const auto w0 = std::chrono::steady_clock::now();
      canvas.draw(app, views);
      times.draw_wall.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count());
    }
    if (!s.frames_dir.empty()) snapshots.take(app, canvas, views, s.eye_w, s.eye_h);
    ++times.frames;
    if (app.finished()) write_outputs_once(app);
    if (app.end_requested()) break;  // the user pressed the end button
  }
  print_replay_summary(times, s, app.embodiment());
  if (a.has("--embodiment-report"))
    write_json_file(a.get("--embodiment-report"),
                    embodiment_report(app.embodiment(), snapshots.saved()));
  if (a.has("--timing")) write_timing(a.get("--timing"), times.app_cpu);
  return finish(app, *audio, journal_path, a);
}

/// The pivot-calibration step driven by a pose log (the same code as live).
int run_pivot_replay(const Args& a) {
  const std::string log_path = a.get("--replay");
  const PoseLog log = read_pose_log(log_path);
  const std::string hand = a.get("--calibrate-tip");
  if (hand != "left" && hand != "right")
    throw std::invalid_argument("--calibrate-tip needs left or right");
  const std::string controllers = controllers_path(a, assets_dir(a));
  PivotCollector pivot(hand == "left" ? Tip::Left : Tip::Right);
  for (const PoseFrame& f : log.frames) {
    const std::optional<PivotCalibration> r = pivot.feed(f);
    if (!r) continue;
    ControllerConfig cc = read_controller_config(controllers);
    const std::string profile = log.header.interaction_profile;
    TipOffsets t = cc.offsets(profile);
    (hand == "left" ? t.left : t.right) = r->tip_offset;
    cc.profiles[profile] = t;
    write_controller_config(controllers, cc);
    std::printf(
        "tip offset %.4f %.4f %.4f m, RMS residual %.2f mm over %d poses (%.0f degrees of "
        "rotation); "
        "saved for %s in %s\n",
        r->tip_offset.x(), r->tip_offset.y(), r->tip_offset.z(), r->rms_residual * 1e3,
        r->num_samples, r->max_rotation_degrees, profile.c_str(), controllers.c_str());
    return 0;
  }
  throw std::runtime_error(
      log_path + ": no trigger hold with at least " + std::to_string(PivotCollector::kMinPoses) +
      " tracked poses of the " + hand +
      " controller; hold the trigger while rotating the controller about its resting tip");
}

int run_simulate(const Args& a) {
  const std::string assets = assets_dir(a);
  const Protocol protocol = read_protocol(protocol_path(a, assets));
  const std::string sex = a.get("--sex", "female");
  const std::string model_path = a.get("--model", default_model_path(models_dir(a, assets), sex));
  const smpl::BodyModel model = smpl::load_model(model_path);
  Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
  {
    std::istringstream s(a.get("--betas"));
    double b = 0.0;
    int i = 0;
    while (s >> b) {
      if (i >= betas.size())
        throw std::invalid_argument("--betas: more values than the model's shape components");
      betas[i++] = b;
    }
  }
  const SimulatedPerson person = person_from_model(model, betas, typed_weight(a, 65.0), sex);
  SimulatorOptions o;
  o.seed = static_cast<std::uint64_t>(integer(a, "--seed", 1, 0, 1000000000000000L));
  o.role = a.get("--role", "self");
  o.frame_rate = number(a, "--frame-rate", 90.0);
  o.tip_noise = number(a, "--noise", 0.0);
  o.dropout_step = a.get("--dropout");
  o.third_take_step = a.get("--third-take");
  o.early_release_step = a.get("--early-release");
  o.redo_step = a.get("--redo");
  o.typed_in_log = a.get("--typed-in-log", "yes") != "no";
  o.motions = a.has("--motions");
  if (a.has("--profile")) o.interaction_profile = a.get("--profile");
  const ControllerConfig cc = read_controller_config(controllers_path(a, assets));
  o.tip_offsets = cc.offsets(o.interaction_profile);
  const SimulatedSession sim = simulate_session(protocol, person, o);
  write_pose_log(a.get("--simulate"), sim.log);
  // The truth, for tests and for the reader.
  Json truth = Json::object();
  for (const auto& kv : sim.truth) truth.set(kv.first, kv.second);
  Json j = Json::object();
  j.set("truth", truth);
  j.set("accepted_samples", sim.accepted_samples);
  j.set("rejected_samples", sim.rejected_samples);
  j.set("frames", static_cast<long>(sim.log.frames.size()));
  Json quiet = Json::array();
  for (size_t q : sim.quiet_frames) quiet.push_back(static_cast<long>(q));
  j.set("quiet_frames", quiet);
  j.set("motion_frames", Json(std::vector<double>{static_cast<double>(sim.motion_begin),
                                                  static_cast<double>(sim.motion_end)}));
  write_json_file(a.get("--simulate") + ".truth.json", j);
  std::cout << "wrote " << a.get("--simulate") << " (" << sim.log.frames.size() << " frames, "
            << sim.accepted_samples << " samples to accept) and " << a.get("--simulate")
            << ".truth.json\n";
  return 0;
}

int run_live(const Args& a) {
  check_record_path(a);
  const std::string assets = assets_dir(a);
  LiveOptions live;
  live.role = a.get("--role", "self");
  live.operator_window = a.has("--operator-window");
  live.record_path = a.get("--record");
  live.calibrate_tip = a.get("--calibrate-tip");
  live.controllers_path = controllers_path(a, assets);
  live.make_app_options = [&a, role = live.role](const std::string& profile) {
    return app_options(a, role, profile);
  };
  live.open_audio = [&a]() { return open_audio(a); };
  live.finish = [&a](VrApp& app, Audio& audio, const std::string& journal) {
    return finish(app, audio, journal, a);
  };
  live.write_outputs = [](VrApp& app) { write_outputs_once(app); };
  if (a.has("--weight")) live.weight = number(a, "--weight", 0.0);
  live.sex = a.get("--sex");
  return run_openxr(live);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    Args args;
    try {
      if (!parse_args(argc, argv, args)) return 0;
    } catch (const caliper::app::CommandLineError& e) {
      std::cerr << caliper::app::usage_error_line("caliper-vr", e.what());
      return kExitUsage;
    }
    if (args.has("--simulate")) return run_simulate(args);
    if (args.has("--replay") && args.has("--calibrate-tip")) return run_pivot_replay(args);
    if (args.has("--replay")) return run_replay(args);
    return run_live(args);
  } catch (const NoRuntimeError& e) {
    std::cerr << "caliper-vr: " << e.what() << "\n";
    return kExitNoRuntime;
  } catch (const std::invalid_argument& e) {
    std::cerr << caliper::app::usage_error_line("caliper-vr", e.what());
    return kExitUsage;
  } catch (const std::exception& e) {
    std::cerr << "caliper-vr: " << e.what() << "\n";
    return kExitError;
  }
}
