/// \file makehuman_rig.hpp
/// From MakeHuman's A-pose rig to SMPL's structure: the 24 SMPL joints as heads of MakeHuman
/// bones, MakeHuman's 139 weighted bones merged into those 24 (at most 4 per vertex, summing to
/// 1), the T-pose baked by linear blend skinning with MakeHuman's own weights, and a sparse joint
/// regressor over the skin vertices fitted to the joint-cube centroids of a set of bodies.
/// Plain arithmetic and square roots only (no libm transcendental functions), fixed loop orders:
/// the results are the same bytes on every x86-64 CPU.
#pragma once

#include <string>
#include <vector>

#include "makehuman.hpp"
#include "smpl/body_model.hpp"

namespace modelgen::mh {

/// Everything read from a MakeHuman asset folder (../shared/data/makehuman layout).
struct Assets {
  BaseMesh base;
  SkinMesh skin;
  Skeleton skeleton;
  BoneWeights weights;
  std::string dir;  ///< the folder the assets came from
};

/// Reads 3dobjs/base.obj, rigs/default.mhskel and rigs/default_weights.mhw under `dir`, and
/// selects the skin. Throws AssetError naming the missing or malformed file.
Assets read_assets(const std::string& dir);

/// Reads `dir`/targets/`relative` (e.g. "measure/measure-waist-circ-incr.target").
Target read_asset_target(const Assets& assets, const std::string& relative);

/// The MakeHuman bone whose head joint is SMPL joint k (k in [0, 24), smpl_joint_names() order).
const std::vector<std::string>& smpl_joint_bones();

/// SMPL joint (0..23) whose segment MakeHuman bone `bone` belongs to: the bone itself if it is
/// in smpl_joint_bones(), else the segment of its nearest listed ancestor (the root and the
/// pelvis bones are the pelvis). Throws AssetError for a bone not in the skeleton.
int smpl_segment(const Skeleton& skeleton, const std::string& bone);

/// The 1-ring of every vertex of `faces` (n vertices), each list sorted increasing (the weight
/// diffusion's and the contact step's neighbourhoods).
std::vector<std::vector<int>> vertex_neighbours(Eigen::Index n, const smpl::Faces& faces);

/// Marks the 1-rings of the marked vertices (`ring` from vertex_neighbours()), `rings` times.
void grow_marks(std::vector<char>& mark, const std::vector<std::vector<int>>& ring, int rings);

/// `passes` passes of v' = (v + mean of v over the 1-ring) / 2 over the marked rows of `v`
/// (V x 3), each pass reading the previous one's values (so the order of the rows does not
/// matter); a vertex with no neighbour stays.
void smooth_marked(Eigen::Ref<smpl::Vertices> v, const std::vector<std::vector<int>>& ring,
                   const std::vector<char>& mark, int passes);

/// V x 24 skinning weights of the skin mesh: MakeHuman's bone weights summed per SMPL segment,
/// the 4 largest kept per vertex (ties to the lower joint index), renormalised to sum 1.
/// A weight on a limb segment of the other side of the body (a left joint for a vertex more than
/// kMidlineBand to the right of the midline, or the reverse) is dropped first: hm08's weights
/// carry a few such strays (0.2 % of toe2-3.R on a left toe vertex, 0.5 % of the other knee on a
/// knee vertex), which pull the skin across the body when the other limb moves and fold it.
/// Then the weights are smoothed: `smoothing_passes` passes of uniform (umbrella) Laplacian
/// diffusion over the skin mesh's 1-ring, w'(i) = (w(i) + mean of w over the neighbours of i) / 2,
/// each vertex restricted to the joints that already influence it or a 1-ring neighbour (so no
/// vertex takes a joint far from it in SMPL's hierarchy) and never to a limb of the other side,
/// renormalised to sum 1 after each pass. MakeHuman's weights change sharply across 90-degree
/// bends (inner elbow, back of the knee, groin, armpit), where linear blend skinning folds the
/// skin (flipped triangles); the diffusion spreads the change over a few rings. Deterministic:
/// plain loops in a fixed order, the same bytes on every CPU. The 4 largest are kept afterwards.
/// Throws AssetError if a skin vertex has no weight at all; std::invalid_argument if
/// smoothing_passes < 0.
smpl::SparseMatrix merged_weights(const Assets& assets, int smoothing_passes);

/// Diffusion passes merged_weights(assets) applies, chosen by measuring the template's flipped
/// triangles in the 10 test poses against its side effects (docs/models.md, "Geometry checks").
constexpr int kWeightSmoothingPasses = 50;  // flipped triangles 168 -> 10 (docs/models.md)

/// merged_weights(assets, kWeightSmoothingPasses): the weights of the MakeHuman models.
smpl::SparseMatrix merged_weights(const Assets& assets);

/// Half-width (decimetres, base-mesh units) of the band about x = 0 where a vertex may carry
/// weights of both sides' limb segments (the crotch, the spine): 1 cm.
constexpr double kMidlineBand = 0.1;

/// A body posed from MakeHuman's A-pose to SMPL's T-pose.
struct TPoseBody {
  Positions positions;  ///< N x 3 base-mesh vertices (decimetres): every vertex with a bone
                        ///< weight posed, the others (joint cubes) left where they were
  Eigen::Matrix<double, 24, 3, Eigen::RowMajor> joints;  ///< SMPL joints, posed, decimetres
};

/// Poses `a_pose` (N x 3 base-mesh positions, decimetres, e.g. the base plus targets) into the
/// T-pose: per arm, the upper arm is turned about the shoulder joint onto the horizontal
/// (+X left, -X right), the forearm about the elbow onto the same line, the hand about the wrist
/// onto it, and the hand twisted about that line so that the palm faces down (index knuckle in
/// front of the little-finger knuckle); the twist is shared half by the distal forearm bone. The
/// shoulder bone (deltoid) takes half the upper-arm rotation. Vertices move by linear blend
/// skinning with MakeHuman's weights (normalised per vertex); legs, trunk and head stay.
TPoseBody t_pose(const Assets& assets, const Positions& a_pose);

/// SMPL joint positions (24 x 3, decimetres) of a body in MakeHuman's rest (A-)pose: centroids
/// of the joint vertex groups of smpl_joint_bones()' heads.
Eigen::Matrix<double, 24, 3, Eigen::RowMajor> smpl_joints(const Assets& assets,
                                                          const Positions& positions);

/// A 24 x V joint regressor over the skin vertices. For each joint, the skin vertices where 36
/// rays from the joint first meet the skin on bodies.front() are chosen (rings across the limb),
/// and their weights solved (rows sum to 1) so that they reproduce the joint over all `bodies`
/// (T-posed, with their joints) in the least-squares sense, with a small ridge towards equal
/// weights that keeps the row well-posed. The regressor is then made left/right symmetric: each
/// row is the mean of its own weights and its mirror joint's weights on the mirror vertices
/// (SkinMesh::mirror), so that a symmetric body has mirror-image joints and its pelvis on the
/// midline. Throws std::invalid_argument for no bodies, AssetError if fewer than 3 vertices
/// surround a joint.
smpl::SparseMatrix fit_joint_regressor(const Assets& assets, const std::vector<TPoseBody>& bodies);

/// The T-posed template model of the base mesh (no shape space: 0 betas): skin vertices in
/// metres, triangles, merged weights, the regressor fitted on the base mesh and `training`
/// target files (paths relative to targets/, each applied at weight 1), SMPL joint names and
/// parents. Metadata names the source folder and the CC0 licence.
smpl::BodyModel template_model(const Assets& assets, const std::vector<std::string>& training);

/// The default regressor training targets: the young macro corners of both sexes, the young
/// height extremes and every measure target (paths relative to targets/).
std::vector<std::string> default_regressor_targets();

/// Every single-measurement target (`measure/measure-*-{decr,incr}.target`: girths, lengths
/// and distances), paths relative to targets/.
std::vector<std::string> measure_targets();

}  // namespace modelgen::mh
