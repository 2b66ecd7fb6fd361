/// \file makehuman_landmarks.hpp
/// The paper's landmarks (and heels, soles) on the MakeHuman skin topology, found once by
/// documented geometric rules on the T-posed template, so that every measurement definition and
/// the VR protocol work on the open model v2 (issue 11). The rules use the template's SMPL
/// joints to know where each limb is; each landmark is one skin vertex, and each right-side
/// landmark is the mirror vertex of its left one (MakeHuman's base mesh is left-right
/// symmetric), so that left and right measurements agree on a symmetric body.
///
/// Frame: metres, +Y up, the body faces +Z, the subject's left is +X, T-pose with palms down
/// (thumbs forward), as template_model() builds it.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "makehuman_rig.hpp"
#include "smpl/body_model.hpp"

namespace modelgen::mh {

/// SMPL joints of a body, 24 x 3, in the frame and units of the vertices they go with.
using Joints24 = Eigen::Matrix<double, 24, 3, Eigen::RowMajor>;

/// Landmarks of the T-posed template of `assets` (`vertices`: V x 3 skin vertices; `joints`:
/// its SMPL joints, same frame; the two marker targets are read from `assets.dir`). Names and rules
/// (left side; right = mirror vertex of the left one):
/// - head_top: highest vertex within 2 mm of the midline (x = mean x of the hips);
/// - left_fingertip: most lateral vertex (tip of the middle finger, the longest in T-pose);
/// - left_wrist: the front (thumb side, +Z) of the skin ring through the wrist joint;
/// - left_elbow: the front (inner elbow, +Z) of the skin ring through the elbow joint;
/// - left_radiale: the top (+Y) of the same ring: the lateral side of the elbow, where the
///   head of the radius is (ANSUR II's radiale; not in caliper::landmark_names(): the generator
///   fits the acromion-radiale length on it, and the model file carries it);
/// - left_shoulder: acromion: the highest vertex of the ring 1.5 cm lateral of the shoulder
///   joint (the top of the humeral head; within 4 cm of the joint front to back);
/// - crotch: the lowest midline vertex below the pelvis joint;
/// - left_hip: the most lateral vertex between the crotch and the pelvis joint (trochanter);
/// - left_nipple: the skin vertex MakeHuman's breast-point target (`breast/breast-point-incr`)
///   moves furthest on the left (the tip of the breast; ties to the most forward one);
/// - navel: of the skin vertices MakeHuman's navel target (`stomach/stomach-navel-in`) moves
///   furthest (the navel), the deepest (least +Z) one on the midline;
/// - left_heel: the rearmost vertex of the foot below the ankle joint;
/// - left_sole: the lowest vertex of the foot in front of the ankle joint.
/// The torso sides and back (waist, chest, torso_back) are not set here: template_model() adds
/// them with the measurement library's rule (caliper::derive_torso_landmarks), as for every
/// model.
/// The right landmarks are the left ones' mirror vertices (SkinMesh::mirror).
/// Throws std::invalid_argument naming the landmark when its rule selects no vertex;
/// AssetError when a marker target is missing.
std::map<std::string, std::vector<int>> template_landmarks(const Assets& assets,
                                                           const smpl::Vertices& vertices,
                                                           const Joints24& joints);

}  // namespace modelgen::mh
