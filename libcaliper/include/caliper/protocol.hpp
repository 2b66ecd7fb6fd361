/// \file protocol.hpp
/// The measuring protocol's arithmetic (Pujades et al., The Virtual Caliper, TVCG 2019,
/// Sec. 3.1): ISAK takes, floor calibration (median of five tip heights plus a plane fit), and
/// the pivot calibration of the controller tip offset.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace caliper {

/// ISAK tolerance: the first two takes agree when their relative difference is below 1.5 %.
constexpr double kIsakTolerance = 0.015;

/// Relative difference of two takes: |a - b| / ((a + b) / 2), i.e. relative to their mean;
/// 0 when both are 0. Throws InvalidInputError for NaN/inf or a negative take.
double isak_relative_difference(double a, double b);

/// True when two takes differ by `tolerance` or more (isak_relative_difference(a, b) >=
/// tolerance), i.e. a third take is needed.
bool isak_needs_third(double a, double b, double tolerance = kIsakTolerance);

/// Result of combining ISAK takes.
struct IsakResult {
  bool complete = false;             ///< false: two takes disagree and no third was given
  double value = 0.0;                ///< mean of two, or median of three (NaN when !complete)
  int takes_used = 0;                ///< 2 or 3 (0 when !complete)
  double relative_difference = 0.0;  ///< of the first two takes
};

/// Combines 2 or 3 takes (in the order taken): if the first two agree (relative difference <
/// tolerance), their mean, ignoring a third; otherwise the median of three, or !complete when
/// only two were given. Throws InvalidInputError for 0, 1 or more than 3 takes, NaN/inf or
/// negative takes.
IsakResult isak_combine(const std::vector<double>& takes, double tolerance = kIsakTolerance);

/// Result of a floor calibration.
struct FloorCalibration {
  double floor_height = 0.0;  ///< median of the samples' y, metres (the floor offset)
  Eigen::Vector3d plane_point = Eigen::Vector3d::Zero();    ///< centroid of the samples
  Eigen::Vector3d plane_normal = Eigen::Vector3d::UnitY();  ///< unit, y component >= 0
  double tilt_degrees = 0.0;                                ///< angle between plane_normal and +Y
  double rms_residual = 0.0;   ///< RMS orthogonal distance of the samples to the plane, m
  double max_residual = 0.0;   ///< largest orthogonal distance, m
  double height_spread = 0.0;  ///< max y - min y of the samples, m
  int num_samples = 0;
};

/// Floor calibration from tip positions on the floor (tracking space, metres; the protocol
/// takes five): the median height, and a total-least-squares plane through the samples
/// (normal = direction of least spread) with its tilt and residuals. Throws CalibrationError
/// for fewer than 3 samples, a NaN/inf sample, or samples that are (nearly) colinear or
/// coincident (RMS spread below 1 cm across their main direction).
FloorCalibration calibrate_floor(const std::vector<Eigen::Vector3d>& tip_positions);

/// A tracked controller pose: grip frame to tracking space, p_world = R * p_grip + position.
struct Pose {
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  ///< normalised on use
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               ///< metres
};

/// Result of a pivot calibration.
struct PivotCalibration {
  Eigen::Vector3d tip_offset = Eigen::Vector3d::Zero();  ///< t, in the grip frame, metres
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();       ///< q, the fixed point, tracking space
  double rms_residual = 0.0;  ///< RMS over samples of |R_i t + p_i - q|, metres
  double max_residual = 0.0;
  double max_rotation_degrees = 0.0;  ///< largest rotation between any sample and the first
  int num_samples = 0;
};

/// Pivot calibration: the tip rests on one fixed point while the controller rotates; solves
/// [R_i  -I] [t; q] = -p_i for all i in least squares (SVD). Throws CalibrationError for fewer
/// than 3 poses, a NaN/inf or zero quaternion or position, or a rank-deficient system (all
/// rotations equal or about a single axis: smallest singular value < 1e-6 of the largest, or
/// no rotation larger than 5 degrees from the first).
PivotCalibration calibrate_pivot(const std::vector<Pose>& poses);

}  // namespace caliper
