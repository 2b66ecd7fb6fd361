// Training sets for the shape regressors: Pujades et al., The Virtual Caliper, TVCG 2019,
// Sec. 3.4.3 (2^10 corners at +/-2 SD over the first 10 betas).
//
// Sections: beta sets (corners, seeded Gaussian); ShapeMeasurer (affine landmarks, exact floor
// candidates, volume as a cubic polynomial in beta); training sets.
//
// The volume cubic: with b~ = (1, beta) and every vertex x_v = X_v b~ (X_v: 3 x (k+1), column 0
// the template, columns 1..k the shape directions), a face contributes
// det(x_a, x_b, x_c) = sum_{i,j,l} b~_i b~_j b~_l det(A_i, B_j, C_l). Summing over faces once
// gives T[i][(j,l)] = sum_f A_i . (B_j x C_l + B_l x C_j) (j < l; j == l without the swap),
// evaluated as a matrix product over blocks of faces; then V(beta) = 1/6 b~' T w(b~) with
// w(b~)_(j,l) = b~_j b~_l.
#include "caliper/training.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include <Eigen/Geometry>

#include "caliper/errors.hpp"
#include "caliper/random.hpp"
#include "smpl/constants.hpp"

namespace caliper {

// ---------------------------------------------------------------------------------------------
// Beta sets

Eigen::MatrixXd corner_betas(int num_betas, double sd) {
  if (num_betas < 1 || num_betas > 20) {
    throw InvalidInputError("corner_betas: number of betas must be 1 to 20, got " +
                            std::to_string(num_betas));
  }
  if (!std::isfinite(sd) || sd <= 0.0) throw InvalidInputError("corner_betas: sd must be > 0");
  const long n = 1L << num_betas;
  Eigen::MatrixXd b(n, num_betas);
  for (long r = 0; r < n; ++r) {
    for (int i = 0; i < num_betas; ++i) b(r, i) = (r >> i) & 1 ? sd : -sd;
  }
  return b;
}

namespace {

/// Uniform in (0, 1] from 53 random bits.
double uniform_open_closed(Xoshiro256& rng) {
  return (static_cast<double>(rng.next() >> 11) + 1.0) * 0x1.0p-53;
}

constexpr double kTwoPi = 2 * smpl::kPi;

}  // namespace

Eigen::MatrixXd gaussian_betas(int count, int num_betas, std::uint64_t seed) {
  if (count < 1 || num_betas < 1) {
    throw InvalidInputError("gaussian_betas: count and number of betas must be >= 1, got " +
                            std::to_string(count) + " and " + std::to_string(num_betas));
  }
  Xoshiro256 rng(seed);
  Eigen::MatrixXd b(count, num_betas);
  const Eigen::Index total = b.size();
  for (Eigen::Index i = 0; i < total; i += 2) {
    const double r = std::sqrt(-2.0 * std::log(uniform_open_closed(rng)));
    const double t = kTwoPi * uniform_open_closed(rng);
    b(i / num_betas, i % num_betas) = r * std::cos(t);
    if (i + 1 < total) b((i + 1) / num_betas, (i + 1) % num_betas) = r * std::sin(t);
  }
  return b;
}

// ---------------------------------------------------------------------------------------------
// ShapeMeasurer

namespace {

// The volume as a cubic in b~ = (1, beta_1..k): K1 x K1 (K1 + 1) / 2, ShapeMeasurer::cubic_.
// From the divergence theorem with the field (x, 0, 0): a flat face contributes
// (x_a + x_b + x_c) N_x / 6, N = (x_b - x_a) x (x_c - x_a); the sum of x is affine in b~ and
// N_x quadratic, so T[i][(j,l)] = sum_f sx_i Q_(j,l) with Q the symmetrised N_x form.
Eigen::MatrixXd volume_cubic(const smpl::BodyModel& model, int k) {
  const int V = model.num_vertices();
  const int K1 = k + 1;
  const int npairs = K1 * (K1 + 1) / 2;
  Eigen::MatrixXd cubic = Eigen::MatrixXd::Zero(K1, npairs);
  using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  RowMat Xc[3];
  for (int c = 0; c < 3; ++c) {
    Xc[c].resize(V, K1);
    Xc[c].col(0) = model.v_template.col(c);
    for (int v = 0; v < V; ++v) Xc[c].row(v).tail(k) = model.shapedirs.block(3 * v + c, 0, 1, k);
  }
  const int F = model.num_faces();
  constexpr int kBlock = 1024;
  Eigen::MatrixXd Sblk(kBlock, K1), Qblk(kBlock, npairs);
  Eigen::RowVectorXd e1y(K1), e1z(K1), e2y(K1), e2z(K1);
  for (int f0 = 0; f0 < F; f0 += kBlock) {
    const int nf = std::min(kBlock, F - f0);
    for (int q = 0; q < nf; ++q) {
      const int f = f0 + q;
      const int ia = model.faces(f, 0), ib = model.faces(f, 1), ic = model.faces(f, 2);
      if (ia < 0 || ib < 0 || ic < 0 || ia >= V || ib >= V || ic >= V) {
        throw InvalidInputError("ShapeMeasurer: face " + std::to_string(f) +
                                " has a vertex index out of range");
      }
      Sblk.row(q) = Xc[0].row(ia) + Xc[0].row(ib) + Xc[0].row(ic);
      e1y = Xc[1].row(ib) - Xc[1].row(ia);
      e1z = Xc[2].row(ib) - Xc[2].row(ia);
      e2y = Xc[1].row(ic) - Xc[1].row(ia);
      e2z = Xc[2].row(ic) - Xc[2].row(ia);
      int pair = 0;
      for (int j = 0; j < K1; ++j) {
        Qblk(q, pair++) = e1y(j) * e2z(j) - e1z(j) * e2y(j);
        for (int l = j + 1; l < K1; ++l) {
          Qblk(q, pair++) = e1y(j) * e2z(l) - e1z(j) * e2y(l) + e1y(l) * e2z(j) - e1z(l) * e2y(j);
        }
      }
    }
    cubic.noalias() += Sblk.topRows(nf).transpose() * Qblk.topRows(nf);
  }
  cubic /= 6.0;
  return cubic;
}

}  // namespace

ShapeMeasurer::ShapeMeasurer(const smpl::BodyModel& model, const LandmarkTable& landmarks,
                             std::vector<MeasurementDef> defs, int num_betas)
    : defs_(std::move(defs)) {
  const int B = model.num_betas();
  const int V = model.num_vertices();
  num_betas_ = num_betas <= 0 ? std::min(10, B) : num_betas;
  if (num_betas_ > B || num_betas_ > kMaxMeasurerBetas || num_betas_ < 1) {
    throw InvalidInputError("ShapeMeasurer: " + std::to_string(num_betas_) +
                            " betas asked, the model '" + model.meta.name + "' has " +
                            std::to_string(B) + " (at most " + std::to_string(kMaxMeasurerBetas) +
                            " are supported, at least 1)");
  }
  if (V == 0 || model.faces.rows() == 0) {
    throw InvalidInputError("ShapeMeasurer: the model '" + model.meta.name + "' has no mesh");
  }
  if (model.shapedirs.rows() != 3 * static_cast<Eigen::Index>(V)) {
    throw InvalidInputError("ShapeMeasurer: shapedirs has " +
                            std::to_string(model.shapedirs.rows()) + " rows, expected 3 x " +
                            std::to_string(V));
  }
  // A model whose shape blend shapes are all zero cannot change shape: a broken model file,
  // not an implausible input (issue 10).
  if (model.shapedirs.leftCols(num_betas_).cwiseAbs().maxCoeff() == 0.0) {
    throw smpl::ModelError("model '" + model.meta.name + "': its shape blend shapes (shapedirs, " +
                           std::to_string(num_betas_) +
                           " components) are all zero, so no body shape can be made or fitted; "
                           "the model file is broken or was saved without them");
  }
  const int k = num_betas_;
  // Landmarks as affine maps of beta.
  std::map<std::string, int> index;
  const auto landmark = [&](const std::string& name, const std::string& id) {
    const auto it = index.find(name);
    if (it != index.end()) return it->second;
    const auto lm = landmarks.find(name);
    if (lm == landmarks.end()) {
      throw LandmarkError("measurement '" + id + "' needs landmark '" + name +
                          "', which the model '" + model.meta.name + "' does not define");
    }
    Affine a;
    a.p0.setZero();
    a.P = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, k);
    if (lm->second.empty()) throw LandmarkError("landmark '" + name + "' has no vertices");
    for (int v : lm->second) {
      if (v < 0 || v >= V) {
        throw LandmarkError("landmark '" + name + "' uses vertex " + std::to_string(v) +
                            ", out of range for the model '" + model.meta.name + "'");
      }
      a.p0 += model.v_template.row(v).transpose();
      a.P += model.shapedirs.block(3 * static_cast<Eigen::Index>(v), 0, 3, k);
    }
    a.p0 /= static_cast<double>(lm->second.size());
    a.P /= static_cast<double>(lm->second.size());
    points_.push_back(a);
    index[name] = static_cast<int>(points_.size()) - 1;
    return index[name];
  };
  for (const auto& d : defs_) {
    from_.push_back(landmark(d.from, d.id));
    to_.push_back(d.kind == MeasurementKind::Distance ? landmark(d.to, d.id) : -1);
  }
  // Heights for the floor.
  y0_ = model.v_template.col(1);
  ydirs_.resize(V, k);
  for (int v = 0; v < V; ++v) ydirs_.row(v) = model.shapedirs.block(3 * v + 1, 0, 1, k);
  ydir_norms_ = ydirs_.rowwise().norm();
  {
    std::vector<int> order(static_cast<std::size_t>(V));
    for (int v = 0; v < V; ++v) order[static_cast<std::size_t>(v)] = v;
    const int nref = std::min(V, 8);
    std::partial_sort(order.begin(), order.begin() + nref, order.end(),
                      [&](int a, int b) { return y0_(a) < y0_(b); });
    floor_refs_.assign(order.begin(), order.begin() + nref);
  }
  prepared_radius_ = std::max(2.0 * std::sqrt(static_cast<double>(k)), 5.0);
  candidates_ = floor_candidates(prepared_radius_);
  cubic_ = volume_cubic(model, k);  // the volume as a cubic in (1, beta)
}

