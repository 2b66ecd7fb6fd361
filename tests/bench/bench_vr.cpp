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
#include <time.h>

#include <algorithm>
#include <filesystem>

#include "caliper/protocol_file.hpp"
#include "caliper/simulator.hpp"
#include "controller_config.hpp"
#include "render/context.hpp"
#include "render/renderer.hpp"
#include "smpl/io.hpp"
#include "vr_app.hpp"

namespace {

using namespace caliper;
using namespace caliper::vr;

constexpr int kEyeWidth = 1440, kEyeHeight = 1600;  // HTC Vive Pro / Valve Index per eye

double thread_cpu() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void BM_VrReplayFrameCpu(benchmark::State& state) {
  const std::string assets = std::string(CALIPER_SOURCE_DIR) + "/assets";
  const Protocol protocol = read_protocol(assets + "/protocol/virtual-caliper.json");
  const smpl::BodyModel model = smpl::load_model(assets + "/models/caliper-female.npz");
  Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
  betas.head(4) << 0.8, -0.6, 0.4, 0.2;
  SimulatorOptions so;
  so.tip_noise = 0.0005;
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
      const double c0 = thread_cpu();
      std::optional<PoseFrame> f = source.next_frame();
      if (!f) break;
      app.advance(*f, &source);
      app.build_scene(scene);
      const std::vector<render::View> views = app.stereo_views(kEyeWidth, kEyeHeight);
      benchmark::DoNotOptimize(views.data());
      const double dt = thread_cpu() - c0;
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

}  // namespace

BENCHMARK_MAIN();
