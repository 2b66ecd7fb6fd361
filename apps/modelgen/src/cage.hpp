/// \file cage.hpp
/// The parametric control cage of the open body model: a closed quad mesh of about 780 faces
/// whose vertex positions are functions of ANSUR II body dimensions (segment lengths, breadths,
/// depths and girths at named levels). Refined by Catmull-Clark subdivision (subdivision.hpp) it
/// gives the model's smooth surface. The topology is the same for every body, so one cage gives
/// one mesh topology and a linear shape space can be learned over a population.
///
/// Construction: a 16-sided torso tube (crotch to shoulders) closed at the top by a 4 x 4 grid
/// with a neck hole; an 8-sided neck and head closed by a 2 x 2 grid; 10-sided arm tubes leaving
/// 3 x 2 holes in the torso sides, ending in a palm whose distal 1 x 4 grid carries four 4-sided
/// fingers, and a 4-sided thumb extruded from the palm side; 10-sided legs sharing the torso's
/// bottom ring through a crotch vertex, bending forward into a foot closed by a 1 x 4 grid.
/// Frame: metres, +Y up, faces +Z, the subject's left is +X, floor at y = 0 (the generator moves
/// the origin to the pelvis afterwards).
#pragma once

#include <array>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace modelgen {

/// A weighted set of vertex ids (a joint or a landmark as a combination of cage vertices).
using VertexBlend = std::vector<std::pair<int, double>>;

/// Calibration offsets applied on top of the survey dimensions (feedback loop of the generator):
/// additive, metres, indexed by Dim.
struct CageCalibration {
  Eigen::VectorXd offset;  ///< kNumDims additive corrections (0 = none)
};

/// The cage of one body.
struct Cage {
  std::vector<Eigen::Vector3d> positions;  ///< cage vertex positions, metres
  std::vector<std::array<int, 4>> quads;   ///< counter-clockwise seen from outside
  std::vector<int> mirror;                 ///< left/right mirror of each vertex
  std::vector<VertexBlend> skin;           ///< per vertex: (joint, weight), weights sum to 1
  std::vector<VertexBlend> joints;         ///< 24 SMPL joints as blends of cage vertices
  std::map<std::string, std::vector<int>> landmarks;       ///< name -> cage vertex ids
  std::map<std::string, std::vector<int>> face_landmarks;  ///< name -> cage face ids (centres)
};

/// Builds the cage for body dimensions `dims` (kNumDims values, metres and kg, see Dim).
/// `female` adds breasts and a female pelvis shape. `bulk` scales the girths that the survey
/// table does not pin down through a validated measurement (limbs, neck, torso depth between the
/// measured levels); the generator calibrates it so that the weight from volume matches. The
/// topology (quads, mirror, skin, joints,
/// landmarks) does not depend on `dims`.
Cage build_cage(const Eigen::VectorXd& dims, bool female, double bulk = 1.0);

}  // namespace modelgen