std::vector<int> ShapeMeasurer::floor_candidates(double radius) const {
  // Necessary conditions for vertex v to be the lowest for some |beta| <= R (Cauchy-Schwarz):
  // (1) its lower bound y0_v - R |S_v| is below the smallest upper bound min_u y0_u + R |S_u|;
  // (2) for every reference vertex u (the template's lowest few), y_v <= y_u is possible:
  //     y0_v - y0_u <= R |S_v - S_u|. (2) is tight when the feet move together (relative
  //     motion small), (1) when the shape space is noisy; both are exact, never approximate.
  const Eigen::VectorXd upper = y0_ + radius * ydir_norms_;
  const double best_upper = upper.minCoeff();
  std::vector<int> out;
  for (Eigen::Index v = 0; v < y0_.size(); ++v) {
    if (y0_(v) - radius * ydir_norms_(v) > best_upper) continue;
    bool possible = true;
    for (int u : floor_refs_) {
      if (y0_(v) - y0_(u) > radius * (ydirs_.row(v) - ydirs_.row(u)).norm()) {
        possible = false;
        break;
      }
    }
    if (possible) out.push_back(static_cast<int>(v));
  }
  return out;
}

double ShapeMeasurer::floor_over(const Eigen::VectorXd& b, const std::vector<int>& cand) const {
  double lowest = std::numeric_limits<double>::infinity();
  const int n = static_cast<int>(b.size());
  for (int v : cand) {
    const double y = y0_(v) + ydirs_.row(v).head(n).dot(b);
    lowest = std::min(lowest, y);
  }
  return lowest;
}

