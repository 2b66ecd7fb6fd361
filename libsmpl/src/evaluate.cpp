// The SMPL forward pass: Loper, Mahmood, Romero, Pons-Moll, Black, "SMPL: A Skinned Multi-Person
// Linear Model", SIGGRAPH Asia 2015, eqs. (1)-(4) and section 3: shape blend shapes, joint
// regression, pose blend shapes, Rodrigues, kinematic chain, linear blend skinning.
#include "smpl/evaluate.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "smpl/simd.hpp"

namespace smpl {
namespace {

// Below this angle (radians) Rodrigues' coefficients come from their Taylor series. At 1e-3 the
// first omitted terms (t^6/5040, t^6/40320) are below 1e-21, far under double rounding.
constexpr double kSmallAngle = 1e-3;

// Kernel variants (simd.hpp): each hot loop below is written once as an always-inline body and
// compiled into one function per x86-64 level (baseline SSE2, AVX2, AVX-512F); a dispatcher picks
// the variant of smpl::simd_level() at each call. Explicit variants instead of GCC's target_clones
// so that tests and benchmarks can run each one and CALIPER_SIMD can pin one. The bodies vectorise
// across independent outputs only and the project builds with -ffp-contract=off, so every variant
// computes bit-identical results (tests/smpl/test_simd.cpp).
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define SMPL_KERNEL_BODY inline __attribute__((always_inline))
#define SMPL_KERNEL_VARIANTS(name, params, args)                 \
  void name##_baseline params {                                  \
    name##_body args;                                            \
  }                                                              \
  __attribute__((target("avx2"))) void name##_avx2 params {      \
    name##_body args;                                            \
  }                                                              \
  __attribute__((target("avx512f"))) void name##_avx512 params { \
    name##_body args;                                            \
  }                                                              \
  void name params {                                             \
    switch (simd_level()) {                                      \
      case SimdLevel::kAvx512:                                   \
        name##_avx512 args;                                      \
        return;                                                  \
      case SimdLevel::kAvx2:                                     \
        name##_avx2 args;                                        \
        return;                                                  \
      case SimdLevel::kBaseline:                                 \
        break;                                                   \
    }                                                            \
    name##_baseline args;                                        \
  }
#else
#define SMPL_KERNEL_BODY inline
#define SMPL_KERNEL_VARIANTS(name, params, args) \
  void name params {                             \
    name##_body args;                            \
  }
#endif

// out = t + S[:, :nb] * beta with S column-major (leading dimension ld): the shape blend shapes.
// 32 rows at a time are accumulated in 4 vectors of 8 doubles that stay in registers while every
// column's 32-row segment streams past: shapedirs is read exactly once, at the cache bandwidth.
SMPL_KERNEL_BODY
void blend_body(const double* t, const double* S, Eigen::Index ld, Eigen::Index rows,
                const double* beta, Eigen::Index nb, double* out) {
  typedef double V8 __attribute__((vector_size(64)));  // GCC/Clang vector extension
  constexpr Eigen::Index kRows = 32;
  Eigen::Index r0 = 0;
  for (; r0 + kRows <= rows; r0 += kRows) {
    V8 a0, a1, a2, a3;
    std::memcpy(&a0, t + r0, sizeof a0);
    std::memcpy(&a1, t + r0 + 8, sizeof a1);
    std::memcpy(&a2, t + r0 + 16, sizeof a2);
    std::memcpy(&a3, t + r0 + 24, sizeof a3);
    for (Eigen::Index b = 0; b < nb; ++b) {
      const double c = beta[b];
      const double* col = S + b * ld + r0;
      V8 x0, x1, x2, x3;
      std::memcpy(&x0, col, sizeof x0);
      std::memcpy(&x1, col + 8, sizeof x1);
      std::memcpy(&x2, col + 16, sizeof x2);
      std::memcpy(&x3, col + 24, sizeof x3);
      a0 += c * x0;
      a1 += c * x1;
      a2 += c * x2;
      a3 += c * x3;
    }
    std::memcpy(out + r0, &a0, sizeof a0);
    std::memcpy(out + r0 + 8, &a1, sizeof a1);
    std::memcpy(out + r0 + 16, &a2, sizeof a2);
    std::memcpy(out + r0 + 24, &a3, sizeof a3);
  }
  for (; r0 < rows; ++r0) {
    double a = t[r0];
    for (Eigen::Index b = 0; b < nb; ++b) a += beta[b] * S[b * ld + r0];
    out[r0] = a;
  }
}
SMPL_KERNEL_VARIANTS(blend,
                     (const double* t, const double* S, Eigen::Index ld, Eigen::Index rows,
                      const double* beta, Eigen::Index nb, double* out),
                     (t, S, ld, rows, beta, nb, out))

