// CPU time per frame of caliper-vr in replay, at the headset's resolution (2 x 1440 x 1600).
//
// What is measured, per frame, as the main thread's CPU time (CLOCK_THREAD_CPUTIME_ID): taking
// the next frame from the pose source, the measuring session (hold, ISAK, floor), the journal
// append (fsync on accepted samples), the tone queueing (silent audio here), building the scene
// snapshot, redrawing the instruction panel's text on the CPU and uploading it when it changed
// (glTexSubImage2D into OSMesa), and the two eye views. Not measured: Renderer::draw and the
// buffer swap, i.e. the rasterisation, which a headset's GPU does (OSMesa's llvmpipe does it on
// the CPU here and would only measure this machine's software rasteriser).
//
// Each iteration replays a whole simulated 90 Hz session (2930 frames: floor calibration and
// five measured steps, 15 accepted samples, the avatar made at the end); the counters give the
// median, 95th percentile and maximum over the frames. The one frame that makes the avatar
// (regressor training and create_avatar, once per session) is reported separately as max_ms.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>

#include "caliper/body_ik.hpp"
#include "caliper/cpu_time.hpp"
#include "caliper/measurements.hpp"
#include "caliper/protocol_file.hpp"
#include "caliper/simulator.hpp"
#include "controller_config.hpp"
#include "render/context.hpp"
#include "render/renderer.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/io.hpp"
#include "vr_app.hpp"

namespace {

using namespace caliper;
using namespace caliper::vr;

constexpr int kEyeWidth = 1440, kEyeHeight = 1600;  // HTC Vive Pro / Valve Index per eye

void BM_VrReplayFrameCpu(benchmark::State& state) {
  const std::string assets = std::string(CALIPER_SOURCE_DIR) + "/assets";
  const Protocol protocol = read_protocol(assets + "/protocol/virtual-caliper.json");
  const smpl::BodyModel model = smpl::load_model(assets + "/models/caliper-female.npz");
  Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
  betas.head(4) << 0.8, -0.6, 0.4, 0.2;
  SimulatorOptions so;
  so.tip_noise = 0.0005;
  so.end_button = false;  // the measuring session only (the embodiment has its own benchmark)
  const SimulatedSession sim =
      simulate_session(protocol, person_from_model(model, betas, 61.5, "female"), so);
  const std::string dir = (std::filesystem::temp_directory_path() / "caliper_bench_vr").string();
  std::filesystem::create_directories(dir);

  auto ctx = render::make_osmesa_context(2 * kEyeWidth, kEyeHeight);
  ctx->make_current();
  render::Renderer renderer(ctx->gl());
  std::vector<double> frame_ms;
  for (auto _ : state) {
    VrAppOptions o;
    o.protocol = protocol;
    o.protocol_dir = assets + "/protocol";  // the arm-span step plays its instruction video
    o.tips = default_controller_config().offsets(sim.log.header.interaction_profile);
    o.journal_path = dir + "/journal.jsonl";
    o.avatar.models_dir = assets + "/models";
    SilentAudio audio;
    VrApp app(std::move(o), audio, &renderer);
    ReplayPoseSource source(sim.log);
    render::Scene scene;
    double total = 0.0;
    while (true) {
      const double c0 = caliper::thread_cpu_seconds();
      std::optional<PoseFrame> f = source.next_frame();
      if (!f) break;
      app.advance(*f, &source);
      app.build_scene(scene);
      const std::vector<render::View> views = app.stereo_views(kEyeWidth, kEyeHeight);
      benchmark::DoNotOptimize(views.data());
      const double dt = caliper::thread_cpu_seconds() - c0;
      frame_ms.push_back(1e3 * dt);
      total += dt;
    }
    if (!app.finished() || !app.avatar())
      state.SkipWithError("the replayed session did not finish");
    state.SetIterationTime(total);
  }
  std::vector<double> s = frame_ms;
  std::sort(s.begin(), s.end());
  state.counters["frames"] = static_cast<double>(s.size());
  state.counters["median_ms"] = s[s.size() / 2];
  state.counters["p95_ms"] = s[static_cast<size_t>(0.95 * static_cast<double>(s.size()))];
  state.counters["p99_ms"] = s[static_cast<size_t>(0.99 * static_cast<double>(s.size()))];
  state.counters["max_ms"] = s.back();
}
BENCHMARK(BM_VrReplayFrameCpu)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);

/// Embodiment: CPU time of BodyIk::solve per frame over the simulator's scripted motions (wave,
/// reach up, cross arms, squat, turn; 90 Hz, about 1800 frames), and, as the baseline measured
/// in the same run, the skinning of the posed mesh that the app does next for every frame
/// (smpl::evaluate without pose correctives, 6890 vertices). One iteration = all frames.
void BM_BodyIkSolveCpu(benchmark::State& state) {
  const std::string assets = std::string(CALIPER_SOURCE_DIR) + "/assets";
  const Protocol protocol = read_protocol(assets + "/protocol/virtual-caliper.json");
  smpl::BodyModel model = smpl::load_model(assets + "/models/caliper-female.npz");
  Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
  betas.head(4) << 0.8, -0.6, 0.4, 0.2;
  const SimulatedPerson person = person_from_model(model, betas, 61.5, "female");
  SimulatorOptions so;
  so.motions = true;
  const SimulatedSession sim = simulate_session(protocol, person, so);
  const IkRig rig = make_ik_rig(model, betas, eyes_below_head_top(person.landmarks.at("head_top")));
  model.posedirs.resize(model.posedirs.rows(), 0);
  const bool skinning = state.range(0) == 1;
  std::vector<double> frame_us;
  for (auto _ : state) {
    BodyIk ik(rig);
    smpl::Workspace ws;
    smpl::Body body;
    double total = 0.0;
    for (size_t i = sim.motion_begin; i < sim.motion_end; ++i) {
      const PoseFrame& f = sim.log.frames[i];
      IkInput in;
      in.head = {f.device(Device::Head).position, f.device(Device::Head).orientation};
      for (int h = 0; h < 2; ++h) {
        const DevicePose& d = f.device(h == 0 ? Device::Left : Device::Right);
        in.grips[static_cast<size_t>(h)] = RigidPose{d.position, d.orientation};
      }
      in.floor = so.runtime_floor_offset;
      in.time = f.time;
      double c0 = caliper::thread_cpu_seconds();
      const IkPose& p = ik.solve(in);
      benchmark::DoNotOptimize(p.joints.data());
      if (skinning) {  // the baseline: time the skinning of this frame's pose instead
        c0 = caliper::thread_cpu_seconds();
        smpl::evaluate(model, betas, p.axis_angle(), p.translation, ws, body);
        benchmark::DoNotOptimize(body.vertices.data());
      }
      const double dt = caliper::thread_cpu_seconds() - c0;
      frame_us.push_back(1e6 * dt);
      total += dt;
    }
    state.SetIterationTime(total);
  }
  std::vector<double> s = frame_us;
  std::sort(s.begin(), s.end());
  state.counters["frames"] = static_cast<double>(s.size() / state.iterations());
  state.counters["median_us"] = s[s.size() / 2];
  state.counters["p95_us"] = s[static_cast<size_t>(0.95 * static_cast<double>(s.size()))];
  state.counters["max_us"] = s.back();
}
// Arg 0: BodyIk::solve; arg 1: the skinning baseline.
BENCHMARK(BM_BodyIkSolveCpu)
    ->Arg(0)
    ->Arg(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