namespace {
void check_betas(const Eigen::VectorXd& b, int k) {
  if (b.size() > k) {
    throw InvalidInputError(std::to_string(b.size()) + " betas given, the measurer handles " +
                            std::to_string(k));
  }
  if (!b.allFinite()) throw InvalidInputError("betas contain NaN or infinity");
}
}  // namespace

double ShapeMeasurer::floor(const Eigen::VectorXd& betas) const {
  check_betas(betas, num_betas_);
  const double r = betas.norm();
  if (r <= prepared_radius_) return floor_over(betas, candidates_);
  return floor_over(betas, floor_candidates(r));
}

double ShapeMeasurer::volume(const Eigen::VectorXd& betas) const {
  check_betas(betas, num_betas_);
  const int K1 = num_betas_ + 1;
  Eigen::VectorXd bt = Eigen::VectorXd::Zero(K1);
  bt.head(1).setOnes();
  bt.segment(1, betas.size()) = betas;
  Eigen::VectorXd w(cubic_.cols());
  int pair = 0;
  for (int j = 0; j < K1; ++j) {
    for (int l = j; l < K1; ++l) w(pair++) = bt(j) * bt(l);
  }
  return bt.dot(cubic_ * w);
}

Eigen::VectorXd ShapeMeasurer::measure(const Eigen::VectorXd& betas) const {
  check_betas(betas, num_betas_);
  const Eigen::Index n = betas.size();
  std::vector<Eigen::Vector3d> pts(points_.size());
  for (std::size_t i = 0; i < points_.size(); ++i) {
    pts[i] = points_[i].p0 + points_[i].P.leftCols(n) * betas;
  }
  bool need_floor = false;
  for (int t : to_) need_floor = need_floor || t < 0;
  const double fl = need_floor ? floor(betas) : 0.0;
  Eigen::VectorXd m(defs_.size());
  for (std::size_t d = 0; d < defs_.size(); ++d) {
    m(d) = to_[d] < 0 ? pts[from_[d]].y() - fl : (pts[from_[d]] - pts[to_[d]]).norm();
  }
  return m;
}