// v += P[:, c0:c0+nc] * f[c0:c0+nc] for the double pose blend shapes (P column-major, leading
// dimension ld). Blocks of 512 rows (4 KB per column segment: long sequential runs that the
// hardware prefetchers follow), 4 columns per pass over the L1-resident block of v.
SMPL_KERNEL_BODY
void pose_blend_f64_body(const double* P, Eigen::Index ld, Eigen::Index rows, const double* f,
                         Eigen::Index c0, Eigen::Index nc, double* v) {
  constexpr Eigen::Index kBlock = 512;
  for (Eigen::Index r0 = 0; r0 < rows; r0 += kBlock) {
    const Eigen::Index n = std::min(kBlock, rows - r0);
    double* o = v + r0;
    Eigen::Index c = c0;
    for (; c + 4 <= c0 + nc; c += 4) {
      const double* p0 = P + c * ld + r0;
      const double* p1 = p0 + ld;
      const double* p2 = p1 + ld;
      const double* p3 = p2 + ld;
      const double f0 = f[c], f1 = f[c + 1], f2 = f[c + 2], f3 = f[c + 3];
      for (Eigen::Index i = 0; i < n; ++i) {
        o[i] += (f0 * p0[i] + f1 * p1[i]) + (f2 * p2[i] + f3 * p3[i]);
      }
    }
    for (; c < c0 + nc; ++c) {
      const double* p0 = P + c * ld + r0;
      const double f0 = f[c];
      for (Eigen::Index i = 0; i < n; ++i) o[i] += f0 * p0[i];
    }
  }
}
SMPL_KERNEL_VARIANTS(pose_blend_f64,
                     (const double* P, Eigen::Index ld, Eigen::Index rows, const double* f,
                      Eigen::Index c0, Eigen::Index nc, double* v),
                     (P, ld, rows, f, c0, nc, v))

// Linear blend skinning of every vertex: out_v = sum_e w_e A_{j_e} [x_v; 1] + translation, with
// the weights as compressed sparse rows (outer, inner, values; nnz per row may be given for
// uncompressed matrices) and A as K row-major 3 x 4 blocks of 12 contiguous doubles.
SMPL_KERNEL_BODY
void skin_body(const double* A, const int* outer, const int* nnz, const int* inner,
               const double* values, Eigen::Index V, const double* x, const double* translation,
               double* out) {
  // Each 3 x 4 row is one vector of 4 doubles (GCC/Clang vector extension: one AVX2 register,
  // two SSE2 registers in the baseline build), so an influence costs 3 vector multiply-adds.
  typedef double Row4 __attribute__((vector_size(32)));
  for (Eigen::Index v = 0; v < V; ++v) {
    Row4 t0 = {0, 0, 0, 0}, t1 = t0, t2 = t0;
    const int begin = outer[v];
    const int end = nnz ? begin + nnz[v] : outer[v + 1];
    for (int e = begin; e < end; ++e) {
      const double w = values[e];
      Row4 a0, a1, a2;
      const double* a = A + 12 * inner[e];
      std::memcpy(&a0, a, sizeof a0);
      std::memcpy(&a1, a + 4, sizeof a1);
      std::memcpy(&a2, a + 8, sizeof a2);
      t0 += w * a0;
      t1 += w * a1;
      t2 += w * a2;
    }
    const double* p = x + 3 * v;
    double* o = out + 3 * v;
    o[0] = t0[0] * p[0] + t0[1] * p[1] + t0[2] * p[2] + t0[3] + translation[0];
    o[1] = t1[0] * p[0] + t1[1] * p[1] + t1[2] * p[2] + t1[3] + translation[1];
    o[2] = t2[0] * p[0] + t2[1] * p[1] + t2[2] * p[2] + t2[3] + translation[2];
  }
}
SMPL_KERNEL_VARIANTS(skin,
                     (const double* A, const int* outer, const int* nnz, const int* inner,
                      const double* values, Eigen::Index V, const double* x,
                      const double* translation, double* out),
                     (A, outer, nnz, inner, values, V, x, translation, out))

