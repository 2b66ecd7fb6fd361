/// \file evaluate.hpp
/// The SMPL forward pass (Loper et al. 2015, eqs. 1-4): shape blend shapes, joint regression,
/// pose blend shapes, Rodrigues, kinematic chain and linear blend skinning.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "smpl/body_model.hpp"

namespace smpl {

/// A posed (or rest-pose) body.
struct Body {
  Vertices vertices;  ///< V x 3, metres, posed and translated.
  Joints joints;      ///< K x 3 posed joint positions (translation included), metres.
  /// K world transforms G_j of the joints (rotation and posed joint position), translation
  /// included; the skinning transform of joint j is G_j * translation(-J_rest_j).
  std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> transforms;
};

/// Rest-pose body for `betas`: v_shaped = v_template + shapedirs * betas and J = J_regressor *
/// v_shaped. `betas` may be shorter than model.num_betas() (missing ones are 0); longer throws
/// std::invalid_argument. transforms are pure translations to the joints. Cost: one 3V x |betas|
/// matrix-vector product plus the sparse regression.
Body shape(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas);

/// Same as shape(), writing into `out` (allocation-free once `out` has the model's sizes).
void shape(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas, Body& out);

/// Full forward pass. `pose`: 3K axis-angle values (joint 0 = global orientation) or empty for the
/// rest pose; `translation` is added last. Pose blend shapes are applied when the model has them;
/// the 9 features of a joint whose rotation is exactly the identity are zero and their columns are
/// skipped. Throws std::invalid_argument when betas are longer than the model's or pose is neither
/// empty nor 3K long.
Body evaluate(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
              const Eigen::Ref<const Eigen::VectorXd>& pose,
              const Eigen::Vector3d& translation = Eigen::Vector3d::Zero());

/// Caller-owned scratch memory for allocation-free per-frame evaluation. Reuse one Workspace (and
/// one Body) per thread and per model: the first call sizes every buffer, later calls with the same
/// model allocate nothing.
struct Workspace {
  Vertices v_shaped;             ///< V x 3 shaped (then pose-corrected) rest vertices.
  Eigen::VectorXd pose_feature;  ///< P = 9 (K - 1) pose-blend-shape features.
  std::vector<Eigen::Matrix3d, Eigen::aligned_allocator<Eigen::Matrix3d>> rotations;  ///< K local.
  std::vector<Eigen::Matrix4d, Eigen::aligned_allocator<Eigen::Matrix4d>> skinning;   ///< K A_j.
  Joints rest_joints;                ///< K x 3 joints regressed from v_shaped.
  std::vector<double> skinning_3x4;  ///< K row-major 3 x 4 blocks of the skinning transforms.

  /// Opt-in single-precision pose blend shapes: when true, evaluate() keeps a float copy of
  /// model.posedirs here (17 MB for SMPL) and streams it instead of the double matrix, halving the
  /// memory traffic of the (memory-bound) posed evaluation. Per block of rows the products are
  /// summed in float, then added to the double vertices; the result is within 1e-7 m of the double
  /// path for SMPL-sized correctives (tested against 1e-6 m). The copy is made on the first call
  /// and again whenever posedirs.data() or its size differs from the last call's; since models are
  /// immutable after loading, do not modify a model's posedirs in place while a workspace uses it.
  bool single_precision_pose_blend_shapes = false;
  Eigen::MatrixXf posedirs_f;                 ///< float copy of posedirs (when enabled).
  const double* posedirs_f_source = nullptr;  ///< posedirs.data() the copy was made from.
  Eigen::VectorXf pose_feature_f;             ///< float pose features (when enabled).

  /// Rows of posedirs that are zero in all 9 columns of a joint are skipped for that joint:
  /// correctives that act only near their joint (the open v2 models': each joint's are non-zero
  /// on 10-40 % of the rows) then cost what they touch. A map of the 64-row chunks each joint
  /// touches is made on the first posed call (one pass over posedirs) and again whenever
  /// posedirs.data() or its size differs from the last call's (the same caveat as posedirs_f).
  /// When some joint leaves a chunk untouched, the joints are applied one by one (their 9
  /// columns each) instead of in runs of consecutive rotated joints: the sums are grouped
  /// differently from a workspace without the map (equal to rounding), and evaluate() and
  /// evaluate_batch() still give the same bits as each other. Dense correctives (SMPL's) leave
  /// nothing to skip and are computed exactly as without the map. The evaluate() overload
  /// without a workspace does not make the map (its pass would cost more than one body saves).
  bool skip_zero_pose_rows = true;
  std::vector<std::uint8_t>
      pose_row_chunks;  ///< (K - 1) x chunks: 1 where the joint has a non-zero
  const double* pose_row_chunks_source = nullptr;  ///< posedirs.data() the map was made from.
  Eigen::Index pose_row_chunks_size = 0;           ///< posedirs.size() the map was made from.

