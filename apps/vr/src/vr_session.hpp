/// \file vr_session.hpp
/// The VR measuring session without any platform: it takes one PoseFrame per displayed frame
/// (from OpenXR or a pose log), runs the measuring protocol (caliper::MeasuringSession), writes
/// the journal, makes the avatar at the end and drives it with the embodiment IK. What the
/// platform has to do in answer is returned as data: the session's events, the feedback to give
/// (tones, haptic pulses), what the instruction panel says and which instruction video the
/// current step shows. No OpenAL, FFmpeg, GL or OpenXR here: the app layer (vr_app.hpp) plays
/// the tones, decodes the videos and uploads what the scene builder (scene_builder.hpp) says to
/// draw; the tests drive this class headless.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "caliper/avatar.hpp"
#include "caliper/body_ik.hpp"
#include "caliper/journal.hpp"
#include "caliper/json.hpp"
#include "caliper/pose_log.hpp"
#include "caliper/session.hpp"
#include "panel_content.hpp"
#include "smpl/body_model.hpp"
#include "smpl/evaluate.hpp"

namespace caliper::vr {

/// How to end the session once it is complete: on the panel and the terminal (the menu action
/// is bound to the menu button, and to B on the Valve Index controller).
inline const char* kEndHint = "To finish, press the menu button of a controller (Valve Index: B).";

/// The virtual mirror: a vertical plane through `centre` with unit horizontal `normal` (the app
/// puts it 1 m in front of the user when the avatar is made). What the user sees in it is the
/// reflection of the driven body, as in a real mirror: the user's left hand is the reflection's
/// right and appears on the user's left.
struct MirrorPlane {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  /// The point's mirror image: p - 2 ((p - centre) . normal) normal.
  Eigen::Vector3d reflect(const Eigen::Vector3d& p) const {
    return p - 2.0 * (p - centre).dot(normal) * normal;
  }
  /// Every vertex reflected, as floats (x, y, z per vertex) for the renderer.
  std::vector<float> reflect(const smpl::Vertices& v) const;
  /// The triangles of the reflected mesh: a reflection reverses orientation, so each triangle's
  /// order is turned round (0, 2, 1) to keep the outside facing out.
  static std::vector<std::uint32_t> reflected_triangles(const smpl::Faces& faces);
};

/// How the avatar is made at the end.
struct AvatarSettings {
  std::string model_path;        ///< explicit model; "" = models_dir/caliper-<sex>.npz
  std::string models_dir;        ///< folder of the open default models
  std::string regressor = "R5";  ///< R2, R4, R5 or R6 (the paper's best is R5)
  std::string regressors_path;   ///< fitted set (caliper train); "" = fit on the model at the end
  std::string mapping_path;  ///< learned real->virtual mapping (hip-width correction); "" = none
};

struct VrSessionOptions {
  Protocol protocol;
  std::string protocol_dir;  ///< folder of the protocol file (video paths are relative to it)
  SessionOptions session;
  TipOffsets tips;
  std::string journal_path;               ///< "" = no journal
  std::optional<JournalContents> resume;  ///< records to restore first (--resume)
  AvatarSettings avatar;
  std::string output_dir;  ///< avatar.glb and session.json at the end ("" = none)
};

/// How well the avatar followed the user since it was made (docs/vr.md, "Embodiment"); the
/// replay prints it and `--embodiment-report FILE` writes it.
struct EmbodimentStats {
  long frames = 0;               ///< frames the avatar was driven
  long reachable_wrists = 0;     ///< wrist targets within the arm's reach (counted per hand)
  double max_wrist_error = 0.0;  ///< m, avatar wrist to controller-derived wrist, when reachable
  long hands_in_torso = 0;       ///< frames with a hand or wrist joint inside the torso capsule
  long limit_violations = 0;     ///< joint-limit violations (check_limits) summed over frames
  double max_joint_step = 0.0;   ///< m, largest move of any joint between consecutive frames
  double max_step_dt = 0.0;      ///< s, the frame interval where that happened
  double ik_cpu_seconds = 0.0;   ///< thread CPU time spent in BodyIk::solve, total
  /// Per frame, for metrics over a part of the session (e.g. the scripted motions).
  struct Frame {
    double time = 0.0;
    double wrist_error = -1.0;  ///< m, larger of the reachable wrists' errors; -1 = none
    bool hand_in_torso = false;
    double joint_step = 0.0;  ///< m, largest joint move since the previous frame
    int limit_violations = 0;
  };
  std::vector<Frame> per_frame;
};

/// Radius of the torso capsule (pelvis to neck joint) the hands must stay out of: a little
/// less than the half depth of a slim adult torso (about 0.1 m).
constexpr double kTorsoRadius = 0.09;

/// The avatar made at the end.
struct AvatarOutcome {
  std::shared_ptr<const smpl::BodyModel> model;
  std::string model_path;
  std::string regressor;
  std::string mapping_path;
  Avatar avatar;
  double eye_height = 0.0;  ///< y of the avatar's eyes above its soles, m
  /// The model without pose correctives, for the per-frame posed mesh (the correctives are a
  /// 3V x 207 product per frame and barely visible at mirror distance).
  std::shared_ptr<const smpl::BodyModel> posing_model;
  std::vector<std::uint32_t> headless_faces;  ///< faces without head vertices (first person)
};

/// Feedback the platform gives the user this frame, in order: a confirmation tone (Tone) or a
/// controller vibration (Haptic, on `hand`).
struct Feedback {
  enum class Kind { Tone, Haptic };
  Kind kind = Kind::Tone;
  Tip hand = Tip::Right;   ///< Haptic: which controller
  double amplitude = 0.0;  ///< Haptic: 0..1
  double seconds = 0.0;    ///< Haptic: duration
  bool operator==(const Feedback& o) const {
    return kind == o.kind && hand == o.hand && amplitude == o.amplitude && seconds == o.seconds;
  }
};

/// The instruction video the current step shows (docs/vr.md): `path` is the protocol's video
/// file resolved against the protocol's folder; a new `step` restarts it.
struct InstructionVideo {
  std::string step;
  std::string path;
};

/// Seconds a tip stays green after an accepted sample (and red after a rejected one).
constexpr double kFlashSeconds = 0.4;

class VrSession {
 public:
  /// Restores `options.resume` and opens the journal. Throws on an unreadable or mismatched
  /// journal (caliper::JournalError and the file errors of JournalWriter).
  explicit VrSession(VrSessionOptions options);
  VrSession(const VrSession&) = delete;
  VrSession& operator=(const VrSession&) = delete;