void ShapeMeasurer::measure_batch(const Eigen::MatrixXd& betas, Eigen::MatrixXd& measurements,
                                  Eigen::VectorXd& volumes) const {
  const Eigen::Index N = betas.rows(), k = betas.cols();
  if (k > num_betas_) {
    throw InvalidInputError("measure_batch: " + std::to_string(k) +
                            " beta columns, the measurer handles " + std::to_string(num_betas_));
  }
  if (!betas.allFinite()) throw InvalidInputError("measure_batch: betas contain NaN or infinity");
  const int K1 = num_betas_ + 1;
  Eigen::MatrixXd bt = Eigen::MatrixXd::Zero(N, K1);
  bt.col(0).setOnes();
  bt.middleCols(1, k) = betas;
  // Volumes: W (N x pairs) * cubic' -> N x K1, row-dot with b~.
  Eigen::MatrixXd W(N, cubic_.cols());
  int pair = 0;
  for (int j = 0; j < K1; ++j) {
    for (int l = j; l < K1; ++l) W.col(pair++) = bt.col(j).cwiseProduct(bt.col(l));
  }
  const Eigen::MatrixXd G = W * cubic_.transpose();
  volumes = G.cwiseProduct(bt).rowwise().sum();
  // Floors: candidate heights for every body.
  bool need_floor = false;
  for (int t : to_) need_floor = need_floor || t < 0;
  Eigen::VectorXd floors = Eigen::VectorXd::Zero(N);
  if (need_floor && N > 0) {
    // Exact early termination: candidates sorted by their lower bound y0_v - R |S_v| (R the
    // largest |beta| of the batch); a body's scan stops at the first bound above its best height,
    // which is seeded by the template's lowest vertices.
    const double r = betas.rowwise().norm().maxCoeff();
    std::vector<int> cand = r <= prepared_radius_ ? candidates_ : floor_candidates(r);
    const double R = std::max(r, r <= prepared_radius_ ? prepared_radius_ : r);
    std::sort(cand.begin(), cand.end(), [&](int a, int b) {
      return y0_(a) - R * ydir_norms_(a) < y0_(b) - R * ydir_norms_(b);
    });
    const auto nc = static_cast<Eigen::Index>(cand.size());
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Yc(nc, k);
    Eigen::VectorXd y0c(nc), lower(nc);
    for (Eigen::Index c = 0; c < nc; ++c) {
      const int v = cand[static_cast<std::size_t>(c)];
      Yc.row(c) = ydirs_.row(v).head(k);
      y0c(c) = y0_(v);
      lower(c) = y0_(v) - R * ydir_norms_(v);
    }
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Yr(floor_refs_.size(),
                                                                              k);
    Eigen::VectorXd y0r(static_cast<Eigen::Index>(floor_refs_.size()));
    for (std::size_t u = 0; u < floor_refs_.size(); ++u) {
      Yr.row(static_cast<Eigen::Index>(u)) = ydirs_.row(floor_refs_[u]).head(k);
      y0r(static_cast<Eigen::Index>(u)) = y0_(floor_refs_[u]);
    }
    const Eigen::MatrixXd seeds = (Yr * betas.transpose()).colwise() + y0r;  // refs x N
    for (Eigen::Index b = 0; b < N; ++b) {
      const Eigen::RowVectorXd beta = betas.row(b);
      double best = seeds.col(b).minCoeff();
      for (Eigen::Index c = 0; c < nc && lower(c) <= best; ++c) {
        best = std::min(best, y0c(c) + Yc.row(c).dot(beta));
      }
      floors(b) = best;
    }
  }
  // Landmark points for every body.
  std::vector<Eigen::MatrixXd> pts(points_.size());  // each N x 3
  for (std::size_t i = 0; i < points_.size(); ++i) {
    pts[i] = (betas * points_[i].P.leftCols(k).transpose()).rowwise() + points_[i].p0.transpose();
  }
  measurements.resize(N, static_cast<Eigen::Index>(defs_.size()));
  for (std::size_t d = 0; d < defs_.size(); ++d) {
    const auto col = static_cast<Eigen::Index>(d);
    if (to_[d] < 0) {
      measurements.col(col) = pts[from_[d]].col(1) - floors;
    } else {
      measurements.col(col) = (pts[from_[d]] - pts[to_[d]]).rowwise().norm();
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Training sets

Eigen::VectorXd TrainingSet::column(const std::string& id) const {
  if (id == "weight") return weights;
  if (id == "volume") return volumes;
  if (id == "weight_feature") return volumes.unaryExpr([](double v) { return std::cbrt(v); });
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] == id) return measurements.col(static_cast<Eigen::Index>(i));
  }
  std::string known = "weight, volume, weight_feature";
  for (const auto& s : ids) known += ", " + s;
  throw InvalidInputError("the training set has no column '" + id + "'; it has " + known);
}

TrainingSet make_training_set(const ShapeMeasurer& measurer, const Eigen::MatrixXd& betas,
                              const WeightFormula& formula) {
  TrainingSet t;
  t.betas = betas;
  for (const auto& d : measurer.definitions()) t.ids.push_back(d.id);
  measurer.measure_batch(betas, t.measurements, t.volumes);
  Eigen::MatrixXd mean_measurements;
  Eigen::VectorXd mean_volume;
  measurer.measure_batch(Eigen::MatrixXd::Zero(1, betas.cols()), mean_measurements, mean_volume);
  t.mean_volume = mean_volume[0];
  t.weight_formula = formula;
  t.weights = (formula.coefficient * t.volumes).array() + formula.intercept;
  return t;
}

TrainingSet paper_training_set(const smpl::BodyModel& model) {
  const LandmarkTable landmarks = landmarks_for(model);
  const ShapeMeasurer measurer(model, landmarks, available_measurements(landmarks));
  return make_training_set(measurer, corner_betas(measurer.num_betas(), 2.0),
                           weight_formula_of(model));
}

}  // namespace caliper
