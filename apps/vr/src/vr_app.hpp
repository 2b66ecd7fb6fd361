/// \file vr_app.hpp
/// The VR measuring app without its platform: it takes one PoseFrame per displayed frame (from
/// OpenXR or a pose log), runs the measuring session, writes the journal, plays the tones and
/// haptics, makes the avatar at the end, and builds the render::Scene that the renderer draws
/// for each eye. The OpenXR loop (openxr_system.cpp), the headless replay (main.cpp) and the
/// benchmark drive this same class.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "audio.hpp"
#include "caliper/avatar.hpp"
#include "caliper/body_ik.hpp"
#include "caliper/journal.hpp"
#include "caliper/session.hpp"
#include "panel.hpp"
#include "pose_source.hpp"
#include "render/renderer.hpp"
#include "render/scene.hpp"
#include "smpl/body_model.hpp"
#include "smpl/evaluate.hpp"
#include "video.hpp"

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

struct VrAppOptions {
  Protocol protocol;
  std::string protocol_dir;  ///< folder of the protocol file (video paths are relative to it)
  SessionOptions session;
  TipOffsets tips;
  std::string journal_path;               ///< "" = no journal
  std::optional<JournalContents> resume;  ///< records to restore first (--resume)
  AvatarSettings avatar;
  std::string output_dir;   ///< avatar.glb and session.json at the end ("" = none)
  bool demo_avatar = true;  ///< show the animated reference avatar on the instruction panel
  int panel_pixels = 512;   ///< instruction panel texture width (height = 5/8 of it)
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

class VrApp {
 public:
  /// `renderer` may be null (no drawing: tests of the logic). Throws on unreadable files.
  VrApp(VrAppOptions options, Audio& audio, render::Renderer* renderer);
  ~VrApp();
  VrApp(const VrApp&) = delete;
  VrApp& operator=(const VrApp&) = delete;

  /// Feeds one frame: session, journal, tone, haptics (through `haptics` if given), avatar at
  /// the end. Returns this frame's events.
  const std::vector<SessionEvent>& advance(const PoseFrame& frame, PoseSource* haptics = nullptr);
  /// New tip offsets (the runtime reported another interaction profile).
  void set_tips(const TipOffsets& tips) { options_.tips = tips; }
  /// An operator command from the desktop window (recorded by the caller if recording).
  void command(const OperatorCommand& command);

  /// Fills `scene` for the current state (uploads changed textures and meshes when a renderer
  /// was given).
  void build_scene(render::Scene& scene) { build_scene(scene, false); }
  /// As build_scene(); with `own_head` the driven body keeps its head (seen from outside: the
  /// operator's window), otherwise the head is left out (it would block the user's own view).
  void build_scene(render::Scene& scene, bool own_head);
  /// Two eye views side by side in a framebuffer of 2 eye_width x eye_height pixels, from the
  /// last head pose (interpupillary distance 64 mm, symmetric 100 degree vertical field).
  std::vector<render::View> stereo_views(int eye_width, int eye_height) const;
  /// One view from the head looking down by `pitch_degrees` (the first-person check).
  render::View first_person_view(int width, int height, float pitch_degrees = 60.0f) const;
  /// One view from behind and above the user (documentation pictures of the whole scene).
  render::View overview(int width, int height) const;
  /// The operator's view of the driven avatar: from in front and to the side of the user, 2.3 m
  /// away, following the body's heading (the left eye's view before the avatar exists).
  render::View operator_view(int width, int height) const;

  const MeasuringSession& session() const { return session_; }
  const std::optional<AvatarOutcome>& avatar() const { return avatar_; }
  /// Session complete and avatar made (or failed with avatar_error()).
  bool finished() const { return finished_; }
  const std::string& avatar_error() const { return avatar_error_; }
  int accepted_this_run() const { return accepted_; }
  int rejected_this_run() const { return rejected_; }
  double time() const { return time_; }
  const PoseFrame& last_frame() const { return frame_; }
  /// Seconds since the current step (or floor phase) began.
  double step_time() const { return time_ - step_started_; }

  /// After the session is complete: the user pressed the end button (menu, either controller;
  /// pressed after completion, so a button held through the last sample does not count). The
  /// program ends the session on it.
  bool end_requested() const { return end_requested_; }
  /// The embodiment solver (after the avatar is made) and its statistics.
  const BodyIk* body_ik() const { return body_ik_ ? &*body_ik_ : nullptr; }
  const EmbodimentStats& embodiment() const { return stats_; }
  /// World vertices of the driven avatar this frame (empty before the avatar exists).
  const smpl::Vertices& posed_vertices();
  /// The instruction panel's content for the current state.
  PanelContent panel() const { return panel_content(); }

  /// Writes output_dir/avatar.glb and output_dir/session.json (when output_dir is set).
  /// Returns the files written.
  std::vector<std::string> write_outputs();
  /// write_outputs() has been called.
  bool outputs_written() const { return outputs_written_; }
  /// The session file content.
  Json session_json() const;

 private:
  void make_avatar();
  PanelContent panel_content() const;
  void add_floor_targets(render::Scene& scene) const;
  void add_controllers(render::Scene& scene) const;
  void add_demo(render::Scene& scene);
  void add_mirror(render::Scene& scene, bool own_head);
  render::MeshHandle ensure_mesh(render::MeshHandle& handle, const smpl::Vertices& v,
                                 const smpl::Faces& f);

  VrAppOptions options_;
  Audio& audio_;
  render::Renderer* renderer_;
  MeasuringSession session_;
  std::optional<JournalWriter> journal_;
  std::vector<SessionEvent> events_;
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
  void drive_avatar();
  std::optional<BodyIk> body_ik_;
  EmbodimentStats stats_;
  std::vector<Eigen::Vector3d> previous_joints_;
  double previous_time_ = 0.0;
  smpl::Workspace posing_workspace_;
  smpl::Body posed_;
  long posed_frame_ = -1;
  MirrorPlane mirror_;
  render::MeshHandle mirror_mesh_ = 0, own_mesh_ = 0, full_mesh_ = 0;
  // Demonstration avatar (reference body).
  std::shared_ptr<const smpl::BodyModel> demo_model_;
  smpl::Vertices demo_vertices_;
  std::map<std::string, Eigen::Vector3d> demo_landmarks_;
  render::MeshHandle demo_mesh_ = 0, avatar_mesh_ = 0;
  // Panel texture.
  PanelContent panel_;
  render::TextureHandle panel_texture_ = 0;
  // Instruction video of the current step.
  std::unique_ptr<VideoPlayer> video_;
  std::string video_step_;
  render::TextureHandle video_texture_ = 0;
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

}  // namespace caliper::vr
