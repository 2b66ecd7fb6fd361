/// \file generator.cpp
/// The open body model generator (see generator.hpp).
///
/// Sections: RNG; population sampling; topology (subdivision, triangles, landmarks, regressor,
/// skinning weights, mirror); measurements; calibration; PCA; assembly.
#include "generator.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "cage.hpp"
#include "caliper/circumference.hpp"
#include "caliper/portable_math.hpp"
#include "caliper/volume.hpp"
#include "caliper/weight.hpp"
#include "smpl/constants.hpp"
#include "smpl/text.hpp"
#include "subdivision.hpp"

namespace modelgen {

// libm's transcendental functions differ in the last bit between CPUs (portable_math.hpp).
namespace pm = caliper::portable;

// ------------------------------------------------------------------------------------ RNG

double Rng::uniform() {
  return (static_cast<double>(next() >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

double Rng::normal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = uniform(), u2 = uniform();
  const double r = std::sqrt(-2.0 * pm::log(u1));
  const double t = 2.0 * smpl::kPi * u2;
  spare_ = r * pm::sin(t);
  has_spare_ = true;
  return r * pm::cos(t);
}

namespace {

using RowSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// ------------------------------------------------------------------------------------ sampling

/// Mapping from survey dimensions to cage inputs: x' = mean + offset + scale (x - mean).
struct DimMapping {
  Eigen::VectorXd offset = Eigen::VectorXd::Zero(kNumDims);
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(kNumDims);
  double bulk = 1.0;  ///< factor on the sampled weight that the body's volume is matched to
};

class Sampler {
 public:
  explicit Sampler(const SexStats& s) : stats_(s) {
    Eigen::LLT<Eigen::MatrixXd> llt(s.covariance());
    if (llt.info() != Eigen::Success) {
      throw std::runtime_error("survey covariance of " + s.sex + " is not positive definite");
    }
    l_ = llt.matrixL();
  }
  Eigen::VectorXd sample(Rng& rng, const DimMapping& map) const {
    Eigen::VectorXd z(kNumDims);
    for (int i = 0; i < kNumDims; ++i) {
      z[i] = std::clamp(rng.normal(), -3.0, 3.0);
    }
    const Eigen::VectorXd dev = l_ * z;
    Eigen::VectorXd x = stats_.mean + map.offset + map.scale.cwiseProduct(dev);
    for (int i = 0; i < kNumDims; ++i) {
      x[i] = std::clamp(x[i], stats_.mean[i] - 3.5 * stats_.sd[i],
                        stats_.mean[i] + 3.5 * stats_.sd[i]);
    }
    return x;
  }
  const SexStats& stats() const { return stats_; }

 private:
  const SexStats& stats_;
  Eigen::MatrixXd l_;
};

Eigen::MatrixXd cage_matrix(const Cage& c) {
  Eigen::MatrixXd p(static_cast<Eigen::Index>(c.positions.size()), 3);
  for (std::size_t i = 0; i < c.positions.size(); ++i) {
    p.row(static_cast<Eigen::Index>(i)) = c.positions[i];
  }
  return p;
}

// ------------------------------------------------------------------------------------ topology

ModelTopology build_topology(const Cage& cage, std::vector<int>* fine_face_points) {
  ModelTopology t;
  t.num_cage_vertices = static_cast<int>(cage.positions.size());
  const Subdivision sub = catmull_clark(t.num_cage_vertices, cage.quads, 2);
  t.subdivision = sub.s;
  const int nv = static_cast<int>(sub.s.rows());
  t.faces.resize(static_cast<Eigen::Index>(sub.quads.size() * 2), 3);
  for (std::size_t q = 0; q < sub.quads.size(); ++q) {
    const auto& f = sub.quads[q];
    t.faces.row(static_cast<Eigen::Index>(2 * q)) << f[0], f[1], f[2];
    t.faces.row(static_cast<Eigen::Index>(2 * q + 1)) << f[0], f[2], f[3];
  }
  t.landmarks = cage.landmarks;
  for (const auto& [name, faces] : cage.face_landmarks) {
    std::vector<int> ids;
    for (int f : faces) {
      ids.push_back(sub.face_point[static_cast<std::size_t>(f)]);
    }
    t.landmarks[name] = ids;
  }
  if (fine_face_points) {
    *fine_face_points = sub.face_point;
  }
  // Joint regressor: cage vertex k keeps index k in the refined mesh.
  std::vector<Eigen::Triplet<double>> jt;
  for (int j = 0; j < 24; ++j) {
    for (const auto& [v, w] : cage.joints[static_cast<std::size_t>(j)]) {
      jt.emplace_back(j, v, w);
    }
  }
  t.j_regressor.resize(24, nv);
  t.j_regressor.setFromTriplets(jt.begin(), jt.end());
  // Skinning weights: cage weights smoothed over the cage graph, subdivided, pruned to 4.
  const int nc = t.num_cage_vertices;
  Eigen::MatrixXd wc = Eigen::MatrixXd::Zero(nc, 24);
  for (int v = 0; v < nc; ++v) {
    for (const auto& [j, w] : cage.skin[static_cast<std::size_t>(v)]) {
      wc(v, j) += w;
    }
  }
  std::vector<std::vector<int>> nbr(static_cast<std::size_t>(nc));
  for (const auto& q : cage.quads) {
    for (int k = 0; k < 4; ++k) {
      nbr[static_cast<std::size_t>(q[k])].push_back(q[(k + 1) % 4]);
      nbr[static_cast<std::size_t>(q[(k + 1) % 4])].push_back(q[k]);
    }
  }
  for (int it = 0; it < 3; ++it) {
    Eigen::MatrixXd next = wc;
    for (int v = 0; v < nc; ++v) {
      Eigen::RowVectorXd avg = Eigen::RowVectorXd::Zero(24);
      for (int n : nbr[static_cast<std::size_t>(v)]) {
        avg += wc.row(n);
      }
      avg /= static_cast<double>(nbr[static_cast<std::size_t>(v)].size());
      next.row(v) = 0.6 * wc.row(v) + 0.4 * avg;
    }
    wc = next;
  }
  const Eigen::MatrixXd wf = sub.s * wc;
  std::vector<Eigen::Triplet<double>> wt;
  for (int v = 0; v < nv; ++v) {
    std::vector<std::pair<double, int>> row;
    for (int j = 0; j < 24; ++j) {
      if (wf(v, j) > 1e-9) {
        row.emplace_back(wf(v, j), j);
      }
    }
    std::sort(row.begin(), row.end(), [](const auto& a, const auto& b) {
      return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    if (row.size() > 4) {
      row.resize(4);
    }
    double sum = 0;
    for (const auto& r : row) {
      sum += r.first;
    }
    for (const auto& r : row) {
      wt.emplace_back(v, r.second, r.first / sum);
    }
  }
  t.weights.resize(nv, 24);
  t.weights.setFromTriplets(wt.begin(), wt.end());
  return t;
}

std::vector<int> mirror_map(const smpl::Vertices& v) {
  const int n = static_cast<int>(v.rows());
  std::vector<std::pair<std::array<long long, 3>, int>> keys;
  keys.reserve(static_cast<std::size_t>(n));
  auto key = [](double x, double y, double z) {
    return std::array<long long, 3>{std::llround(x * 1e5), std::llround(y * 1e5),
                                    std::llround(z * 1e5)};
  };
  for (int i = 0; i < n; ++i) {
    keys.emplace_back(key(v(i, 0), v(i, 1), v(i, 2)), i);
  }
  std::sort(keys.begin(), keys.end());
  std::vector<int> m(static_cast<std::size_t>(n), -1);
  for (int i = 0; i < n; ++i) {
    const auto k = key(-v(i, 0), v(i, 1), v(i, 2));
    auto it = std::lower_bound(keys.begin(), keys.end(), std::make_pair(k, -1));
    int best = -1;
    if (it != keys.end() && it->first == k) {
      best = it->second;
    }
    if (best < 0 || (v.row(best) - Eigen::RowVector3d(-v(i, 0), v(i, 1), v(i, 2))).norm() > 1e-6) {
      double bd = 1e300;
      for (int j = 0; j < n; ++j) {
        const double dd = (v.row(j) - Eigen::RowVector3d(-v(i, 0), v(i, 1), v(i, 2))).norm();
        if (dd < bd) {
          bd = dd;
          best = j;
        }
      }
    }
    m[static_cast<std::size_t>(i)] = best;
  }
  return m;
}

// Aligned refined vertices of one cage: pelvis joint at the origin.
smpl::Vertices refine(const ModelTopology& t, const Eigen::MatrixXd& cage_pos,
                      const Eigen::RowVectorXd& pelvis_row) {
  const Eigen::RowVector3d pelvis = pelvis_row * cage_pos;
  Eigen::MatrixXd shifted = cage_pos.rowwise() - pelvis;
  smpl::Vertices out = t.subdivision * shifted;
  return out;
}

// Builds the cage of one sampled body. The girths the survey dimensions leave free (bulk, see
// build_cage()) are chosen per body so that the weight from volume matches the body's sampled
// weight (times the calibrated factor `map.bulk`): two secant steps on log(weight) vs log(bulk).
Cage body_cage(const Eigen::VectorXd& dims, bool female, double weight_factor,
               const ModelTopology& topo, const smpl::Faces& faces,
               const Eigen::RowVectorXd& pelvis_row, const caliper::WeightFormula& formula) {
  const double target = dims[kWeight] * weight_factor;
  auto weight_of = [&](const Cage& c) {
    const smpl::Vertices v = topo.subdivision * cage_matrix(c);
    (void)pelvis_row;
    return caliper::weight_from_volume(caliper::mesh_volume(v, faces), formula);
  };
  double b0 = 1.0;
  Cage c0 = build_cage(dims, female, b0);
  double w0 = weight_of(c0);
  double b1 = std::clamp(b0 * target / w0, 0.6, 1.8);
  Cage c1 = build_cage(dims, female, b1);
  const double w1 = weight_of(c1);
  const double slope = pm::log(w1 / w0) / pm::log(b1 / b0);
  if (!(std::abs(b1 - b0) > 1e-9) || !(slope > 0.2)) {
    return c1;
  }
  const double b2 = std::clamp(b1 * pm::pow(target / w1, 1.0 / slope), 0.6, 1.8);
  return build_cage(dims, female, b2);
}

}  // namespace

// ------------------------------------------------------------------------------------ measurements

namespace {

// The validation measurements in table order, each with its survey dimension (-1: arm_length,
// which is kAcromionRadiale + kRadialeStylion).
struct ValidationMeasure {
  const char* id;
  int dim;
};
constexpr ValidationMeasure kValidationMeasures[] = {{"stature", kStature},
                                                     {"weight", kWeight},
                                                     {"span", kSpan},
                                                     {"crotch_height", kCrotchHeight},
                                                     {"hip_breadth", kHipBreadth},
                                                     {"arm_length", -1},
                                                     {"biacromial", kBiacromial},
                                                     {"chest_circ", kChestCirc},
                                                     {"waist_circ", kWaistCirc},
                                                     {"buttock_circ", kButtockCirc}};

}  // namespace

const std::vector<std::string>& validation_ids() {
  static const std::vector<std::string> kIds = [] {
    std::vector<std::string> ids;
    for (const ValidationMeasure& m : kValidationMeasures) ids.emplace_back(m.id);
    return ids;
  }();
  return kIds;
}

int validation_dim(const std::string& id) {
  for (const ValidationMeasure& m : kValidationMeasures) {
    if (id == m.id) {
      return m.dim;
    }
  }
  return -1;
}

HangingArms hanging_arms(const smpl::BodyModel& model, const smpl::Vertices& vertices) {
  const caliper::LandmarkTable& lm = model.landmarks;
  const int kShoulder[2] = {16, 17};  // SMPL left_shoulder, right_shoulder
  const char* kAcromion[2] = {"left_shoulder", "right_shoulder"};
  const char* kWrist[2] = {"left_wrist", "right_wrist"};
  if (model.parents.size() <= 17 || model.j_regressor.rows() <= 17 ||
      model.weights.cols() != static_cast<Eigen::Index>(model.parents.size()) ||
      model.weights.rows() != vertices.rows() || model.j_regressor.cols() != vertices.rows()) {
    throw std::invalid_argument(
        "hanging arms: the model needs SMPL's joints (left and right shoulder are joints 16 and "
        "17) with a joint regressor and skinning weights for its " +
        std::to_string(vertices.rows()) + " vertices");
  }
  // Joints whose motion follows a shoulder rotation: the shoulder and its descendants.
  std::vector<char> follows[2];
  for (int s = 0; s < 2; ++s) {
    follows[s].assign(model.parents.size(), 0);
    follows[s][static_cast<std::size_t>(kShoulder[s])] = 1;
    for (std::size_t j = 0; j < model.parents.size(); ++j) {
      const int p = model.parents[j];
      if (p >= 0 && follows[s][static_cast<std::size_t>(p)]) {
        follows[s][j] = 1;
      }
    }
  }
  auto landmark = [&](const char* name) -> std::vector<int> {
    const auto it = lm.find(name);
    if (it == lm.end() || it->second.empty()) {
      throw std::invalid_argument(std::string("hanging arms: the model has no landmark '") + name +
                                  "'");
    }
    return it->second;
  };
  HangingArms out;
  for (int s = 0; s < 2; ++s) {
    Eigen::Vector3d joint = Eigen::Vector3d::Zero();
    for (smpl::SparseMatrix::InnerIterator it(model.j_regressor, kShoulder[s]); it; ++it) {
      joint += it.value() * vertices.row(it.col()).transpose();
    }
    // T-pose arm along +x (left) or -x (right); hanging: rotated 90 degrees down about z.
    const double sign = s == 0 ? -1.0 : 1.0;
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(sign * 0.5 * smpl::kPi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    Eigen::Vector3d acromion = Eigen::Vector3d::Zero();
    const std::vector<int> a = landmark(kAcromion[s]);
    for (int v : a) {
      acromion += vertices.row(v).transpose() / static_cast<double>(a.size());
    }
    Eigen::Vector3d wrist = Eigen::Vector3d::Zero();
    const std::vector<int> w = landmark(kWrist[s]);
    for (int v : w) {
      // Linear blend skinning restricted to the shoulder rotation: the share of the vertex's
      // weight on joints that follow the shoulder moves with it.
      double moving = 0;
      for (smpl::SparseMatrix::InnerIterator it(model.weights, v); it; ++it) {
        if (follows[s][static_cast<std::size_t>(it.col())]) {
          moving += it.value();
        }
      }
      const Eigen::Vector3d p = vertices.row(v).transpose();
      wrist += (p + moving * (r * (p - joint) + joint - p)) / static_cast<double>(w.size());
    }
    out.acromion[s] = acromion;
    out.wrist[s] = wrist;
  }
  return out;
}

double hanging_arm_length(const smpl::BodyModel& model, const smpl::Vertices& vertices) {
  const HangingArms h = hanging_arms(model, vertices);
  return 0.5 * ((h.wrist[0] - h.acromion[0]).norm() + (h.wrist[1] - h.acromion[1]).norm());
}

std::map<std::string, double> validation_measurements(const smpl::BodyModel& model,
                                                      const smpl::Vertices& vertices) {
  const caliper::LandmarkTable& lm = model.landmarks;
  const caliper::MeasurementMap m = caliper::measure(vertices, lm);
  const caliper::MeasurementMap c = caliper::circumferences(vertices, model.faces, lm);
  const double volume = caliper::mesh_volume(vertices, model.faces);
  std::map<std::string, double> out;
  auto get = [](const caliper::MeasurementMap& mm, const std::string& k) {
    const auto it = mm.find(k);
    return it == mm.end() ? std::nan("") : it->second;
  };
  out["stature"] = get(m, "height");
  out["weight"] =
      caliper::weight_from_volume(volume, caliper::weight_formula_for(model.meta.gender));
  out["span"] = get(m, "arm_span_fingertips");
  out["crotch_height"] = get(m, "inseam_height");
  out["hip_breadth"] = get(m, "hip_width");
  out["arm_length"] = hanging_arm_length(model, vertices);
  out["arm_length_tpose"] = get(m, "arm_length");
  out["biacromial"] = get(m, "shoulder_width");
  out["chest_circ"] = get(c, "chest_circumference");
  out["waist_circ"] = get(c, "waist_circumference");
  out["buttock_circ"] = get(c, "hip_circumference");
  return out;
}

// ------------------------------------------------------------------------------------ generation

namespace {

struct Population {
  Eigen::MatrixXd x;  // N x 3 Vc, aligned cage coordinates (row: x0 y0 z0 x1 ...)
};

void log_line(GenerationReport* r, const std::string& s) {
  if (r) {
    r->lines.push_back(s);
  }
}

// Calibrates the dimension mapping of one sex so that measured means and SDs of the refined
// population match the survey.
DimMapping calibrate(const Sampler& sampler, bool female, const ModelTopology& topo,
                     const smpl::BodyModel& proto, const Eigen::RowVectorXd& pelvis_row,
                     const GeneratorOptions& opt, GenerationReport* report) {
  DimMapping map;
  const std::vector<std::string>& ids = validation_ids();
  const caliper::WeightFormula formula = caliper::weight_formula_for(female ? "female" : "male");
  for (int round = 0; round < opt.calibration_rounds; ++round) {
    Rng rng(opt.seed ^ (female ? 0xf0ull : 0x0full) ^ (static_cast<std::uint64_t>(round) << 32));
    const int n = opt.calibration_bodies;
    std::map<std::string, std::vector<double>> vals;
    for (int b = 0; b < n; ++b) {
      const Eigen::VectorXd x = sampler.sample(rng, map);
      const Cage cage = body_cage(x, female, map.bulk, topo, proto.faces, pelvis_row, formula);
      const smpl::Vertices v = refine(topo, cage_matrix(cage), pelvis_row);
      const auto m = validation_measurements(proto, v);
      for (const auto& [k, val] : m) {
        vals[k].push_back(val);
      }
    }
    std::string line = std::string(female ? "female" : "male") + " calibration round " +
                       std::to_string(round) + ":";
    for (const std::string& id : ids) {
      const int d = validation_dim(id);
      if (d < 0) {
        continue;
      }
      const auto& v = vals[id];
      double mean = 0, var = 0;
      for (double x : v) {
        mean += x;
      }
      mean /= static_cast<double>(v.size());
      for (double x : v) {
        var += (x - mean) * (x - mean);
      }
      const double sd = std::sqrt(var / static_cast<double>(v.size() - 1));
      const double tm = sampler.stats().mean[d], ts = sampler.stats().sd[d];
      if (d == kWeight) {
        map.bulk *= tm / mean;
      } else {
        map.offset[d] += tm - mean;
        map.scale[d] *= std::clamp(ts / sd, 0.7, 1.4);
      }
      line += " " + id + " " + smpl::format_fixed(mean, 4) + "/" + smpl::format_fixed(tm, 4);
    }
    log_line(report, line);
  }
  return map;
}

// Orthonormal basis of the columns of m.
Eigen::MatrixXd orth(const Eigen::MatrixXd& m) {
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(m);
  return qr.householderQ() * Eigen::MatrixXd::Identity(m.rows(), m.cols());
}

// `opt.population` bodies sampled from the survey (sexes alternating), as cages with the pelvis
// joint at the origin: one row per body, x, y, z of every cage vertex.
Eigen::MatrixXd sample_population(std::vector<Sampler>& samplers,
                                  const std::vector<DimMapping>& maps,
                                  const std::vector<std::string>& sexes, const ModelTopology& topo,
                                  const Eigen::RowVectorXd& pelvis_row,
                                  const GeneratorOptions& opt) {
  const int nc = topo.num_cage_vertices;
  const int n = opt.population;
  Eigen::MatrixXd x(n, 3 * nc);
  Rng rng(opt.seed);
  for (int b = 0; b < n; ++b) {
    const std::size_t s = static_cast<std::size_t>(b % static_cast<int>(sexes.size()));
    const Eigen::VectorXd dims = samplers[s].sample(rng, maps[s]);
    const Cage cage = body_cage(dims, sexes[s] == "female", maps[s].bulk, topo, topo.faces,
                                pelvis_row, caliper::weight_formula_for(sexes[s]));
    Eigen::MatrixXd p = cage_matrix(cage);
    const Eigen::RowVector3d pelvis = pelvis_row * p;
    p.rowwise() -= pelvis;
    for (int v = 0; v < nc; ++v) {
      x.block(b, 3 * Eigen::Index{v}, 1, 3) = p.row(v);
    }
  }
  return x;
}

// S3 = S (x) I3: the subdivision matrix acting on x, y, z rows (3V x 3C).
RowSparse subdivision_xyz(const RowSparse& subdivision, int nv, int nc) {
  RowSparse s3(3 * Eigen::Index{nv}, 3 * Eigen::Index{nc});
  std::vector<Eigen::Triplet<double>> tr;
  for (int r = 0; r < nv; ++r) {
    for (RowSparse::InnerIterator it(subdivision, r); it; ++it) {
      for (int c = 0; c < 3; ++c) {
        tr.emplace_back(3 * r + c, 3 * static_cast<int>(it.col()) + c, it.value());
      }
    }
  }
  s3.setFromTriplets(tr.begin(), tr.end());
  return s3;
}

// The principal components of the refined population: unit directions scaled by their standard
// deviations (3V x k), and the share of the variance each explains.
struct Components {
  Eigen::MatrixXd shapedirs;
  Eigen::VectorXd explained;
};

// PCA over refined vertices of the centred population `x` (N x 3C): A = X S3^T (N x 3V), never
// formed. Randomized subspace iteration (Halko, Martinsson and Tropp 2011) with a fixed seed.
Components principal_components(const Eigen::MatrixXd& x, const ModelTopology& topo,
                                const GeneratorOptions& opt) {
  const int nc = topo.num_cage_vertices;
  const int nv = static_cast<int>(topo.subdivision.rows());
  const int n = opt.population;
  const RowSparse s3 = subdivision_xyz(topo.subdivision, nv, nc);
  const RowSparse s3t = s3.transpose();
  auto apply_a = [&](const Eigen::MatrixXd& w) -> Eigen::MatrixXd {  // (3V x l) -> (N x l)
    const Eigen::MatrixXd z = s3t * w;
    return x * z;
  };
  auto apply_at = [&](const Eigen::MatrixXd& y) -> Eigen::MatrixXd {  // (N x l) -> (3V x l)
    const Eigen::MatrixXd z = x.transpose() * y;
    return s3 * z;
  };
  const int k = opt.components;
  const int l = k + 10;
  Eigen::MatrixXd omega(3 * nv, l);
  {
    Rng rng(opt.seed + 17);
    for (int c = 0; c < l; ++c) {
      for (int r = 0; r < 3 * nv; ++r) {
        omega(r, c) = rng.normal();
      }
    }
  }
  Eigen::MatrixXd q = orth(apply_a(omega));
  for (int it = 0; it < 6; ++it) {
    const Eigen::MatrixXd z = orth(apply_at(q));
    q = orth(apply_a(z));
  }
  const Eigen::MatrixXd bt = apply_at(q);  // 3V x l = A^T Q
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(bt.transpose() * bt);
  double total = 0;
  for (int b = 0; b < n; ++b) {
    Eigen::MatrixXd p(nc, 3);
    for (int v = 0; v < nc; ++v) {
      p.row(v) = x.block(b, 3 * Eigen::Index{v}, 1, 3);
    }
    total += (topo.subdivision * p).squaredNorm();
  }
  Eigen::MatrixXd shapedirs(3 * nv, k);
  Eigen::VectorXd explained(k);
  for (int c = 0; c < k; ++c) {
    const int e = l - 1 - c;  // eigenvalues ascending
    const double sigma2 = std::max(es.eigenvalues()[e], 0.0);
    const double sigma = std::sqrt(sigma2);
    Eigen::VectorXd dir = bt * es.eigenvectors().col(e) / sigma;
    Eigen::Index imax = 0;
    dir.cwiseAbs().maxCoeff(&imax);
    if (dir[imax] < 0) {
      dir = -dir;
    }
    shapedirs.col(c) = dir * sigma / std::sqrt(static_cast<double>(n - 1));
    explained[c] = sigma2 / total;
  }
  return {shapedirs, explained};
}

// The model: the mean body, the components, the topology's joints, weights and landmarks.
smpl::BodyModel assemble_model(const ModelTopology& topo, const Eigen::RowVectorXd& mean,
                               const Eigen::MatrixXd& shapedirs, const std::string& gender,
                               const GeneratorOptions& opt) {
  const int nc = topo.num_cage_vertices;
  const int nv = static_cast<int>(topo.subdivision.rows());
  const int k = opt.components;
  const int n = opt.population;
  smpl::BodyModel model;
  Eigen::MatrixXd mean_cage_pos(nc, 3);
  for (int v = 0; v < nc; ++v) {
    mean_cage_pos.row(v) = mean.segment(3 * Eigen::Index{v}, 3);
  }
  model.v_template = topo.subdivision * mean_cage_pos;
  model.faces = topo.faces;
  model.shapedirs = shapedirs;
  model.posedirs = Eigen::MatrixXd(3 * nv, 0);
  model.j_regressor = topo.j_regressor;
  model.weights = topo.weights;
  model.parents = smpl::smpl_parents();
  model.joint_names = smpl::smpl_joint_names();
  model.landmarks = topo.landmarks;
  model.mirror = mirror_map(model.v_template);
  model.meta.name = "caliper-open-" + gender;
  model.meta.gender = gender;
  model.meta.source = "caliper-modelgen (The Virtual Caliper project)";
  model.meta.extra["licence"] = "MIT (the project's licence); free for any use";
  model.meta.extra["survey"] = "ANSUR II 2012 public release (US Army), statistics only";
  model.meta.extra["components"] = std::to_string(k);
  model.meta.extra["population"] = std::to_string(n);
  model.meta.extra["pose_blend_shapes"] = "none (posedirs has 0 columns)";
  return model;
}

}  // namespace

DeterministicNumerics::DeterministicNumerics()
    : l1_(Eigen::l1CacheSize()), l2_(Eigen::l2CacheSize()), l3_(Eigen::l3CacheSize()) {
  Eigen::setCpuCacheSizes(std::ptrdiff_t{32} * 1024, std::ptrdiff_t{512} * 1024,
                          std::ptrdiff_t{4} * 1024 * 1024);
}

DeterministicNumerics::~DeterministicNumerics() {
  Eigen::setCpuCacheSizes(l1_, l2_, l3_);
}

smpl::BodyModel generate_model(const SurveyStats& stats, const std::string& gender,
                               const GeneratorOptions& opt, GenerationReport* report) {
  const DeterministicNumerics pinned;
  if (gender != "female" && gender != "male" && gender != "neutral") {
    throw std::invalid_argument("generate_model: gender must be female, male or neutral, not '" +
                                gender + "'");
  }
  // Topology from the mean body of the first sex (topology does not depend on the body).
  const bool topo_female = gender != "male";
  const Cage mean_cage = build_cage(stats.of(topo_female ? "female" : "male").mean, topo_female);
  const ModelTopology topo = build_topology(mean_cage, nullptr);
  const int nc = topo.num_cage_vertices;
  const int nv = static_cast<int>(topo.subdivision.rows());
  const Eigen::RowVectorXd pelvis_row =
      Eigen::RowVectorXd(topo.j_regressor.row(0)) * topo.subdivision;

  smpl::BodyModel proto;
  proto.faces = topo.faces;
  proto.landmarks = topo.landmarks;
  proto.j_regressor = topo.j_regressor;  // the hanging-arm measurement poses the shoulders
  proto.weights = topo.weights;
  proto.parents = smpl::smpl_parents();
  log_line(report, "cage: " + std::to_string(nc) + " vertices, " +
                       std::to_string(mean_cage.quads.size()) +
                       " quads; mesh: " + std::to_string(nv) + " vertices, " +
                       std::to_string(topo.faces.rows()) + " triangles");

  // Sexes in the population and their calibrated mappings.
  std::vector<std::string> sexes;
  if (gender == "neutral") {
    sexes = {"female", "male"};
  } else {
    sexes = {gender};
  }
  std::vector<Sampler> samplers;
  std::vector<DimMapping> maps;
  for (const std::string& s : sexes) {
    samplers.emplace_back(stats.of(s));
    proto.meta.gender = s;
    maps.push_back(calibrate(samplers.back(), s == "female", topo, proto, pelvis_row, opt, report));
  }
  proto.meta.gender = gender;

  // Population.
  const int n = opt.population;
  Eigen::MatrixXd x = sample_population(samplers, maps, sexes, topo, pelvis_row, opt);
  const Eigen::RowVectorXd mean = x.colwise().mean();
  x.rowwise() -= mean;

  const int k = opt.components;
  const Components pca = principal_components(x, topo, opt);
  const Eigen::VectorXd& explained = pca.explained;
  if (report) {
    report->explained_variance = explained;
  }
  log_line(report, "PCA: population " + std::to_string(n) + ", " + std::to_string(k) +
                       " components explain " + smpl::format_fixed(100.0 * explained.sum(), 2) +
                       " % of the variance");

  smpl::BodyModel model = assemble_model(topo, mean, pca.shapedirs, gender, opt);
  smpl::validate(model, model.meta.name);
  return model;
}

// ------------------------------------------------------------------------------------ validation

ValidationFigures survey_figures(const SurveyStats& stats, const std::string& gender) {
  Eigen::VectorXd mu;
  Eigen::MatrixXd cov;
  int count = 0;
  if (gender == "neutral") {
    const Eigen::VectorXd df = stats.female.mean - stats.male.mean;
    mu = 0.5 * (stats.female.mean + stats.male.mean);
    cov = 0.5 * (stats.female.covariance() + stats.male.covariance()) + 0.25 * df * df.transpose();
    count = stats.female.count + stats.male.count;
  } else {
    const SexStats& s = stats.of(gender);
    mu = s.mean;
    cov = s.covariance();
    count = s.count;
  }
  ValidationFigures f;
  f.count = count;
  for (const std::string& id : validation_ids()) {
    const int d = validation_dim(id);
    if (d >= 0) {
      f.mean[id] = mu[d];
      f.sd[id] = std::sqrt(cov(d, d));
    } else {
      f.mean[id] = mu[kAcromionRadiale] + mu[kRadialeStylion];
      f.sd[id] = std::sqrt(cov(kAcromionRadiale, kAcromionRadiale) +
                           cov(kRadialeStylion, kRadialeStylion) +
                           2 * cov(kAcromionRadiale, kRadialeStylion));
    }
  }
  auto corr = [&](int a, int b) { return cov(a, b) / std::sqrt(cov(a, a) * cov(b, b)); };
  f.corr_stature_span = corr(kStature, kSpan);
  f.corr_stature_weight = corr(kStature, kWeight);
  return f;
}

ValidationFigures model_figures(const smpl::BodyModel& model, int samples, std::uint64_t seed,
                                const SurveyPopulation* population) {
  const DeterministicNumerics pinned;
  Rng rng(seed);
  std::map<std::string, std::vector<double>> vals;
  Eigen::VectorXd betas(model.num_betas());
  const Eigen::MatrixXd factor = population ? sampling_factor(population->cov) : Eigen::MatrixXd();
  for (int b = 0; b < samples; ++b) {
    for (int k = 0; k < betas.size(); ++k) {
      betas[k] = rng.normal();
    }
    if (population) betas = population->mean + factor * betas;
    const Eigen::VectorXd flat = model.shapedirs * betas;
    smpl::Vertices v = model.v_template;
    for (int i = 0; i < v.rows(); ++i) {
      for (int c = 0; c < 3; ++c) {
        v(i, c) += flat[3 * i + c];
      }
    }
    for (const auto& [k, x] : validation_measurements(model, v)) {
      vals[k].push_back(x);
    }
  }
  ValidationFigures f;
  f.count = samples;
  auto moments = [](const std::vector<double>& x, double& mean, double& sd) {
    mean = 0;
    for (double v : x) {
      mean += v;
    }
    mean /= static_cast<double>(x.size());
    double var = 0;
    for (double v : x) {
      var += (v - mean) * (v - mean);
    }
    sd = std::sqrt(var / static_cast<double>(x.size() - 1));
  };
  for (const auto& [k, x] : vals) {
    moments(x, f.mean[k], f.sd[k]);
  }
  auto corr = [&](const std::string& a, const std::string& b) {
    const auto& xa = vals[a];
    const auto& xb = vals[b];
    double c = 0;
    for (std::size_t i = 0; i < xa.size(); ++i) {
      c += (xa[i] - f.mean[a]) * (xb[i] - f.mean[b]);
    }
    c /= static_cast<double>(xa.size() - 1);
    return c / (f.sd[a] * f.sd[b]);
  };
  f.corr_stature_span = corr("stature", "span");
  f.corr_stature_weight = corr("stature", "weight");
  return f;
}

}  // namespace modelgen
