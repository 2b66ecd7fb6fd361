// The subcommands run in process (main_guarded) on a small generated model: happy paths, exact
// exit codes and messages for bad input.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "app/editor_core.hpp"
#include "caliper/json.hpp"
#include "caliper/mapping.hpp"
#include "caliper/measurements.hpp"
#include "caliper/population.hpp"
#include "caliper/shape_curve.hpp"
#include "caliper_test/shape_curve_example.hpp"
#include "cli_fixture.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "mesh_io.hpp"
#include "render_bridge.hpp"
#include "smpl/fbx.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"
#include "smpl/npz.hpp"
#ifdef CALIPER_CLI_TESTS_HAVE_RENDER
#include "cli_run.hpp"
#include "render/image.hpp"
#endif

namespace caliper::cli {
namespace {

// A regressor reproduces its inputs up to the model's nonlinearity (the floor vertex, the
// weight's cube root); the bound for used inputs is 1 mm.
constexpr double kInputTolM = 1e-3;
// Files store float32 vertices: 1e-6 relative of ~1 m.
constexpr double kFloatTolM = 1e-5;
// Weight and volume of the same mesh read back from float32 files: 1e-6 relative of 0.08 m3.
constexpr double kWeightTolKg = 0.01;
constexpr double kVolumeTolM3 = 1e-5;

using test::CliRun;

class Commands : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::path(CALIPER_TEST_DATA_DIR) / "cli-cmd" / info->name();
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    model_ = path("model.npz");
    smpl::save_model(test::cli_test_model("female"), model_);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  /// `caliper batch PEOPLE` (a file in the test folder) on `model` with `regressor`, by the fast
  /// path and by measuring meshes (--circumferences): every column of `cols` prints alike in each
  /// row. Returns the fast and the mesh results.
  std::pair<CsvTable, CsvTable> expect_fast_batch_equals_mesh(
      const std::string& model, const std::string& people, const std::string& regressor,
      const std::vector<const char*>& cols) const;
  CliRun run(const std::vector<std::string>& args) const {
    std::ostringstream out, err;
    Io io{out, err, false};
    CliRun r;
    r.code = main_guarded(args, io);
    r.out = out.str();
    r.err = err.str();
    return r;
  }
  std::filesystem::path dir_;
  std::string model_;
};

using test::contains;

TEST_F(Commands, CreateReproducesHeightAndWeightAndWritesGlb) {
  const CliRun r = run({"create", "--model", model_, "--height", "172cm", "--weight", "70kg",
                        "--force", "--out", path("a.glb"), "--json"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  const Json j = parse_json(r.out);
  EXPECT_EQ(j.at("regressor").as_string(), "R2");
  EXPECT_NEAR(j.at("achieved").at("height").as_number(), 1.72, kInputTolM);
  EXPECT_NEAR(j.at("achieved").at("weight").as_number(), 70.0, 0.5);
  EXPECT_EQ(j.at("betas").size(), 10u);
  EXPECT_TRUE(j.at("plausibility").contains("p_value"));
  const smpl::GltfAvatar glb = smpl::read_gltf(path("a.glb"));
  EXPECT_EQ(glb.vertices.rows(), 1298);
  // The GLB stands on the floor and has the achieved height.
  EXPECT_NEAR(glb.vertices.col(1).minCoeff(), 0.0, kFloatTolM);
  EXPECT_FALSE(contains(r.err, "error")) << r.err;
}

TEST_F(Commands, CreateTextReportListsInputAchievedAndPlausibility) {
  const CliRun r =
      run({"create", "--model", model_, "--height", "5ft8in", "--weight", "150lb", "--force"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_TRUE(contains(r.out, "Overall height")) << r.out;
  EXPECT_TRUE(contains(r.out, "172.7 cm")) << r.out;  // 68 in
  EXPECT_TRUE(contains(r.out, "68.0 kg")) << r.out;   // 150 lb
  EXPECT_TRUE(contains(r.out, "Volume")) << r.out;
  EXPECT_TRUE(contains(r.out, "Mahalanobis distance")) << r.out;
  EXPECT_TRUE(contains(r.out, "beyond 3 SD")) << r.out;
}

TEST_F(Commands, CreateWritesObjAndPlyThatMeasureBack) {
  for (const char* ext : {"obj", "ply"}) {
    const std::string out = path(std::string("a.") + ext);
    const CliRun c = run({"create", "--model", model_, "--height", "170cm", "--weight", "66kg",
                          "--force", "--out", out, "-q"});
    ASSERT_EQ(c.code, kExitOk) << c.err;
    const CliRun m = run({"measure", out, "--model", model_, "--json"});
    ASSERT_EQ(m.code, kExitOk) << m.err;
    const Json j = parse_json(m.out);
    EXPECT_NEAR(j.at("measurements").at("height").as_number(), 1.70, kInputTolM) << ext;
    EXPECT_NEAR(read_mesh(out).vertices.col(1).minCoeff(), 0.0, kFloatTolM) << ext;
  }
}

// Every format that carries the mesh, made from the open male model and measured back without
// naming the model: the file's own record picks it, and every measurement is reproduced.
TEST_F(Commands, EveryFormatMeasuresBackTheCreatedAvatarToAMillimetre) {
  ::setenv("CALIPER_ASSETS", (std::string(CALIPER_SOURCE_DIR) + "/assets").c_str(), 1);
  struct Case {
    const char* file;
    std::vector<std::string> extra;
  };
  const std::vector<Case> cases = {{"a.glb", {}},
                                   {"a.gltf", {}},
                                   {"a.vrm", {}},
                                   {"a.fbx", {}},
                                   {"a.obj", {}},
                                   {"a.ply", {}},
                                   {"z.obj", {"--up", "z"}},
                                   {"z.ply", {"--up", "z"}},
                                   {"k.glb", {"--shape-keys", "10"}},
                                   {"s.fbx", {"--bone-names", "smpl"}}};
  for (const auto& c : cases) {
    std::vector<std::string> args = {"create",   "--sex", "male",       "--height", "181cm",
                                     "--weight", "84kg",  "--arm-span", "186cm",    "--inseam",
                                     "84cm",     "--out", path(c.file), "--json"};
    args.insert(args.end(), c.extra.begin(), c.extra.end());
    const CliRun made = run(args);
    ASSERT_EQ(made.code, kExitOk) << c.file << ": " << made.err;
    const Json achieved = parse_json(made.out).at("achieved");
    const CliRun m = run({"measure", path(c.file), "--json"});
    ASSERT_EQ(m.code, kExitOk) << c.file << ": " << m.err;
    const Json j = parse_json(m.out);
    EXPECT_NE(j.at("model").as_string().find("caliper-male.npz"), std::string::npos) << c.file;
    EXPECT_EQ(j.at("model_chosen_by").as_string(), "the avatar file") << c.file;
    const Json& measured = j.at("measurements");
    size_t compared = 0;
    for (const auto& [id, value] : achieved.as_object()) {
      const Json* got = measured.find(id);
      if (!got || !value.is_number()) continue;
      ++compared;
      if (id == "weight") {
        EXPECT_NEAR(got->as_number(), value.as_number(), kWeightTolKg) << c.file << " " << id;
      } else if (id == "volume") {
        EXPECT_NEAR(got->as_number(), value.as_number(), kVolumeTolM3) << c.file << " " << id;
      } else {
        EXPECT_NEAR(got->as_number(), value.as_number(), kInputTolM) << c.file << " " << id;
      }
    }
    EXPECT_GE(compared, 13u) << c.file;
  }
  ::unsetenv("CALIPER_ASSETS");
}

// The editor's export carries the same record as `caliper create`: `caliper measure` on it picks
// the open model and sex it was made with (not the neutral default) and reproduces the editor's
// measurements, weight included, in every format.
TEST_F(Commands, MeasureOnAnEditorExportUsesItsModelAndSex) {
  const std::string assets = std::string(CALIPER_SOURCE_DIR) + "/assets";
  ::setenv("CALIPER_ASSETS", assets.c_str(), 1);
  caliper::app::EditorCore editor;
  ASSERT_TRUE(editor.load_model_file(assets + "/models/caliper-male.npz"));
  ASSERT_TRUE(editor.set_value("height", 1.85));
  ASSERT_TRUE(editor.set_value("weight", 90.3));
  const MeasurementMap made = editor.avatar().achieved;
  ASSERT_TRUE(made.count("weight"));
  const auto meta = editor.export_metadata();
  EXPECT_EQ(meta.at("open_model_sex"), "male");
  EXPECT_EQ(meta.at("model"), "caliper-open-male");
  EXPECT_EQ(meta.at("regressor"), "R2");
  EXPECT_TRUE(meta.count("betas") && meta.count("measurements") && meta.count("generator"));
  ASSERT_EQ(caliper::app::export_formats().size(), 6u);
  for (const auto& format : caliper::app::export_formats()) {
    const std::string file = path("editor" + format.extension);
    ASSERT_TRUE(editor.export_avatar(file)) << editor.messages().back().text;
    const CliRun m = run({"measure", file, "--json"});
    ASSERT_EQ(m.code, kExitOk) << file << ": " << m.err;
    const Json j = parse_json(m.out);
    EXPECT_NE(j.at("model").as_string().find("caliper-male.npz"), std::string::npos) << file;
    EXPECT_EQ(j.at("model_chosen_by").as_string(), "the avatar file") << file;
    const Json& measured = j.at("measurements");
    EXPECT_NEAR(measured.at("weight").as_number(), made.at("weight"), kWeightTolKg) << file;
    for (const auto& [id, value] : made) {
      if (id == "weight" || id == "volume" || !measured.contains(id)) continue;
      EXPECT_NEAR(measured.at(id).as_number(), value, kInputTolM) << file << " " << id;
    }
  }
  ::unsetenv("CALIPER_ASSETS");
}

// A model with texture coordinates (as the MakeHuman-based open models of issue 11): `caliper
// create` and the editor's export keep them in every format that carries them (GLB, glTF, VRM,
// FBX, OBJ), and every file still measures back as the avatar.
TEST_F(Commands, CreateAndEditorExportKeepTheModelsTextureCoordinates) {
  // Texture coordinates read back (the bound); the test's are multiples of 1/64.
  constexpr double kUvTol = 1e-6;
  smpl::BodyModel m = test::cli_test_model("female");
  m.meta.extra["licence"] = "MIT";  // for the VRM
  const Eigen::Index V = m.num_vertices(), F = m.num_faces();
  // One coordinate per vertex, and coordinates of their own for the corners of every 5th
  // triangle: a seam around each of those.
  m.uvs.resize(V + 3 * F, 2);
  for (Eigen::Index i = 0; i < m.uvs.rows(); ++i) {
    m.uvs.row(i) << static_cast<double>(i % 64) / 64.0, static_cast<double>((i / 64) % 64) / 64.0;
  }
  m.uv_faces = m.faces;
  for (Eigen::Index f = 0; f < F; f += 5) {
    for (int c = 0; c < 3; ++c) m.uv_faces(f, c) = static_cast<int>(V + 3 * f + c);
  }
  const std::string model = path("textured.npz");
  smpl::save_model(m, model);
  auto worst_uv = [&](const smpl::Faces& faces, const smpl::TexCoords& uvs) {
    EXPECT_EQ(faces.rows(), F);
    double worst = 0.0;
    for (Eigen::Index f = 0; f < F && f < faces.rows(); ++f) {
      for (int c = 0; c < 3; ++c) {
        worst = std::max(
            worst, (uvs.row(faces(f, c)) - m.uvs.row(m.uv_faces(f, c))).cwiseAbs().maxCoeff());
      }
    }
    return worst;
  };
  for (const char* file : {"t.glb", "t.gltf", "t.vrm", "t.fbx", "t.obj", "t.ply"}) {
    const CliRun made = run({"create", "--model", model, "--height", "170cm", "--weight", "66kg",
                             "--force", "--out", path(file), "--json"});
    ASSERT_EQ(made.code, kExitOk) << file << ": " << made.err;
    const double height = parse_json(made.out).at("achieved").at("height").as_number();
    const CliRun measured = run({"measure", path(file), "--model", model, "--json"});
    ASSERT_EQ(measured.code, kExitOk) << file << ": " << measured.err;
    EXPECT_NEAR(parse_json(measured.out).at("measurements").at("height").as_number(), height,
                kInputTolM)
        << file;
    const std::string ext = std::filesystem::path(file).extension().string();
    if (ext == ".glb" || ext == ".gltf" || ext == ".vrm") {
      const smpl::GltfAvatar a = smpl::read_gltf(path(file));
      EXPECT_GT(a.vertices.rows(), V) << file << ": split at the seams";
      EXPECT_LE(worst_uv(a.faces, a.texcoords), kUvTol) << file;
    } else if (ext == ".ply") {
      EXPECT_EQ(read_mesh(path(file)).vertices.rows(), V) << file << ": welded, no UVs";
    } else {
      const smpl::FbxAvatar a = smpl::read_with_assimp(path(file));
      EXPECT_LE(worst_uv(a.faces, a.uvs), kUvTol) << file;
    }
  }
  caliper::app::EditorCore editor;
  ASSERT_TRUE(editor.load_model_file(model));
  ASSERT_TRUE(editor.set_value("height", 1.72));
  for (const char* file : {"editor.glb", "editor.fbx", "editor.obj"}) {
    ASSERT_TRUE(editor.export_avatar(path(file))) << editor.messages().back().text;
    if (std::string(file) == "editor.glb") {
      const smpl::GltfAvatar a = smpl::read_gltf(path(file));
      EXPECT_LE(worst_uv(a.faces, a.texcoords), kUvTol) << file;
    } else {
      const smpl::FbxAvatar a = smpl::read_with_assimp(path(file));
      EXPECT_LE(worst_uv(a.faces, a.uvs), kUvTol) << file;
    }
  }
}

TEST_F(Commands, ExportOptionsAreCheckedWithClearMessages) {
  const std::vector<std::string> base = {"create",   "--model", model_,    "--height", "170cm",
                                         "--weight", "66kg",    "--force", "-q"};
  auto with = [&](std::vector<std::string> more) {
    std::vector<std::string> a = base;
    a.insert(a.end(), more.begin(), more.end());
    return run(a);
  };
  CliRun r = with({"--out", path("a.glb"), "--up", "z"});
  EXPECT_EQ(r.code, kExitUsage);
  EXPECT_TRUE(contains(r.err, "--up applies to .obj and .ply")) << r.err;
  r = with({"--out", path("a.obj"), "--shape-keys", "3"});
  EXPECT_EQ(r.code, kExitUsage);
  EXPECT_TRUE(contains(r.err, "--shape-keys")) << r.err;
  r = with({"--out", path("a.glb"), "--shape-keys", "11"});
  EXPECT_EQ(r.code, kExitUsage);
  EXPECT_TRUE(contains(r.err, "from 0 to 10")) << r.err;
  r = with({"--out", path("a.glb"), "--bone-names", "unity"});
  EXPECT_EQ(r.code, kExitUsage);
  EXPECT_TRUE(contains(r.err, "expected smpl")) << r.err;
  r = with({"--shape-keys", "3"});
  EXPECT_EQ(r.code, kExitUsage);
  EXPECT_TRUE(contains(r.err, "needs --out")) << r.err;
  // A user's model file states no licence: VRM export is refused until --licence says it.
  r = with({"--out", path("a.vrm")});
  EXPECT_EQ(r.code, kExitRuntime);
  EXPECT_TRUE(contains(r.err, "--licence")) << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("a.vrm")));
  r = with({"--out", path("a.vrm"), "--licence", "https://example.org/my-licence"});
  EXPECT_EQ(r.code, kExitOk) << r.err;
  // Pose files: JSON (flat, triples, {"pose": ...}) and .npy; wrong sizes named.
  {
    std::ofstream f(path("flat.json"));
    f << "[";
    for (int i = 0; i < 72; ++i) f << (i ? ", " : "") << (i == 50 ? -0.9 : 0.0);
    f << "]";
  }
  {
    std::ofstream f(path("obj.json"));
    f << "{\"pose\": [";
    for (int i = 0; i < 24; ++i) f << (i ? ", " : "") << "[0, 0, " << (i == 17 ? 0.9 : 0.0) << "]";
    f << "]}";
  }
  std::ofstream(path("short.json")) << "[0, 0, 0]";
  smpl::write_npy(path("pose.npy"), smpl::make_npy(Eigen::MatrixXd::Zero(24, 3).eval()));
  EXPECT_EQ(with({"--out", path("p.glb"), "--pose", path("flat.json")}).code, kExitOk);
  EXPECT_EQ(with({"--out", path("p.fbx"), "--pose", path("obj.json")}).code, kExitOk);
  EXPECT_EQ(with({"--out", path("p.obj"), "--pose", path("pose.npy")}).code, kExitOk);
  r = with({"--out", path("p.glb"), "--pose", path("short.json")});
  EXPECT_EQ(r.code, kExitRuntime);
  EXPECT_TRUE(contains(r.err, "has 3 numbers; the model's 24 joints need 72")) << r.err;
  r = with({"--out", path("p.vrm"), "--pose", path("flat.json")});
  EXPECT_EQ(r.code, kExitUsage);
  EXPECT_TRUE(contains(r.err, "T-pose")) << r.err;
  // The A-pose glTF: left shoulder (joint 16) rotated -0.9 rad about z.
  EXPECT_EQ(with({"--out", path("a.glb")}).code, kExitOk);
  const smpl::GltfAvatar posed = smpl::read_gltf(path("p.glb"));
  const smpl::GltfAvatar rest = smpl::read_gltf(path("a.glb"));
  EXPECT_GT((posed.joints.row(20) - rest.joints.row(20)).norm(), 0.05);  // the wrist moved
  EXPECT_NEAR((posed.joints.row(1) - rest.joints.row(1)).norm(), 0.0, kFloatTolM);
}

// `--population ansur2`: the likeliest soldier of that height and weight (the noise-aware
// regressor with the model's ANSUR II population as its prior), whose waist is smaller than the
// general population's body of the same height and weight (docs/evaluation.md, section 3).
TEST_F(Commands, CreateForAPopulationTheModelCarries) {
  const std::string open = std::string(CALIPER_SOURCE_DIR) + "/assets/models/caliper-female.npz";
  const std::vector<std::string> who = {"create", "--model",  open,   "--height",
                                        "165cm",  "--weight", "64kg", "--json"};
  auto with = [&who](std::vector<std::string> more) {
    std::vector<std::string> a = who;
    a.insert(a.end(), more.begin(), more.end());
    return a;
  };
  const CliRun soldier = run(with({"--population", "ansur2"}));
  ASSERT_EQ(soldier.code, kExitOk) << soldier.err;
  const Json s = parse_json(soldier.out);
  EXPECT_EQ(s.at("regressor").as_string(), "noise-aware");
  EXPECT_EQ(s.at("population").as_string(), "ansur2");
  const CliRun general = run(with({"--regressor", "noise-aware"}));
  ASSERT_EQ(general.code, kExitOk) << general.err;
  const Json g = parse_json(general.out);
  EXPECT_LT(s.at("achieved").at("waist_circumference").as_number(),
            g.at("achieved").at("waist_circumference").as_number() - 0.01);
  const CliRun r2 = run(with({"--population", "ansur2", "--regressor", "R2"}));
  EXPECT_EQ(r2.code, kExitUsage);
  EXPECT_TRUE(contains(r2.err, "--population takes the noise-aware regressor")) << r2.err;
  const CliRun none = run({"create", "--model", model_, "--height", "170cm", "--weight", "66kg",
                           "--force", "--population", "ansur2"});
  EXPECT_EQ(none.code, kExitUsage);
  EXPECT_TRUE(contains(none.err, "carries no population 'ansur2'")) << none.err;
}

// Every population each committed model carries makes an avatar (`--population nhanes` was
// refused on the female and male files: the NHANES subjects' own covariance, registered from
// four measurements, is singular). A model of the general population carries NHANES as that
// population, its own N(0, I): the same avatar as the noise-aware regressor without one.
TEST_F(Commands, EveryPopulationOfEveryCommittedModelMakesAnAvatar) {
  for (const char* sex : {"female", "male", "neutral"}) {
    const std::string open =
        std::string(CALIPER_SOURCE_DIR) + "/assets/models/caliper-" + sex + ".npz";
    const std::vector<std::string> keys = population_keys(smpl::load_model(open));
    EXPECT_EQ(keys, (std::vector<std::string>{"ansur2", "nhanes"})) << sex;
    const std::vector<std::string> who = {"create", "--model",  open,   "--height",
                                          "170cm",  "--weight", "70kg", "--arm-span",
                                          "172cm",  "--json"};
    auto betas = [this, &who, sex](const std::vector<std::string>& more) {
      std::vector<std::string> a = who;
      a.insert(a.end(), more.begin(), more.end());
      const CliRun r = run(a);
      EXPECT_EQ(r.code, kExitOk) << sex << " " << (more.empty() ? "" : more.back()) << ": "
                                 << r.err;
      if (r.code != kExitOk) return Eigen::VectorXd();
      const std::vector<double> list = parse_json(r.out).at("betas").as_numbers();
      return Eigen::VectorXd(
          Eigen::Map<const Eigen::VectorXd>(list.data(), static_cast<Eigen::Index>(list.size())));
    };
    const Eigen::VectorXd own = betas({});
    for (const std::string& key : keys) {
      const Eigen::VectorXd b = betas({"--population", key});
      if (key == "nhanes" && b.size() == own.size() && b.size() > 0) {
        EXPECT_LT((b - own).cwiseAbs().maxCoeff(), 1e-6) << sex;
      }
    }
  }
}

TEST_F(Commands, CreateRecordsItsModelAndMeasureRefusesAnUnknownOpenModel) {
  const CliRun c = run({"create", "--model", model_, "--height", "170cm", "--weight", "66kg",
                        "--force", "--out", path("a.glb"), "-q"});
  ASSERT_EQ(c.code, kExitOk) << c.err;
  const MeshFile made = read_mesh(path("a.glb"));
  EXPECT_EQ(made.extras.at("model"), "caliper-test-female");
  EXPECT_EQ(made.extras.count("open_model_sex"), 0u) << "made with --model, not an open model";
  const smpl::BodyModel m = smpl::load_model(model_);
  write_avatar(path("x.glb"), m, Eigen::VectorXd::Zero(10), m.v_template,
               {{"open_model_sex", "robot"}});
  const CliRun r = run({"measure", path("x.glb")});
  EXPECT_EQ(r.code, kExitRuntime);
  EXPECT_TRUE(contains(r.err, "unknown open model sex 'robot'")) << r.err;
  EXPECT_EQ(run({"measure", path("x.glb"), "--model", model_}).code, kExitOk);
}

TEST_F(Commands, CreateRefusesImplausibleInputWithExitCode3) {
  CliRun r = run({"create", "--model", model_, "--height", "4m", "--weight", "80kg"});
  EXPECT_EQ(r.code, kExitImplausible);
  EXPECT_TRUE(contains(r.err, "height")) << r.err;
  EXPECT_TRUE(contains(r.err, "--force")) << r.err;
  r = run({"create", "--model", model_, "--height", "170cm", "--weight", "-5kg"});
  EXPECT_EQ(r.code, kExitImplausible) << r.err;
  EXPECT_TRUE(contains(r.err, "weight")) << r.err;
  // A value no body has: --force is neither suggested nor accepted (it used to be suggested,
  // and then the regressor refused the value with a vaguer message).
  EXPECT_FALSE(contains(r.err, "--force")) << r.err;
  r = run({"create", "--model", model_, "--height", "170cm", "--weight", "-5kg", "--force"});
  EXPECT_EQ(r.code, kExitImplausible) << r.err;
  EXPECT_TRUE(contains(r.err, "weight = -5 kg must be positive")) << r.err;
  r = run({"create", "--model", model_, "--height", "170cm", "--weight", "65kg", "--arm-span",
           "85cm", "--inseam", "80cm"});
  EXPECT_EQ(r.code, kExitImplausible) << r.err;
  EXPECT_TRUE(contains(r.err, "arm")) << r.err;
}

TEST_F(Commands, CreateUsageErrorsHaveExitCode2) {
  EXPECT_EQ(run({"create", "--model", model_, "--height", "170", "--weight", "60kg"}).code,
            kExitUsage);
  EXPECT_EQ(run({"create", "--model", model_}).code, kExitUsage);
  EXPECT_EQ(run({"create", "--model", model_, "--height", "1.7m", "--out", path("a.txt")}).code,
            kExitUsage);
  EXPECT_EQ(run({"create", "--height", "1.7m", "--sex", "robot"}).code, kExitUsage);
  const CliRun r = run({"create", "--model", model_, "--height", "1.7m", "--regressor", "R5"});
  EXPECT_EQ(r.code, kExitUsage);
  EXPECT_TRUE(contains(r.err, "R5 needs --weight, --arm-span, --inseam, --hip-width")) << r.err;
}

TEST_F(Commands, MissingFilesHaveExitCode1) {
  CliRun r = run({"create", "--model", path("none.npz"), "--height", "1.7m", "--weight", "60kg"});
  EXPECT_EQ(r.code, kExitRuntime);
  EXPECT_TRUE(contains(r.err, "none.npz: model file not found")) << r.err;
  std::ofstream(path("bad.npz")) << "not a zip";
  r = run({"create", "--model", path("bad.npz"), "--height", "1.7m", "--weight", "60kg"});
  EXPECT_EQ(r.code, kExitRuntime);
  EXPECT_TRUE(contains(r.err, "bad.npz")) << r.err;
}

TEST_F(Commands, MeasureBetasMatchesTheLibrary) {
  const CliRun r = run({"measure", "--model", model_, "--betas", "1,-0.5,0.25", "--json"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  const smpl::BodyModel model = smpl::load_model(model_);
  Eigen::VectorXd b(3);
  b << 1, -0.5, 0.25;
  const MeasurementMap expected = measure_all(model, shaped_vertices(model, b));
  const Json j = parse_json(r.out);
  for (const auto& [id, v] : expected)
    EXPECT_DOUBLE_EQ(j.at("measurements").at(id).as_number(), v) << id;
  EXPECT_EQ(run({"measure", "--model", model_, "--betas", "1,2,3,4,5,6,7,8,9,10,11"}).code,
            kExitUsage);
}

TEST_F(Commands, TrainSavesRegressorsThatCreateReuses) {
  CliRun r = run({"train", "--model", model_, "--save", path("r.json")});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_TRUE(contains(r.out, "training set: 1024 bodies")) << r.out;
  EXPECT_TRUE(contains(r.out, "R6")) << r.out;
  EXPECT_TRUE(contains(r.out, "noise-aware")) << r.out;
  r = run({"create", "--model", model_, "--regressors", path("r.json"), "--height", "1.7m",
           "--weight", "60kg", "--force", "--json"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_NEAR(parse_json(r.out).at("achieved").at("height").as_number(), 1.70, kInputTolM);
  // Regressors of another model are refused.
  const std::string other = path("other.npz");
  smpl::save_model(test::cli_test_model("male", 99), other);
  r = run({"create", "--model", other, "--regressors", path("r.json"), "--height", "1.7m",
           "--weight", "60kg", "--force"});
  EXPECT_EQ(r.code, kExitRuntime) << r.err;
  r = run({"train", "--model", model_, "--json", "--gaussian", "300", "--seed", "3"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_EQ(parse_json(r.out).at("training_set").at("bodies").as_int(), 300);
}

TEST_F(Commands, BatchWritesResultsAvatarsAndReportsBadRows) {
  std::ofstream(path("people.csv")) << "id,sex,height_cm,weight_kg\n"
                                       "a,female,170,62\n"
                                       "b,female,abc,70\n"
                                       "c,female,400,70\n"
                                       "d,female,160,55\n";
  const CliRun r = run({"batch", path("people.csv"), "--model", model_, "-j", "2", "--out",
                        path("results.csv"), "--out-dir", path("avatars"), "--force"});
  // Row b cannot be read: exit code 1, every other row still done.
  EXPECT_EQ(r.code, kExitRuntime) << r.err;
  EXPECT_TRUE(contains(r.err, "4 people")) << r.err;
  EXPECT_TRUE(contains(r.err, "progress: 4 of 4 done")) << r.err;  // plain lines, no tty
  const CsvTable t = read_csv(path("results.csv"));
  ASSERT_EQ(t.rows.size(), 4u);
  const int status = t.column("status");
  const int height = t.column("height_cm");
  ASSERT_GE(status, 0);
  ASSERT_GE(height, 0);
  EXPECT_EQ(t.rows[0][static_cast<size_t>(status)], "ok");
  EXPECT_NEAR(std::stod(t.rows[0][static_cast<size_t>(height)]), 170.0, 0.1);
  EXPECT_EQ(t.rows[1][static_cast<size_t>(status)], "error");
  EXPECT_EQ(t.rows[3][static_cast<size_t>(status)], "ok");
  EXPECT_TRUE(std::filesystem::exists(path("avatars/a.glb")));
  EXPECT_TRUE(std::filesystem::exists(path("avatars/d.glb")));
  EXPECT_FALSE(std::filesystem::exists(path("avatars/b.glb")));
}

std::pair<CsvTable, CsvTable> Commands::expect_fast_batch_equals_mesh(
    const std::string& model, const std::string& people, const std::string& regressor,
    const std::vector<const char*>& cols) const {
  const CliRun fast = run({"batch", path(people), "--model", model, "--force", "--out",
                           path("fast.csv"), "--regressor", regressor});
  const CliRun mesh = run({"batch", path(people), "--model", model, "--force", "--out",
                           path("mesh.csv"), "--regressor", regressor, "--circumferences"});
  EXPECT_EQ(fast.code, kExitOk) << fast.err;
  EXPECT_EQ(mesh.code, kExitOk) << mesh.err;
  CsvTable f = read_csv(path("fast.csv")), m = read_csv(path("mesh.csv"));
  EXPECT_EQ(f.rows.size(), m.rows.size());
  for (const char* col : cols) {
    const int c = f.column(col), cm = m.column(col);  // the mesh CSV has more columns
    EXPECT_GE(c, 0) << col;
    EXPECT_GE(cm, 0) << col;
    if (c < 0 || cm < 0) continue;
    for (size_t r = 0; r < std::min(f.rows.size(), m.rows.size()); ++r)  // to printing
      EXPECT_EQ(f.rows[r][static_cast<size_t>(c)], m.rows[r][static_cast<size_t>(cm)]) << col;
  }
  return {std::move(f), std::move(m)};
}

TEST_F(Commands, BatchFastPathEqualsMeasuringTheMesh) {
  std::ofstream(path("people.csv")) << "id,height_cm,weight_kg,arm_span_cm,inseam_cm\n"
                                       "a,172,73,27,75\nb,168,66,26.5,74\n";
  // The CSV's 2 decimals: the values agree to printing.
  const auto [f, m] =
      expect_fast_batch_equals_mesh(model_, "people.csv", "R4",
                                    {"height_cm", "weight_kg", "inseam_height_cm", "hip_width_cm",
                                     "arm_length_cm", "volume_L", "beta0", "mahalanobis"});
  ASSERT_EQ(f.rows.size(), 2u);
  // Circumferences only when asked (issue 17: no columns that are always empty).
  EXPECT_LT(f.column("chest_circumference_cm"), 0);
  ASSERT_GE(m.column("chest_circumference_cm"), 0);
  EXPECT_FALSE(m.rows[0][static_cast<size_t>(m.column("chest_circumference_cm"))].empty());
}

// A model that carries a shape curve (caliper/shape_curve.hpp): create and batch start R2-R6
// from it (every beta set; the fast batch path equals measuring the mesh), --no-shape-curve gives
// the paper's betas, and a malformed curve entry is refused naming the file and the way out.
TEST_F(Commands, ShapeCurveIsUsedSwitchedOffAndAMalformedOneRefused) {
  smpl::BodyModel m = test::cli_test_model("female");
  set_shape_curve(m, test::example_shape_curve(Eigen::MatrixXd::Constant(m.num_betas(), 6, 0.05)));
  const std::string curved = path("curved.npz");
  smpl::save_model(m, curved);
  const std::vector<std::string> who = {"create",   "--model", curved,    "--height", "172cm",
                                        "--weight", "73kg",    "--force", "--json"};
  auto with = [&who](std::vector<std::string> more) {
    std::vector<std::string> a = who;
    a.insert(a.end(), more.begin(), more.end());
    return a;
  };
  const CliRun from_curve = run(who), paper = run(with({"--no-shape-curve"}));
  ASSERT_EQ(from_curve.code, kExitOk) << from_curve.err;
  ASSERT_EQ(paper.code, kExitOk) << paper.err;
  EXPECT_TRUE(parse_json(from_curve.out).at("shape_curve").as_bool());
  EXPECT_FALSE(parse_json(paper.out).at("shape_curve").as_bool());
  const std::vector<double> bc = parse_json(from_curve.out).at("betas").as_numbers();
  const std::vector<double> bp = parse_json(paper.out).at("betas").as_numbers();
  ASSERT_EQ(bc.size(), bp.size());
  double moved = 0.0;
  for (size_t i = 0; i < bc.size(); ++i) moved = std::max(moved, std::abs(bc[i] - bp[i]));
  EXPECT_GT(moved, 1e-3) << "the curve changed nothing";
  // Batch: the fast path (ShapeMeasurer over every beta) equals measuring the mesh.
  std::ofstream(path("people.csv")) << "id,height_cm,weight_kg\na,172,73\nb,160,90\n";
  const auto tables = expect_fast_batch_equals_mesh(
      curved, "people.csv", "R2", {"height_cm", "weight_kg", "volume_L", "beta0", "mahalanobis"});
  EXPECT_EQ(tables.first.rows.size(), 2u);
  // A curve over more betas than the batch's exact maps take (kMaxMeasurerBetas = 32): the fast
  // path measures the mesh instead, with the same figures.
  smpl::BodyModel wide = test::cli_test_model("female");
  const Eigen::MatrixXd d = wide.shapedirs;
  wide.shapedirs.resize(d.rows(), 36);
  for (int k = 0; k < 36; ++k) wide.shapedirs.col(k) = d.col(k % 10) * (k < 10 ? 1.0 : 0.1);
  set_shape_curve(wide, test::example_shape_curve(Eigen::MatrixXd::Constant(36, 6, 0.05)));
  smpl::save_model(wide, path("wide.npz"));
  const auto wide_tables = expect_fast_batch_equals_mesh(
      path("wide.npz"), "people.csv", "R2", {"height_cm", "weight_kg", "volume_L", "beta20"});
  EXPECT_EQ(wide_tables.first.rows.size(), 2u);
  // A malformed entry: refused, naming the file and what to do; --no-shape-curve still works.
  m.meta.extra[shape_curve_meta_key()] = "{\"population\": 3";
  smpl::save_model(m, curved);
  const CliRun bad = run(who);
  EXPECT_EQ(bad.code, kExitRuntime);
  EXPECT_TRUE(contains(bad.err, "curved.npz") && contains(bad.err, "shape_curve") &&
              contains(bad.err, "--no-shape-curve"))
      << bad.err;
  EXPECT_EQ(run(with({"--no-shape-curve"})).code, kExitOk);
}

TEST_F(Commands, BatchRefusesImplausibleRowsWithoutForce) {
  std::ofstream(path("people.csv")) << "height_m,weight_lb\n1.7,140\n4.0,150\n";
  const CliRun r = run(
      {"batch", path("people.csv"), "--model", model_, "--out", path("results.csv"), "-j", "1"});
  EXPECT_EQ(r.code, kExitRuntime);
  const CsvTable t = read_csv(path("results.csv"));
  ASSERT_EQ(t.rows.size(), 2u);
  const size_t status = static_cast<size_t>(t.column("status"));
  EXPECT_EQ(t.rows[1][status], "refused");
  EXPECT_TRUE(contains(t.rows[1].back(), "height")) << t.rows[1].back();
}

TEST_F(Commands, ModelsDescribesAFile) {
  const CliRun r = run({"models", model_, "--json"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  const Json j = parse_json(r.out);
  const Json& models = j.at("models");
  ASSERT_GE(models.size(), 1u);
  const Json& m = models[models.size() - 1];
  EXPECT_EQ(m.at("vertices").as_int(), 1298);
  EXPECT_EQ(m.at("betas").as_int(), 10);
  EXPECT_EQ(m.at("gender").as_string(), "female");
  EXPECT_EQ(run({"models", path("none.npz")}).code, kExitRuntime);
}

TEST_F(Commands, RenderWritesPngs) {
  if (!renderer_available()) GTEST_SKIP() << "built without the renderer";
  const CliRun r = run({"render", "--model", model_, "--betas", "1", "--views", "front,side",
                        "--size", "64x96", "--out", path("pic")});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_TRUE(std::filesystem::exists(path("pic_front.png")));
  EXPECT_TRUE(std::filesystem::exists(path("pic_side.png")));
  EXPECT_EQ(run({"render", "--model", model_, "--views", "top"}).code, kExitUsage);
}

#ifdef CALIPER_CLI_TESTS_HAVE_RENDER
// Issue 17, item 13: the body fills the picture (it filled about half its height) and is not cut.
TEST_F(Commands, RenderedBodyFillsThePicture) {
  // The camera fits the vertices with a 5 % margin (frame_points_tight): the body spans ~90 % of
  // the picture's height or width; 80 % leaves room for antialiasing and the perspective.
  constexpr double kMinFill = 0.80;
  ASSERT_EQ(run({"render", "--model", model_, "--views", "front,side", "--size", "120x160", "--out",
                 path("fill")})
                .code,
            kExitOk);
  for (const char* view : {"front", "side"}) {
    const render::Image img = render::read_png(path(std::string("fill_") + view + ".png"));
    // Skin pixels: clearly redder than blue; the background and the floor grid are grey.
    int x0 = img.width, x1 = -1, y0 = img.height, y1 = -1;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const std::uint8_t* p = img.pixel(x, y);
        if (p[0] > 30 && p[0] > p[2] * 1.15) {
          x0 = std::min(x0, x);
          x1 = std::max(x1, x);
          y0 = std::min(y0, y);
          y1 = std::max(y1, y);
        }
      }
    ASSERT_GE(x1, 0) << view << ": no body in the picture";
    const double fill = std::max(static_cast<double>(x1 - x0 + 1) / img.width,
                                 static_cast<double>(y1 - y0 + 1) / img.height);
    EXPECT_GE(fill, kMinFill) << view << " rows " << y0 << "-" << y1 << " columns " << x0 << "-"
                              << x1;
    EXPECT_TRUE(x0 > 0 && y0 > 0 && x1 < img.width - 1 && y1 < img.height - 1)
        << view << ": the body touches the border (cut off)";
  }
}
#endif

TEST_F(Commands, EvaluateTable1RunsOnAModel) {
  const CliRun r = run({"evaluate", "table1", "--model", model_, "-n", "10"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_TRUE(contains(r.out, "| R2 Mean |")) << r.out;
  EXPECT_TRUE(contains(r.out, "| noise-aware Max |")) << r.out;
  EXPECT_EQ(run({"evaluate", "nonsense", "--model", model_}).code, kExitUsage);
}

// Issue 17, item 13: the command line's details.
TEST_F(Commands, CreateWithoutOutSaysNothingWasWritten) {
  const CliRun r =
      run({"create", "--model", model_, "--height", "172cm", "--weight", "70kg", "--force"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_TRUE(contains(r.err, "no avatar file written")) << r.err;
  // Every format --out writes is named (.vrm and .fbx were missing).
  for (const char* ext : {".glb", ".gltf", ".vrm", ".fbx", ".obj", ".ply"})
    EXPECT_TRUE(contains(r.err, ext)) << ext << ": " << r.err;
  const CliRun w = run({"create", "--model", model_, "--height", "172cm", "--weight", "70kg",
                        "--force", "--out", path("a.obj")});
  EXPECT_FALSE(contains(w.err, "no avatar file written")) << w.err;
}

TEST_F(Commands, DecimalCommaIsADecimalPoint) {
  const CliRun r = run({"create", "--model", model_, "--height", "1,72m", "--weight", "70,5kg",
                        "--force", "--json"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  const Json j = parse_json(r.out);
  EXPECT_NEAR(j.at("achieved").at("height").as_number(), 1.72, kInputTolM);
  // A comma that is not between digits is still refused.
  EXPECT_EQ(run({"create", "--model", model_, "--height", "172,cm", "--weight", "70kg"}).code,
            kExitUsage);
}

// `caliper batch --ansur`: the survey's arm (acromion-radiale plus radiale-stylion, taken on the
// hanging arm) is mapped onto the model's virtual arm length (shoulder to wrist landmark in the
// T-pose) before R6 gets it, so the avatar's arm is the mapped value, not the survey's 7 cm
// longer one; the results' input column keeps what the survey measured.
TEST_F(Commands, BatchMapsTheSurveysHangingArmOntoTheVirtualArm) {
  std::ofstream(path("ansur.csv"))
      << "subjectid,stature,weightkg,span,crotchheight,hipbreadth,acromionradialelength,"
         "radialestylionlength,Gender\n"
         "1,1630,650,1660,780,350,310,240,Female\n";
  const std::string open = std::string(CALIPER_SOURCE_DIR) + "/assets/models/caliper-female.npz";
  const CliRun r = run({"batch", "--ansur", path("ansur.csv"), "--model", open, "--regressor", "R6",
                        "-j", "1", "--out", path("results.csv")});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  const CsvTable t = read_csv(path("results.csv"));
  ASSERT_EQ(t.rows.size(), 1u);
  const int achieved = t.column("arm_length_cm"), input = t.column("input_arm_length_cm");
  ASSERT_GE(achieved, 0);
  ASSERT_GE(input, 0);
  const double mapped = 100.0 * hanging_arm_map(smpl::load_model(open)).apply(0.550);
  EXPECT_NEAR(std::stod(t.rows[0][static_cast<size_t>(input)]), 55.0, 0.01);
  EXPECT_NEAR(std::stod(t.rows[0][static_cast<size_t>(achieved)]), mapped, 0.1);
  EXPECT_LT(mapped, 50.0);  // the virtual arm is much shorter than the survey's
}

// A tape on the hanging arm (`--arm-length-hanging`; an `arm_length_hanging_cm` column in
// batch): the model's own map turns it into its arm length, which R6 then reproduces; the
// report keeps the value as measured. Giving both arm lengths is refused.
TEST_F(Commands, CreateAndBatchMapATapeOnTheHangingArmOntoTheModelsArm) {
  const std::string open = std::string(CALIPER_SOURCE_DIR) + "/assets/models/caliper-female.npz";
  const double mapped = hanging_arm_map(smpl::load_model(open)).apply(0.550);
  EXPECT_LT(mapped, 0.50);  // the model's arm is much shorter than the hanging one
  const std::vector<std::string> six = {
      "--model", open,       "--height", "163cm",       "--weight", "65kg",        "--arm-span",
      "166cm",   "--inseam", "78cm",     "--hip-width", "35cm",     "--regressor", "R6"};
  std::vector<std::string> args = {"create", "--json", "--arm-length-hanging", "55cm"};
  args.insert(args.end(), six.begin(), six.end());
  const CliRun r = run(args);
  ASSERT_EQ(r.code, kExitOk) << r.err;
  const Json j = parse_json(r.out);
  EXPECT_NEAR(j.at("hanging_arm").at("measured").as_number(), 0.550, 1e-12);
  EXPECT_NEAR(j.at("hanging_arm").at("arm_length").as_number(), mapped, 1e-12);
  EXPECT_NEAR(j.at("input").at("arm_length").as_number(), mapped, 1e-12);
  EXPECT_NEAR(j.at("achieved").at("arm_length").as_number(), mapped, kInputTolM);
  args.push_back("--arm-length");
  args.push_back("50cm");
  const CliRun both = run(args);
  EXPECT_EQ(both.code, kExitUsage);
  EXPECT_TRUE(contains(both.err, "not both")) << both.err;

  std::ofstream(path("people.csv")) << "id,sex,height_cm,weight_kg,arm_span_cm,inseam_cm,"
                                       "hip_width_cm,arm_length_hanging_cm\n"
                                       "p1,F,163,65,166,78,35,55\n";
  const CliRun b = run({"batch", path("people.csv"), "--model", open, "--regressor", "R6", "-j",
                        "1", "--out", path("results.csv")});
  ASSERT_EQ(b.code, kExitOk) << b.err;
  const CsvTable t = read_csv(path("results.csv"));
  ASSERT_EQ(t.rows.size(), 1u);
  EXPECT_NEAR(std::stod(t.rows[0][static_cast<size_t>(t.column("input_arm_length_cm"))]), 55.0,
              0.01);
  EXPECT_NEAR(std::stod(t.rows[0][static_cast<size_t>(t.column("arm_length_cm"))]), 100.0 * mapped,
              0.1);
  std::ofstream(path("both.csv")) << "height_cm,weight_kg,arm_length_cm,arm_length_hanging_cm\n"
                                     "163,65,48,55\n";
  const CliRun bb = run({"batch", path("both.csv"), "--model", open, "--out", path("r2.csv")});
  EXPECT_EQ(bb.code, kExitRuntime);
  EXPECT_TRUE(contains(bb.err, "keep one of them")) << bb.err;
}

// The plausibility check judges what the survey measured (a 55 cm hanging arm for a 163 cm
// woman), not its mapping onto the model's virtual arm: on the small test model, whose arms are
// short, the mapped value is no human arm, and the person was refused with a value they never
// gave ("arm_length = 0.2038 m"). The avatar is made and says its shape is unusual instead.
TEST_F(Commands, BatchJudgesTheSurveysArmAsMeasured) {
  std::ofstream(path("ansur.csv"))
      << "subjectid,stature,weightkg,span,crotchheight,hipbreadth,acromionradialelength,"
         "radialestylionlength,Gender\n"
         "1,1630,650,1660,780,350,310,240,Female\n";
  const CliRun r = run({"batch", "--ansur", path("ansur.csv"), "--model", model_, "-j", "1",
                        "--out", path("results.csv")});
  EXPECT_EQ(r.code, kExitOk) << r.err;
  const CsvTable t = read_csv(path("results.csv"));
  ASSERT_EQ(t.rows.size(), 1u);
  EXPECT_EQ(t.rows[0][static_cast<size_t>(t.column("status"))], "ok");
  EXPECT_FALSE(contains(t.rows[0].back(), "implausible input")) << t.rows[0].back();
}

TEST_F(Commands, BatchCountsInWordsAndWarnsAboutMissingSex) {
  std::ofstream(path("people.csv")) << "id,sex,height_cm,weight_kg\n"
                                       "a,,170,62\n";
  // One open model per sex (no --model): the empty cell is reported, not silently neutral.
  std::filesystem::create_directories(dir_ / "assets" / "models");
  smpl::save_model(test::cli_test_model("neutral"), path("assets/models/caliper-neutral.npz"));
  const char* before = std::getenv("CALIPER_ASSETS");
  const std::string saved = before != nullptr ? before : "";
  setenv("CALIPER_ASSETS", path("assets").c_str(), 1);
  const CliRun r =
      run({"batch", path("people.csv"), "-j", "1", "--out", path("results.csv"), "--force"});
  if (before != nullptr)
    setenv("CALIPER_ASSETS", saved.c_str(), 1);
  else
    unsetenv("CALIPER_ASSETS");
  EXPECT_TRUE(contains(r.err, "1 person has no sex")) << r.err;
  const CliRun m = run({"batch", path("people.csv"), "--model", model_, "-j", "1", "--out",
                        path("results.csv"), "--force"});
  EXPECT_TRUE(contains(m.err, "1 person in")) << m.err;
  EXPECT_TRUE(contains(m.err, "1 job;")) << m.err;
  EXPECT_TRUE(contains(m.err, "0 errors")) << m.err;
  EXPECT_FALSE(contains(m.err, "1 people")) << m.err;
}

TEST(Cli, EveryCommandDefaultsToTheNeutralSex) {
  for (const char* cmd : {"create", "measure", "batch", "render", "evaluate"}) {
    std::ostringstream out, err;
    Io io{out, err, false};
    EXPECT_EQ(main_guarded({cmd, "--help"}, io), kExitOk) << cmd;
    const std::string help = out.str() + err.str();
    const size_t at = help.find("--sex");
    ASSERT_NE(at, std::string::npos) << cmd;
    const std::string line = help.substr(at, help.find('\n', help.find("neutral", at)) - at);
    EXPECT_TRUE(contains(line, "default neutral") || contains(line, "else neutral"))
        << cmd << ": " << line;
  }
}

TEST_F(Commands, PlausibilityNamesTheComponentsBeyond3Sd) {
  const CliRun r =
      run({"create", "--model", model_, "--height", "172cm", "--weight", "70kg", "--force"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  // "beyond 3 SD: none" or a count with component names ("1 (b0)"), never a bare index.
  EXPECT_TRUE(contains(r.out, "beyond 3 SD: none") || contains(r.out, "beyond 3 SD: 1 (b"))
      << r.out;
  EXPECT_TRUE(contains(r.out, "share of people")) << r.out;
}

TEST_F(Commands, ImperialInputGetsAnImperialReport) {
  const CliRun r =
      run({"create", "--model", model_, "--height", "5ft8in", "--weight", "154lb", "--force"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_TRUE(contains(r.out, "68.0 in (172.7 cm)")) << r.out;
  EXPECT_TRUE(contains(r.out, "154.0 lb (69.9 kg)")) << r.out;
  const CliRun m =
      run({"create", "--model", model_, "--height", "172cm", "--weight", "70kg", "--force"});
  EXPECT_FALSE(contains(m.out, " in (")) << m.out;
}

TEST_F(Commands, BatchColumnsHoldOnlyWhatWasComputed) {
  std::ofstream(path("people.csv")) << "id,sex,height_cm,weight_kg\n"
                                       "a,female,170,62\n";
  const CliRun r = run({"batch", path("people.csv"), "--model", model_, "-j", "1", "--out",
                        path("plain.csv"), "--force"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  const CsvTable t = read_csv(path("plain.csv"));
  for (const std::string& h : t.header) {
    EXPECT_EQ(h.find("circumference"), std::string::npos) << h;
  }
  // The test model's regressors set its first betas; no always-zero columns after them.
  const int k = test::cli_test_model("female").num_betas();
  int beta_columns = 0;
  for (const std::string& h : t.header) beta_columns += h.rfind("beta", 0) == 0;
  EXPECT_GT(beta_columns, 0);
  EXPECT_LE(beta_columns, std::min(k, 10));
  const CliRun c = run({"batch", path("people.csv"), "--model", model_, "-j", "1", "--out",
                        path("circ.csv"), "--force", "--circumferences"});
  ASSERT_EQ(c.code, kExitOk) << c.err;
  const CsvTable tc = read_csv(path("circ.csv"));
  const int chest = tc.column("chest_circumference_cm");
  ASSERT_GE(chest, 0);
  EXPECT_FALSE(tc.rows[0][static_cast<size_t>(chest)].empty());
}

TEST(Cli, MistypedCommandGetsASuggestionAndOneHelpPointer) {
  std::ostringstream out, err;
  Io io{out, err, false};
  EXPECT_EQ(main_guarded({"creat"}, io), kExitUsage);
  EXPECT_TRUE(contains(err.str(), "did you mean create?")) << err.str();
  EXPECT_EQ(err.str().find("--help"), err.str().rfind("--help")) << err.str();
  std::ostringstream out2, err2;
  Io io2{out2, err2, false};
  EXPECT_EQ(main_guarded({"create", "--heigth", "1m"}, io2), kExitUsage);
  EXPECT_EQ(err2.str().find("--help"), err2.str().rfind("--help")) << err2.str();
}

TEST(Cli, VersionHelpAndUnknownCommand) {
  std::ostringstream out, err;
  Io io{out, err, false};
  EXPECT_EQ(main_guarded({"--version"}, io), kExitOk);
  EXPECT_EQ(out.str(), version_string() + "\n");
  EXPECT_EQ(main_guarded({"frobnicate"}, io), kExitUsage);
  EXPECT_TRUE(contains(err.str(), "caliper: error: unknown command 'frobnicate'"));
  EXPECT_EQ(main_guarded({}, io), kExitUsage);
}

}  // namespace
}  // namespace caliper::cli
