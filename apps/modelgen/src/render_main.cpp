/// \file render_main.cpp
/// caliper-modelgen-render: the model card's pictures, rendered headless (OSMesa) with the
/// project's renderer: front, side and three-quarter views of the mean body and of +/- 2 SD
/// along the first three shape components (one picture per component: -2 SD, mean, +2 SD).
///
///   caliper-modelgen-render assets/models/caliper-female.npz docs/images/model-female
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>

#include "render/render_mesh.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/io.hpp"

int main(int argc, char** argv) {
  try {
    if (argc < 3) {
      std::cerr << "usage: caliper-modelgen-render MODEL.npz PREFIX [--components N] [--pose]\n"
                   "writes PREFIX-mean-{front,side,three_quarter}.png and\n"
                   "PREFIX-pc<k>.png (-2 SD, mean, +2 SD) for k = 1..N (default 3)\n";
      return 2;
    }
    const std::string model_path = argv[1], prefix = argv[2];
    int components = 3;
    bool pose = false;
    for (int i = 3; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--components" && i + 1 < argc) {
        components = std::stoi(argv[++i]);
      }
      if (a == "--pose") {
        pose = true;
      }
    }
    const smpl::BodyModel model = smpl::load_model(model_path);
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
    for (int k = 0; k < components && k < model.num_betas(); ++k) {
      const Eigen::Index nv = model.num_vertices(), nf = model.num_faces();
      smpl::Vertices v(3 * nv, 3);
      smpl::Faces f(3 * nf, 3);
      for (int s = -1; s <= 1; ++s) {
        betas.setZero();
        betas[k] = 2.0 * s;
        smpl::Vertices b = smpl::shape(model, betas).vertices;
        b.col(0).array() += 1.9 * s;
        const Eigen::Index slot = s + 1;
        v.middleRows(slot * nv, nv) = b;
        f.middleRows(slot * nf, nf) = model.faces.array() + static_cast<int>(slot * nv);
      }
      caliper::render::render_mesh_png(v, f, prefix + "-pc" + std::to_string(k + 1) + ".png", o);
    }
    o.width = 480;
    o.height = 640;
    if (pose) {
      Eigen::VectorXd theta = Eigen::VectorXd::Zero(3 * Eigen::Index{model.num_joints()});
      betas.setZero();
      const auto joint = [&theta](Eigen::Index k) { return theta.segment<3>(3 * k); };
      joint(18) = Eigen::Vector3d(0, -1.5708, 0);  // left elbow bent forward
      joint(19) = Eigen::Vector3d(0, 1.5708, 0);   // right elbow
      joint(4) = Eigen::Vector3d(1.5708, 0, 0);    // left knee
      joint(2) = Eigen::Vector3d(-1.5708, 0, 0);   // right hip flexed
      joint(16) = Eigen::Vector3d(0, 0, -1.2);     // left shoulder down
      const smpl::Body b = smpl::evaluate(model, betas, theta);
      for (const char* view : {"front", "three_quarter"}) {
        o.view = view;
        caliper::render::render_mesh_png(b.vertices, model.faces,
                                         prefix + "-posed-" + view + ".png", o);
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "caliper-modelgen-render: " << e.what() << "\n";
    return 1;
  }
}