// Single-precision pose blend shapes over one run of columns [c0, c0 + nc): float columns are
// summed per block of rows in float, then added to the double vertices.
SMPL_KERNEL_BODY
void pose_blend_f32_body(const float* P, Eigen::Index ld, Eigen::Index rows, const float* feature,
                         Eigen::Index c0, Eigen::Index nc, double* v) {
  constexpr Eigen::Index kBlock = 512;
  float acc[kBlock];
  for (Eigen::Index r0 = 0; r0 < rows; r0 += kBlock) {
    const Eigen::Index n = std::min(kBlock, rows - r0);
    for (Eigen::Index i = 0; i < n; ++i) acc[i] = 0.0f;
    for (Eigen::Index c = c0; c < c0 + nc; ++c) {
      const float f = feature[c];
      const float* col = P + c * ld + r0;
      for (Eigen::Index i = 0; i < n; ++i) acc[i] += f * col[i];
    }
    for (Eigen::Index i = 0; i < n; ++i) v[r0 + i] += static_cast<double>(acc[i]);
  }
}
SMPL_KERNEL_VARIANTS(pose_blend_f32,
                     (const float* P, Eigen::Index ld, Eigen::Index rows, const float* feature,
                      Eigen::Index c0, Eigen::Index nc, double* v),
                     (P, ld, rows, feature, c0, nc, v))

void check_betas(const BodyModel& model, Eigen::Index n) {
  if (n > model.num_betas()) {
    throw std::invalid_argument("smpl::evaluate: " + std::to_string(n) +
                                " betas given but the model has only " +
                                std::to_string(model.num_betas()) +
                                " shape components; load it with more betas or pass fewer");
  }
}

// v_shaped = v_template + shapedirs[:, :n] * betas (missing betas are zero), then the joints.
void shaped_rest(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
                 Vertices& v_shaped, Joints& joints) {
  check_betas(model, betas.size());
  const Eigen::Index V = model.v_template.rows();
  v_shaped.resize(V, 3);
  blend(model.v_template.data(), model.shapedirs.data(), model.shapedirs.rows(), 3 * V,
        betas.data(), betas.size(), v_shaped.data());
  // J = J_regressor * v_shaped, row by row over the sparse regressor (no temporaries).
  const Eigen::Index K = model.j_regressor.rows();
  joints.resize(K, 3);
  for (Eigen::Index k = 0; k < K; ++k) {
    Eigen::RowVector3d j = Eigen::RowVector3d::Zero();
    for (SparseMatrix::InnerIterator it(model.j_regressor, k); it; ++it) {
      j += it.value() * v_shaped.row(it.col());
    }
    joints.row(k) = j;
  }
}

// v += posedirs[:, cols] * feature[cols] for each run of consecutive joints that are rotated.
template <typename Matrix, typename Vector>
void add_pose_blend_shapes(
    const Matrix& posedirs, const Vector& feature,
    const std::vector<Eigen::Matrix3d, Eigen::aligned_allocator<Eigen::Matrix3d>>& rot,
    Eigen::Map<Eigen::VectorXd>& v) {
  using Scalar = typename Matrix::Scalar;
  const int K = static_cast<int>(rot.size());
  int k = 1;
  while (k < K) {
    if (rot[static_cast<size_t>(k)].isIdentity(0.0)) {
      ++k;
      continue;
    }
    int end = k + 1;
    while (end < K && !rot[static_cast<size_t>(end)].isIdentity(0.0)) ++end;
    const Eigen::Index c0 = 9 * (k - 1), nc = 9 * (end - k);
    if constexpr (std::is_same_v<Scalar, double>) {
      pose_blend_f64(posedirs.data(), posedirs.rows(), posedirs.rows(), feature.data(), c0, nc,
                     v.data());
    } else {
      pose_blend_f32(posedirs.data(), posedirs.rows(), posedirs.rows(), feature.data(), c0, nc,
                     v.data());
    }
    k = end;
  }
}

}  // namespace

Eigen::Matrix3d rodrigues(const Eigen::Vector3d& r) {
  const double t2 = r.squaredNorm();
  const double t = std::sqrt(t2);
  double a, b;  // R = I + a K + b K^2, a = sin t / t, b = (1 - cos t) / t^2
  if (t < kSmallAngle) {
    a = 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0);
    b = 0.5 * (1.0 - t2 / 12.0 * (1.0 - t2 / 30.0));
  } else {
    const double s = std::sin(0.5 * t);
    a = std::sin(t) / t;
    b = 2.0 * s * s / t2;
  }
  Eigen::Matrix3d K;
  K << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity() + a * K + b * (K * K);
  return R;
}

void shape(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas, Body& out) {
  shaped_rest(model, betas, out.vertices, out.joints);
  const auto K = static_cast<size_t>(model.num_joints());
  out.transforms.resize(K);
  for (size_t k = 0; k < K; ++k) {
    out.transforms[k].setIdentity();
    out.transforms[k].topRightCorner<3, 1>() =
        out.joints.row(static_cast<Eigen::Index>(k)).transpose();
  }
}

Body shape(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas) {
  Body body;
  shape(model, betas, body);
  return body;
}