  /// Float copies of v_template and shapedirs for shape_batch() into a BodyBatchF (made on its
  /// first call and again whenever shapedirs.data() or a size differs from the last call's; 0.9
  /// MB for SMPL's 10 betas). The same caveat as posedirs_f: do not modify a model in place
  /// while a workspace uses it.
  Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor> v_template_f;
  Eigen::MatrixXf shapedirs_f;                 ///< float copy of shapedirs.
  const double* shapedirs_f_source = nullptr;  ///< shapedirs.data() the copies were made from.
  /// The batch's betas rounded to float (N x B, row-major).
  Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> betas_f;
};

/// Same as evaluate(), writing into `out` and using `ws`; allocates nothing once `out` and `ws`
/// have been used with the same model.
void evaluate(const BodyModel& model, const Eigen::Ref<const Eigen::VectorXd>& betas,
              const Eigen::Ref<const Eigen::VectorXd>& pose, const Eigen::Vector3d& translation,
              Workspace& ws, Body& out);

/// Row-major double matrix: one body (or one body's parameters) per row, as numpy's C order.
using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Row-major float matrix, as RowMatrixXd (numpy's float32 in C order).
using RowMatrixXf = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// N bodies evaluated together (shape_batch, evaluate_batch).
struct BodyBatch {
  /// N x 3V, metres: row n holds body n's vertices x0 y0 z0 x1 y1 z1 ... (numpy shape (N, V, 3)
  /// in C order), posed and translated.
  RowMatrixXd vertices;
  /// N x 3K, metres: row n holds body n's joint positions (translation included), (N, K, 3).
  RowMatrixXd joints;
};

/// shape() for N bodies at once. `betas`: N x B, B <= model.num_betas() (missing betas are 0).
/// Blocked: shapedirs is read once per batch per thread (a block of rows small enough for the L1
/// cache at a time, applied to every body of the thread's share while it is in cache, 4 bodies
/// sharing each loaded vector of it). Every output has the same bits as
/// shape() on that row of `betas` (same operations in the same order) on every SIMD variant.
/// `threads`: worker threads (std::thread; 1 = the calling thread only, 0 = one per core); bodies
/// are shared out among them, results do not depend on the count. `out` is resized to N x 3V and
/// N x 3K (allocation-free when it already has these sizes). Throws std::invalid_argument when B
/// exceeds the model's betas or `threads` is negative.
void shape_batch(const BodyModel& model, const Eigen::Ref<const RowMatrixXd>& betas, BodyBatch& out,
                 int threads = 1);

/// BodyBatch in single precision: N x 3V vertices and N x 3K joints, metres, float.
struct BodyBatchF {
  RowMatrixXf vertices;  ///< as BodyBatch::vertices
  RowMatrixXf joints;    ///< as BodyBatch::joints
};

/// shape_batch() in single precision, for callers that want float vertices (a GPU upload, a
/// float32 pipeline): the products are computed in float on ws's float copies of v_template and
/// shapedirs (see Workspace), each beta rounded to float, so the memory read and written per
/// body is half that of the double batch; the joints are regressed from the float vertices with
/// sums in double. Within 1e-6 m of the double shape_batch for SMPL-sized bodies (tested), and
/// the same bits on every SIMD variant and for every thread count. Same errors as shape_batch.
void shape_batch(const BodyModel& model, const Eigen::Ref<const RowMatrixXd>& betas, Workspace& ws,
                 BodyBatchF& out, int threads = 1);

/// evaluate() for N bodies at once. `betas`: N x B as in shape_batch; `poses`: N x 3K axis-angle
/// values (radians; joint 0 is the global orientation) or 0 columns for the rest pose;
/// `translations`: N x 3 metres or 0 rows (no translation). The pose blend shapes are a blocked
/// matrix product: each block of rows of posedirs (or of ws's float copy when
/// ws.single_precision_pose_blend_shapes is set; see Workspace) is read once per batch and applied
/// to every body while it is in cache, the blocks shared out among `threads` workers; the joint
/// columns skipped are those whose rotation is the identity in every body of the batch. Results
/// are within 1e-12 m of evaluate() on each body (equal bits when the same joint columns are
/// skipped, e.g. every joint rotated) and have the same bits on every SIMD variant and for every
/// thread count. Throws std::invalid_argument when the row counts differ, B exceeds the model's
/// betas, poses are neither 0 nor 3K wide, translations are neither 0 x 3 nor N x 3, or `threads`
/// is negative.
void evaluate_batch(const BodyModel& model, const Eigen::Ref<const RowMatrixXd>& betas,
                    const Eigen::Ref<const RowMatrixXd>& poses,
                    const Eigen::Ref<const RowMatrixXd>& translations, Workspace& ws,
                    BodyBatch& out, int threads = 1);

/// Rotation matrix of an axis-angle vector (angle = norm, radians; right-handed about the axis):
/// R = I + (sin t / t) K + ((1 - cos t) / t^2) K^2 with K = [axis_angle]x. Exact and finite at zero
/// angle: below t = 1e-3 the two coefficients come from their Taylor series (error < 1e-19), and
/// (1 - cos t) is computed as 2 sin^2(t / 2) to avoid cancellation. Any angle is accepted
/// (t and t + 2 pi give the same matrix).
Eigen::Matrix3d rodrigues(const Eigen::Vector3d& axis_angle);

}  // namespace smpl
