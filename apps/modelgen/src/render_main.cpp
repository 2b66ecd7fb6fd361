/// \file render_main.cpp
/// caliper-modelgen-render: the model card's pictures, rendered headless (OSMesa) with the
/// project's renderer: front, side and three-quarter views of the mean body and of +/- 2 SD
/// along the first three shape components (one picture per component: -2 SD, mean, +2 SD);
/// optionally the body in a test pose (--pose), avatars of one height at BMI 18, 25, 35, 45 and
/// 55 from the model's own R2 regressor (--bmi HEIGHT), close-ups of the face and the left hand
/// (--closeups), and a checker pattern through the texture coordinates (--checker).
///
///   caliper-modelgen-render assets/models/caliper-female.npz docs/images/model-female
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "app/cli_style.hpp"
#include "caliper/avatar.hpp"
#include "caliper/regressor.hpp"
#include "caliper/shape_curve.hpp"
#include "render/render_mesh.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/export.hpp"
#include "smpl/io.hpp"

namespace {

/// Bodies side by side (1.9 m apart along x) as one mesh, so that sizes compare at one scale.
void render_row(const std::vector<smpl::Vertices>& bodies, const smpl::Faces& faces,
                const std::string& path, const caliper::render::RenderOptions& o) {
  const Eigen::Index nv = bodies.front().rows(), nf = faces.rows();
  const auto n = static_cast<Eigen::Index>(bodies.size());
  smpl::Vertices v(n * nv, 3);
  smpl::Faces f(n * nf, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    smpl::Vertices b = bodies[static_cast<size_t>(i)];
    b.col(0).array() += 1.9 * (static_cast<double>(i) - 0.5 * static_cast<double>(n - 1));
    v.middleRows(i * nv, nv) = b;
    f.middleRows(i * nf, nf) = faces.array() + static_cast<int>(i * nv);
  }
  caliper::render::render_mesh_png(v, f, path, o);
}

/// The faces whose three vertices all take most of their skinning weight from one of `joints`,
/// re-indexed into those vertices (`vertices` gets their positions from `body`).
smpl::Faces region(const smpl::BodyModel& model, const smpl::Vertices& body,
                   const std::vector<int>& joints, smpl::Vertices& vertices) {
  const Eigen::Index nv = model.num_vertices();
  std::vector<int> index(static_cast<size_t>(nv), -1);
  std::vector<Eigen::Index> kept;
  const Eigen::MatrixXd w = Eigen::MatrixXd(model.weights);
  for (Eigen::Index i = 0; i < nv; ++i) {
    Eigen::Index top = 0;
    w.row(i).maxCoeff(&top);
    if (std::find(joints.begin(), joints.end(), static_cast<int>(top)) == joints.end()) continue;
    index[static_cast<size_t>(i)] = static_cast<int>(kept.size());
    kept.push_back(i);
  }
  vertices.resize(static_cast<Eigen::Index>(kept.size()), 3);
  for (size_t k = 0; k < kept.size(); ++k)
    vertices.row(static_cast<Eigen::Index>(k)) = body.row(kept[k]);
  std::vector<Eigen::Vector3i> tris;
  for (Eigen::Index f = 0; f < model.num_faces(); ++f) {
    const int a = index[static_cast<size_t>(model.faces(f, 0))];
    const int b = index[static_cast<size_t>(model.faces(f, 1))];
    const int c = index[static_cast<size_t>(model.faces(f, 2))];
    if (a >= 0 && b >= 0 && c >= 0) tris.emplace_back(a, b, c);
  }
  smpl::Faces out(static_cast<Eigen::Index>(tris.size()), 3);
  for (size_t k = 0; k < tris.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = tris[k];
  return out;
}

/// Avatars of `height` metres at BMI 18, 25, 35, 45 and 55: betas from the model's plain R2
/// regressor (the paper's corner training; weight enters through the volume), from the model's
/// shape curve when it carries one (caliper create's path).
void render_bmi(const smpl::BodyModel& model, double height, const std::string& prefix,
                caliper::render::RenderOptions o) {
  caliper::TrainOptions t;
  t.noise_aware = false;
  const caliper::RegressorSet set = caliper::train_regressors(model, t);
  const caliper::LinearRegressor* r2 = set.find("R2");
  const std::optional<caliper::ShapeCurve> curve = caliper::shape_curve(model);
  const caliper::LandmarkTable landmarks = caliper::landmarks_for(model);
  std::vector<smpl::Vertices> bodies;
  for (const double bmi : {18.0, 25.0, 35.0, 45.0, 55.0}) {
    const Eigen::VectorXd b = caliper::linear_betas(
        model, *r2, caliper::MeasurementMap{{"height", height}, {"weight", bmi * height * height}},
        curve ? &*curve : nullptr, landmarks);
    Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
    betas.head(b.size()) = b;
    bodies.push_back(smpl::shape(model, betas).vertices);
  }
  o.view = "front";
  o.width = 1600;
  o.height = 400;
  o.fill = true;
  o.floor_grid = false;
  render_row(bodies, model.faces, prefix + "-bmi.png", o);
}

/// The mean body split at its texture seams, coloured by a checker of 24 x 24 cells over the
/// texture square (per vertex of the split mesh, so the cells' edges are soft): stretched cells
/// show stretched texture (a checker cannot show a flipped island: it is its own mirror image).
void render_checker(const smpl::BodyModel& model, const smpl::Vertices& mean,
                    const std::string& prefix, caliper::render::RenderOptions o) {
  const smpl::SeamSplit split = smpl::split_at_seams(model, "checker");
  const auto n = static_cast<Eigen::Index>(split.source.size());
  smpl::Vertices v(n, 3);
  o.vertex_colours.resize(static_cast<size_t>(3 * n));
  constexpr double kCells = 24.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    v.row(i) = mean.row(split.source[static_cast<size_t>(i)]);
    const auto cu = static_cast<long>(std::floor(split.uvs(i, 0) * kCells));
    const auto cv = static_cast<long>(std::floor(split.uvs(i, 1) * kCells));
    const bool dark = ((cu + cv) % 2) != 0;
    const float c[3] = {dark ? 0.25f : 0.95f, dark ? 0.30f : 0.85f, dark ? 0.55f : 0.60f};
    for (int k = 0; k < 3; ++k) o.vertex_colours[static_cast<size_t>(3 * i + k)] = c[k];
  }
  for (const char* view : {"front", "back"}) {
    o.view = view;
    caliper::render::render_mesh_png(v, split.faces, prefix + "-checker-" + view + ".png", o);
  }
}

struct RenderArgs {
  std::string model_path, prefix;
  int components = 3;
  bool pose = false, closeups = false, checker = false;
  double bmi_height = 0.0;
};

// Parses the command line into `args` in the programs' common style (app/cli_style.hpp); false
// when the program is done (--help printed: `code` 0; a usage error printed: `code` 2).
bool parse_args(int argc, char** argv, RenderArgs& args, int& code) {
  namespace app = caliper::app;
  CLI::App cli("", "caliper-modelgen-render");
  app::apply_style(
      cli, {{"caliper-modelgen-render MODEL.npz PREFIX [--components N] [--pose]",
             "                        [--bmi HEIGHT_M] [--closeups] [--checker]"},
            "Writes PREFIX-mean-{front,side,three_quarter}.png and PREFIX-pc<k>.png (-2 SD, mean,\n"
            "+2 SD) for k = 1..N; --pose: PREFIX-posed-{front,three_quarter}.png; --bmi:\n"
            "PREFIX-bmi.png (BMI 18, 25, 35, 45, 55 at that height, the model's R2); --closeups:\n"
            "PREFIX-face.png, PREFIX-hand.png; --checker: PREFIX-checker-{front,back}.png.",
            "exit codes: 0 ok, 1 error, 2 usage error"});
  app::add_value(cli, "--components", args.components, "N",
                 "components drawn at -2 SD, mean and +2 SD")
      ->check(app::non_negative());
  app::add_value(cli, "--bmi", args.bmi_height, "HEIGHT_M",
                 "height in metres of the BMI row, between 0.5 and 2.5 (e.g. 1.65)")
      ->default_str("")
      ->check(app::number_check([](double h) { return h >= 0.5 && h <= 2.5; },
                                "needs a height in metres between 0.5 and 2.5"));
  app::add_flag(cli, "--pose", args.pose, "the mean body in a test pose");
  app::add_flag(cli, "--closeups", args.closeups, "face and left hand of the mean body");
  app::add_flag(cli, "--checker", args.checker, "a checker texture through the UVs");
  try {
    const app::CommandLine line =
        app::parse_command_line(cli, std::vector<std::string>(argv + 1, argv + argc));
    if (line.help) {
      std::cout << cli.help();
      code = 0;
      return false;
    }
    if (line.positional.size() != 2)
      throw app::CommandLineError("give the model file and the output prefix (MODEL.npz PREFIX)");
    args.model_path = line.positional[0];
    args.prefix = line.positional[1];
    return true;
  } catch (const app::CommandLineError& e) {
    std::cerr << app::usage_error_line("caliper-modelgen-render", e.what());
    code = 2;
    return false;
  }
}

// The mean body in a test pose (elbows, a knee and a hip bent), front and three-quarter.
void render_posed(const smpl::BodyModel& model, const std::string& prefix,
                  caliper::render::RenderOptions o) {
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(3 * Eigen::Index{model.num_joints()});
  const Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
  const auto joint = [&theta](Eigen::Index k) { return theta.segment<3>(3 * k); };
  joint(18) = Eigen::Vector3d(0, -1.5708, 0);  // left elbow bent forward
  joint(19) = Eigen::Vector3d(0, 1.5708, 0);   // right elbow
  joint(4) = Eigen::Vector3d(1.5708, 0, 0);    // left knee
  joint(2) = Eigen::Vector3d(-1.5708, 0, 0);   // right hip flexed
  joint(16) = Eigen::Vector3d(0, 0, -1.2);     // left shoulder down
  const smpl::Body b = smpl::evaluate(model, betas, theta);
  for (const char* view : {"front", "three_quarter"}) {
    o.view = view;
    caliper::render::render_mesh_png(b.vertices, model.faces, prefix + "-posed-" + view + ".png",
                                     o);
  }
}

// Close-ups of the mean body's face and left hand.
void render_closeups(const smpl::BodyModel& model, const smpl::Vertices& mean,
                     const std::string& prefix, caliper::render::RenderOptions c) {
  c.fill = true;
  c.floor_grid = false;
  c.width = 480;
  c.height = 480;
  smpl::Vertices part;
  const smpl::Faces head = region(model, mean, {15}, part);  // head
  c.view = "front";
  caliper::render::render_mesh_png(part, head, prefix + "-face.png", c);
  const smpl::Faces hand = region(model, mean, {20, 22}, part);  // left wrist, hand
  c.azimuth_degrees = 0.0f;
  c.elevation_degrees = 80.0f;  // from above: the back of the T-posed hand
  caliper::render::render_mesh_png(part, hand, prefix + "-hand.png", c);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    RenderArgs args;
    int code = 0;
    if (!parse_args(argc, argv, args, code)) return code;
    const std::string& prefix = args.prefix;
    const smpl::BodyModel model = smpl::load_model(args.model_path);
    caliper::render::RenderOptions o;
    o.width = 480;
    o.height = 640;
    Eigen::VectorXd betas = Eigen::VectorXd::Zero(model.num_betas());
    const smpl::Body mean = smpl::shape(model, betas);
    for (const char* view : {"front", "side", "three_quarter"}) {
      o.view = view;
      caliper::render::render_mesh_png(mean.vertices, model.faces,
                                       prefix + "-mean-" + view + ".png", o);
    }
    // -2 SD, mean and +2 SD side by side in one picture, so that sizes compare at one scale.
    o.view = "front";
    o.width = 1200;
    o.height = 560;
    for (int k = 0; k < args.components && k < model.num_betas(); ++k) {
      std::vector<smpl::Vertices> bodies;
      for (int s = -1; s <= 1; ++s) {
        betas.setZero();
        betas[k] = 2.0 * s;
        bodies.push_back(smpl::shape(model, betas).vertices);
      }
      render_row(bodies, model.faces, prefix + "-pc" + std::to_string(k + 1) + ".png", o);
    }
    o.width = 480;
    o.height = 640;
    if (args.pose) render_posed(model, prefix, o);
    if (args.bmi_height > 0.0) render_bmi(model, args.bmi_height, prefix, o);
    if (args.closeups) render_closeups(model, mean.vertices, prefix, o);
    if (args.checker && model.has_uvs()) render_checker(model, mean.vertices, prefix, o);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "caliper-modelgen-render: " << e.what() << "\n";
    return 1;
  }
}