  /// Feeds one frame: session, journal, avatar at the end, embodiment after it. Returns this
  /// frame's events; feedback() holds the tones and haptics they ask for.
  const std::vector<SessionEvent>& advance(const PoseFrame& frame);
  /// The feedback asked for by the last advance() (accepted: tone + strong short pulse;
  /// rejected: weak long pulse).
  const std::vector<Feedback>& feedback() const { return feedback_; }
  /// An operator command from the desktop window: journalled, its events appended to events().
  void command(const OperatorCommand& command);
  /// This frame's events (advance() and the commands since).
  const std::vector<SessionEvent>& events() const { return events_; }
  /// New tip offsets (the runtime reported another interaction profile).
  void set_tips(const TipOffsets& tips) { options_.tips = tips; }

  const VrSessionOptions& options() const { return options_; }
  const MeasuringSession& measuring() const { return session_; }
  const std::optional<AvatarOutcome>& avatar() const { return avatar_; }
  /// Session complete and avatar made (or failed with avatar_error()).
  bool finished() const { return finished_; }
  const std::string& avatar_error() const { return avatar_error_; }
  int accepted_this_run() const { return accepted_; }
  int rejected_this_run() const { return rejected_; }
  double time() const { return time_; }
  /// Time of the last rejected sample (-1e9 before any).
  double last_reject_time() const { return last_reject_time_; }
  const PoseFrame& last_frame() const { return frame_; }
  /// Seconds since the current step (or floor phase) began.
  double step_time() const { return time_ - step_started_; }
  /// After the session is complete: the user pressed the end button (menu, either controller;
  /// pressed after completion, so a button held through the last sample does not count).
  bool end_requested() const { return end_requested_; }

  /// The embodiment solver (after the avatar is made, if its model has SMPL's skeleton).
  const BodyIk* body_ik() const { return body_ik_ ? &*body_ik_ : nullptr; }
  const EmbodimentStats& embodiment() const { return stats_; }
  /// World vertices of the driven avatar this frame (its rest vertices while not driven; empty
  /// before the avatar exists). Evaluated at most once per driven frame.
  const smpl::Vertices& posed_vertices() const;
  /// The mirror, placed when the avatar was made.
  const MirrorPlane& mirror() const { return mirror_; }

  /// What the instruction panel says now.
  PanelContent panel() const;
  /// The current step's instruction video, if it has one.
  std::optional<InstructionVideo> instruction_video() const;

  /// Writes output_dir/avatar.glb and output_dir/session.json (when output_dir is set).
  /// Returns the files written.
  std::vector<std::string> write_outputs();
  /// write_outputs() has been called.
  bool outputs_written() const { return outputs_written_; }
  /// The session file content.
  Json session_json() const;

 private:
  void make_avatar();
  void drive_avatar();
  void record_embodiment(const IkPose& pose);
  PanelContent done_panel() const;

  VrSessionOptions options_;
  MeasuringSession session_;
  std::optional<JournalWriter> journal_;
  std::vector<SessionEvent> events_;
  std::vector<Feedback> feedback_;
  PoseFrame frame_;
  double time_ = 0.0;
  double step_started_ = 0.0;
  int accepted_ = 0, rejected_ = 0;
  double last_reject_time_ = -1e9;
  bool finished_ = false;
  bool end_requested_ = false;
  bool end_button_released_ = false;  ///< no menu button held since completion
  bool outputs_written_ = false;
  std::optional<AvatarOutcome> avatar_;
  std::string avatar_error_;
  // Embodiment.
  std::optional<BodyIk> body_ik_;
  EmbodimentStats stats_;
  std::vector<Eigen::Vector3d> previous_joints_;
  double previous_time_ = 0.0;
  MirrorPlane mirror_;
  // The posed mesh, evaluated lazily (only when something draws it).
  mutable smpl::Workspace posing_workspace_;
  mutable smpl::Body posed_;
  mutable long posed_frame_ = -1;
};

/// The typed values the operator window shows: the session's (typed in the window, in a log,
/// or given with --weight/--sex), else the field's starting value (70 kg, no sex chosen).
struct TypedFields {
  double weight = 70.0;  ///< kg
  int sex = -1;          ///< 0 female, 1 male, -1 none
};
TypedFields typed_fields(const MeasuringSession& session);

/// Loads an open default model by sex from `dir` ("caliper-female.npz", ...; "" or unknown sex:
/// neutral). Throws smpl::ModelError naming the file.
std::shared_ptr<const smpl::BodyModel> load_default_model(const std::string& dir,
                                                          const std::string& sex);

/// Rest-pose vertices standing on y = 0 and centred in x and z.
smpl::Vertices standing(const smpl::Vertices& v);

/// Yaw (about +Y) that turns +Z into the head's horizontal forward direction (OpenXR looks
/// along -Z); 0 when the head looks straight up or down.
double head_yaw(const Eigen::Quaterniond& head);

}  // namespace caliper::vr
