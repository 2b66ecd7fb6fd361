// Renderer and editor benchmarks: one slider-drag frame of the editor with a full-size
// SMPL-shaped model (6890 vertices, 13776 faces, 10 betas; tests/support make_random_model):
// regress + evaluate (EditorCore::drag_value) + upload (Renderer::update_positions) + draw,
// and the OSMesa (llvmpipe) frame time at 1024 x 1024.
//
// Run: build/bin/bench_render --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

#include "app/editor_core.hpp"
#include "caliper_test/random_model.hpp"
#include "editor_app.hpp"
#include "render/camera.hpp"
#include "render/render_mesh.hpp"
#include "smpl/io.hpp"

namespace {

namespace ca = caliper::app;
namespace cr = caliper::render;

const ca::ModelEntry& full_size_entry() {
  static const ca::ModelEntry e = [] {
    auto m = std::make_shared<smpl::BodyModel>(caliper::test::make_random_model(10));
    m->meta.gender = "female";
    return ca::make_model_entry(m, "random-full-size");
  }();
  return e;
}

/// The editor's default model: the open female model from assets/models (13,380 vertices,
/// 26,756 triangles, 1.9 x SMPL's), to show what a user of the shipped models gets.
const ca::ModelEntry& open_female_entry() {
  static const ca::ModelEntry e = [] {
    auto m = std::make_shared<smpl::BodyModel>(
        smpl::load_model(CALIPER_SOURCE_DIR "/assets/models/caliper-female.npz"));
    return ca::make_model_entry(m, "caliper-female");
  }();
  return e;
}

/// state.range(2): 0 = the full-size SMPL-shaped test model, 1 = the open female model.
const ca::ModelEntry& bench_entry(int64_t which) {
  return which == 1 ? open_female_entry() : full_size_entry();
}

std::vector<float> floats(const smpl::Vertices& v) {
  std::vector<float> out(static_cast<size_t>(v.size()));
  for (Eigen::Index i = 0; i < v.size(); ++i)
    out[static_cast<size_t>(i)] = static_cast<float>(v.data()[i]);
  return out;
}

/// Slider heights the drag alternates between (inside the valid range).
double drag_height(int64_t i) {
  return 1.60 + 0.002 * static_cast<double>(i % 100);
}

struct DragFixture {
  ca::EditorCore core;
  std::unique_ptr<cr::OffscreenRenderer> off;
  cr::MeshHandle mesh = 0;
  cr::Scene scene;
  cr::View view;

  DragFixture(int w, int h, int samples = 4, int64_t model = 0) {
    core.add_model(bench_entry(model));
    off = std::make_unique<cr::OffscreenRenderer>(w, h, samples);
    cr::MeshData m = cr::mesh_data(core.avatar().vertices, bench_entry(model).model->faces);
    mesh = off->renderer().upload_mesh(m);
    cr::MeshInstance inst;
    inst.mesh = mesh;
    scene.meshes.push_back(inst);
    view.viewport = {0, 0, w, h};
    const auto& v = core.avatar().vertices;
    view.camera =
        cr::frame_box(v.colwise().minCoeff().cast<float>(), v.colwise().maxCoeff().cast<float>(),
                      25, static_cast<float>(w) / static_cast<float>(h));
    core.begin_drag();
  }

  /// One slider event as the editor handles it: regress + evaluate, upload, draw calls.
  void drag_frame(int64_t i) {
    core.drag_value("height", drag_height(i));
    off->bind();
    off->renderer().update_positions(mesh, floats(core.avatar().vertices));
    off->renderer().draw(scene, view);
  }
};

/// Regress + evaluate only (what the app core does per slider event).
void BM_DragRegressEvaluate(benchmark::State& state) {
  ca::EditorCore core;
  core.add_model(bench_entry(state.range(0)));
  core.begin_drag();
  int64_t i = 0;
  for (auto _ : state) {
    core.drag_value("height", drag_height(i++));
    benchmark::DoNotOptimize(core.avatar().vertices.data());
  }
}
BENCHMARK(BM_DragRegressEvaluate)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// One drag frame as the editor's CPU issues it: regress + evaluate + upload + draw calls
/// (no wait for llvmpipe's rasterizer threads; glFinish runs outside the timed region).
void BM_DragFrameCpu(benchmark::State& state) {
  DragFixture f(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), 4,
                state.range(2));
  f.off->renderer().set_cull_closed_meshes(state.range(3) != 0);
  f.off->renderer().set_level_of_detail(state.range(4) != 0);
  int64_t i = 0;
  for (auto _ : state) {
    f.drag_frame(i++);
    state.PauseTiming();
    f.off->resolve();  // ends with glFinish
    state.ResumeTiming();
  }
  state.counters["triangles"] = static_cast<double>(f.off->renderer().triangles_drawn());
}
// Arguments: width, height, model (0 SMPL-shaped, 1 open female), back-face culling of closed
// meshes (1, the renderer's default; 0 = everything two-sided, the baseline), level of detail
// (1, the renderer's default: the coarsest simplified index buffer under half a pixel of error;
// 0 = always the full mesh, the baseline).
BENCHMARK(BM_DragFrameCpu)
    ->Args({1200, 1000, 0, 0, 0})
    ->Args({1200, 1000, 0, 1, 0})
    ->Args({1200, 1000, 0, 1, 1})
    ->Args({1200, 1000, 1, 0, 0})
    ->Args({1200, 1000, 1, 1, 0})
    ->Args({1200, 1000, 1, 1, 1})
    ->Unit(benchmark::kMillisecond);

