/// \file simulator.hpp
/// A session simulator: writes the pose log of a virtual person of known body shape doing the
/// measuring protocol (floor calibration, then every step), so that tests know the true answer.
/// The controller tips go to the person's landmarks (with Gaussian tracking noise if asked),
/// the trigger is held for the protocol's hold time, and scripted incidents happen on request: a
/// tracking dropout during a hold (then a retake), an early trigger release (then a retake), an
/// ISAK disagreement that needs a third take, operator commands (start, typed weight and sex,
/// redo). Deterministic for a given seed (std::mt19937_64 with our own Box-Muller normals).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "caliper/pose_log.hpp"
#include "caliper/protocol_file.hpp"
#include "caliper/session.hpp"
#include "smpl/body_model.hpp"

namespace caliper {

/// The simulated person: landmark points of the standing body (rest pose, floor at y = 0,
/// facing +Z, centred at the origin in x and z), metres; plus the typed values.
struct SimulatedPerson {
  std::map<std::string, Eigen::Vector3d> landmarks;
  /// Rest joints in the same frame (SMPL's 24 for SMPL-structured models; used by the
  /// embodiment motions), empty when the model has another skeleton.
  std::vector<Eigen::Vector3d> joints;
  double weight = 70.0;        ///< kg
  std::string sex = "female";  ///< typed choice
  /// Where the left wrist hangs at rest (m from the midline; the right one mirrored): far enough
  /// out that every vertex of the hanging hand (fingers down, palm in) clears the side of the
  /// trunk and thigh at its height by 2 cm; 0 when unknown (then 6 cm outside the shoulder).
  double hang_wrist_x = 0.0;
};

/// The person of `model` with `betas` (rest pose, v_template + shapedirs * betas): the landmark
/// points of landmarks_for(model), shifted so that the lowest vertex is at y = 0 and the body is
/// centred in x and z. Throws LandmarkError when a landmark of the shared vocabulary is missing.
SimulatedPerson person_from_model(const smpl::BodyModel& model, const Eigen::VectorXd& betas,
                                  double weight, const std::string& sex);

/// The values a perfect measurer gets for every measured step of `protocol` (height of the
/// landmark above the floor, or the distance between the two landmarks), plus "weight".
std::map<std::string, double> true_measurements(const SimulatedPerson& person,
                                                const Protocol& protocol);

/// What happens during the simulated session.
struct SimulatorOptions {
  std::uint64_t seed = 1;
  std::string role = "self";  ///< "operator" adds a start command and types weight and sex
  double frame_rate = 90.0;   ///< frames per second of the log
  double tip_noise = 0.0;     ///< per-frame Gaussian tip noise, standard deviation per axis, m
  /// The runtime's floor error: every tracked y is this much higher than the true height (the
  /// floor calibration must remove it).
  double runtime_floor_offset = 0.02;
  TipOffsets tip_offsets;  ///< the controllers' tip offsets (as configured in the app)
  std::string interaction_profile = "/interaction_profiles/htc/vive_controller";
  /// Step id whose first hold loses tracking of one controller for 0.15 s mid-hold ("" = none).
  std::string dropout_step;
  /// Step id whose second take is 3 % too long, so ISAK asks for a third ("" = none).
  std::string third_take_step;
  /// Step id whose first hold is released after 0.4 s ("" = none).
  std::string early_release_step;
  /// Operator role: step id after whose first take the operator presses redo ("" = none).
  std::string redo_step;
  /// Put typed values (weight, sex) into the log as commands (else the app takes --weight/--sex).
  bool typed_in_log = true;
  /// After the measurements: wave (right hand), reach up, cross arms, squat and a 90 degree
  /// turn, moving the headset and the controllers as the person's body would (for the
  /// embodiment; needs SimulatedPerson::joints).
  bool motions = false;
  /// At the end the person presses the right controller's menu button (ends the session).
  bool end_button = true;
};

/// The simulated session.
struct SimulatedSession {
  PoseLog log;
  std::map<std::string, double> truth;  ///< true_measurements()
  int accepted_samples = 0;  ///< samples the session must accept (floor + takes), = tones
  int rejected_samples = 0;  ///< holds the session must reject
  /// Frame indices where no trigger is held and no hold is pending: places where cutting the log
  /// (a simulated crash) loses no sample.
  std::vector<size_t> quiet_frames;
  /// First and one-past-last frame of the embodiment motions (both 0 without them); the first is
  /// where the first posture is reached, after the hands have left the last measuring posture.
  size_t motion_begin = 0, motion_end = 0;
};

/// Simulates the whole protocol. Throws InvalidInputError when a landmark the protocol needs is
/// not in `person`, or a scripted step id is not in the protocol.
SimulatedSession simulate_session(const Protocol& protocol, const SimulatedPerson& person,
                                  const SimulatorOptions& options = {});

}  // namespace caliper