void evaluate(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
              const Eigen::Ref<const Eigen::VectorXd>& pose, const Eigen::Vector3d& translation,
              Workspace& ws, Body& out) {
  const int K = model.num_joints();
  if (pose.size() != 0 && pose.size() != 3 * K) {
    throw std::invalid_argument("smpl::evaluate: pose has " + std::to_string(pose.size()) +
                                " values, expected 0 (rest pose) or 3 x " + std::to_string(K) +
                                " = " + std::to_string(3 * K) + " axis-angle values");
  }
  // 1-2. Shape blend shapes and joint regression.
  shaped_rest(model, betas, ws.v_shaped, ws.rest_joints);
  const Eigen::Index V = ws.v_shaped.rows();

  // 3. Local rotations.
  const auto Ks = static_cast<size_t>(K);
  ws.rotations.resize(Ks);
  for (size_t k = 0; k < Ks; ++k) {
    ws.rotations[k] = pose.size() == 0
                          ? Eigen::Matrix3d::Identity()
                          : rodrigues(pose.segment<3>(3 * static_cast<Eigen::Index>(k)));
  }

  // 4-5. Pose blend shapes: feature 9 (k - 1) + 3 row + col = (R_k - I)(row, col).
  if (model.has_pose_blend_shapes()) {
    const Eigen::Index P = model.num_pose_features();
    ws.pose_feature.resize(P);
    for (int k = 1; k < K; ++k) {
      const Eigen::Matrix3d d = ws.rotations[static_cast<size_t>(k)] - Eigen::Matrix3d::Identity();
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) ws.pose_feature[9 * (k - 1) + 3 * i + j] = d(i, j);
      }
    }
    Eigen::Map<Eigen::VectorXd> flat(ws.v_shaped.data(), 3 * V);
    if (ws.single_precision_pose_blend_shapes) {
      if (ws.posedirs_f_source != model.posedirs.data() ||
          ws.posedirs_f.rows() != model.posedirs.rows() ||
          ws.posedirs_f.cols() != model.posedirs.cols()) {
        ws.posedirs_f = model.posedirs.cast<float>();
        ws.posedirs_f_source = model.posedirs.data();
      }
      ws.pose_feature_f.resize(P);
      ws.pose_feature_f = ws.pose_feature.cast<float>();
      add_pose_blend_shapes(ws.posedirs_f, ws.pose_feature_f, ws.rotations, flat);
    } else {
      add_pose_blend_shapes(model.posedirs, ws.pose_feature, ws.rotations, flat);
    }
  }

  // 6. Kinematic chain: G_0 = [R_0 | J_0], G_k = G_parent [R_k | J_k - J_parent].
  out.transforms.resize(Ks);
  ws.skinning.resize(Ks);
  for (int k = 0; k < K; ++k) {
    const auto ks = static_cast<size_t>(k);
    Eigen::Matrix4d local = Eigen::Matrix4d::Identity();
    local.topLeftCorner<3, 3>() = ws.rotations[ks];
    const int p = model.parents[ks];
    const Eigen::Vector3d jk = ws.rest_joints.row(k).transpose();
    if (p < 0) {
      local.topRightCorner<3, 1>() = jk;
      out.transforms[ks] = local;
    } else {
      local.topRightCorner<3, 1>() = jk - ws.rest_joints.row(p).transpose();
      out.transforms[ks] = out.transforms[static_cast<size_t>(p)] * local;
    }
    // 7. Remove the rest pose: A_k = G_k * translation(-J_k).
    ws.skinning[ks] = out.transforms[ks];
    ws.skinning[ks].topRightCorner<3, 1>() -= out.transforms[ks].topLeftCorner<3, 3>() * jk;
  }

  // 8. Linear blend skinning, then the global translation.
  ws.skinning_3x4.resize(12 * Ks);
  for (size_t k = 0; k < Ks; ++k) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c)
        ws.skinning_3x4[12 * k + 4 * static_cast<size_t>(r) + static_cast<size_t>(c)] =
            ws.skinning[k](r, c);
    }
  }
  out.vertices.resize(V, 3);
  const SparseMatrix& W = model.weights;
  skin(ws.skinning_3x4.data(), W.outerIndexPtr(), W.innerNonZeroPtr(), W.innerIndexPtr(),
       W.valuePtr(), V, ws.v_shaped.data(), translation.data(), out.vertices.data());
  out.joints.resize(K, 3);
  for (int k = 0; k < K; ++k) {
    auto& G = out.transforms[static_cast<size_t>(k)];
    G.topRightCorner<3, 1>() += translation;
    out.joints.row(k) = G.topRightCorner<3, 1>().transpose();
  }
}

Body evaluate(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
              const Eigen::Ref<const Eigen::VectorXd>& pose, const Eigen::Vector3d& translation) {
  Workspace ws;
  Body body;
  evaluate(model, betas, pose, translation, ws, body);
  return body;
}

}  // namespace smpl