/// Upload only: float conversion, normals (13776 faces) and glBufferSubData of positions and
/// normals.
void BM_UploadPositions(benchmark::State& state) {
  DragFixture f(64, 64, 1);
  const std::vector<float> p = floats(f.core.avatar().vertices);
  for (auto _ : state) {
    f.off->renderer().update_positions(f.mesh, floats(f.core.avatar().vertices));
  }
  benchmark::DoNotOptimize(p.data());
}
BENCHMARK(BM_UploadPositions)->Unit(benchmark::kMillisecond);

/// A new mesh's upload (upload_mesh: winding check, normals, buffers), with argument 1 its
/// simplified levels (prepare_levels: what the editor adds when it loads a model), and its
/// release. Arguments: model (0 SMPL-shaped, 1 open female), levels (0 or 1).
void BM_UploadMesh(benchmark::State& state) {
  DragFixture f(64, 64, 1, state.range(0));
  const cr::MeshData m =
      cr::mesh_data(f.core.avatar().vertices, bench_entry(state.range(0)).model->faces);
  for (auto _ : state) {
    const cr::MeshHandle h = f.off->renderer().upload_mesh(m);
    if (state.range(1) != 0) f.off->renderer().prepare_levels(h);
    f.off->renderer().release_mesh(h);
  }
}
BENCHMARK(BM_UploadMesh)
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond);

/// Draw calls only (mesh, no upload), CPU side of llvmpipe's vertex processing and binning.
void BM_DrawCallsOnly(benchmark::State& state) {
  DragFixture f(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), 4,
                state.range(2));
  for (auto _ : state) {
    f.off->bind();
    f.off->renderer().draw(f.scene, f.view);
    state.PauseTiming();
    f.off->resolve();  // ends with glFinish
    state.ResumeTiming();
  }
}
BENCHMARK(BM_DrawCallsOnly)
    ->Args({1200, 1000, 0})
    ->Args({1200, 1000, 1})
    ->Unit(benchmark::kMillisecond);

/// The same frame including llvmpipe's rasterization and the multisample resolve (glFinish):
/// the wall time of a whole software-rendered frame.
void BM_DragFrameFinished(benchmark::State& state) {
  DragFixture f(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  int64_t i = 0;
  for (auto _ : state) {
    f.drag_frame(i++);
    f.off->resolve();  // ends with glFinish
  }
}
BENCHMARK(BM_DragFrameFinished)
    ->Args({1200, 1000})
    ->Args({1024, 1024})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// A whole editor frame while the height slider is dragged: regress + evaluate + ImGui panels +
/// scene (avatar, grid, measurement overlay) + upload + draw calls + ImGui drawing, CPU side
/// (the wait for llvmpipe's rasterizer threads runs outside the timed region).
void BM_EditorDragFrameCpu(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  ca::EditorCore core;
  core.add_model(full_size_entry());
  cr::OffscreenRenderer off(w, h, 4);
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;
  io.DisplaySize = ImVec2(static_cast<float>(w), static_cast<float>(h));
  io.DeltaTime = 1.0f / 60.0f;
  {
    caliper::editor::EditorApp app(core, off.context().gl());
    for (int i = 0; i < 3; ++i) {  // let ImGui lay its windows out
      off.bind();
      app.frame(w, h);
      off.resolve();
    }
    core.begin_drag();
    int64_t i = 0;
    for (auto _ : state) {
      core.drag_value("height", drag_height(i++));
      off.bind();
      app.frame(w, h);
      state.PauseTiming();
      off.resolve();
      state.ResumeTiming();
    }
    core.end_drag();
  }
  ImGui::DestroyContext();
}
BENCHMARK(BM_EditorDragFrameCpu)->Args({1600, 1000})->Unit(benchmark::kMillisecond);

/// OSMesa 1024 x 1024: draw + resolve + read back the image (what `caliper render` does per
/// picture, without the PNG encoding).
void BM_OsMesaFrameWithReadback(benchmark::State& state) {
  DragFixture f(1024, 1024, static_cast<int>(state.range(0)));
  for (auto _ : state) {
    cr::Image img = f.off->render(f.scene, std::vector<cr::View>{f.view});
    benchmark::DoNotOptimize(img.rgba.data());
  }
}
BENCHMARK(BM_OsMesaFrameWithReadback)->Arg(1)->Arg(4)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
