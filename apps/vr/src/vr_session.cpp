// The platform-free VR session (see vr_session.hpp).
//
// Sections: helpers | construction | advance (session, journal, feedback) | avatar |
// embodiment | panel | outputs.
#include "vr_session.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "caliper/assets.hpp"
#include "caliper/cpu_time.hpp"
#include "caliper/errors.hpp"
#include "caliper/measurements.hpp"
#include "caliper/regressor.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"

namespace caliper::vr {
namespace {

/// The open default model for a sex: "female" and "male" have their own, anything else
/// (unknown, not given) the neutral one.
std::string open_model_sex(const std::string& sex) {
  return (sex == "female" || sex == "male") ? sex : "neutral";
}

/// The mirror's plane, m in front of the head when the avatar is made (then fixed in the room);
/// the reflection of the user appears twice as far.
constexpr double kMirrorPlane = 1.0;

/// Distance of `p` from the segment a-b.
double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(1e-12, ab.squaredNorm()), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

std::string cm(double metres) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(1);
  s << metres * 100.0 << " cm";
  return s.str();
}

/// The faces of `model` without the head and neck (more than half of a corner's skinning
/// weight on them), so that the first-person body does not block the user's own view.
std::vector<std::uint32_t> headless_faces(const smpl::BodyModel& model) {
  std::vector<std::uint32_t> out;
  const smpl::Faces& f = model.faces;
  for (Eigen::Index i = 0; i < f.rows(); ++i) {
    bool head = false;
    for (int c = 0; c < 3; ++c)
      head = head || model.weights.coeff(f(i, c), ik_joint::kHead) +
                             model.weights.coeff(f(i, c), ik_joint::kNeck) >
                         0.5;
    if (head) continue;
    for (int c = 0; c < 3; ++c) out.push_back(static_cast<std::uint32_t>(f(i, c)));
  }
  return out;
}

/// The regressor's inputs from the session's result; throws InvalidInputError naming a skipped
/// measurement the regressor needs.
MeasurementMap regressor_inputs(const LinearRegressor& reg, const SessionResult& r) {
  MeasurementMap inputs;
  for (const std::string& id : reg.inputs()) {
    auto it = r.measurements.find(id);
    if (it == r.measurements.end())
      throw InvalidInputError("the " + reg.name() + " regressor needs \"" + id +
                              "\", which was skipped");
    inputs[id] = it->second;
  }
  return inputs;
}

/// The avatar of the session's result, standing on y = 0 (no embodiment yet).
AvatarOutcome shaped_avatar(const AvatarSettings& settings, const SessionResult& r) {
  AvatarOutcome out;
  out.model_path = settings.model_path;
  if (out.model_path.empty())
    out.model_path = default_model_path(settings.models_dir, open_model_sex(r.sex));
  out.model = std::make_shared<const smpl::BodyModel>(smpl::load_model(out.model_path));
  const RegressorSet set = settings.regressors_path.empty()
                               ? train_regressors(*out.model)
                               : RegressorSet::load(settings.regressors_path);
  const LinearRegressor* reg = set.find(settings.regressor);
  if (!reg)
    throw InvalidInputError("no regressor \"" + settings.regressor + "\" (use R2, R4, R5 or R6)");
  out.regressor = reg->name();
  std::optional<MeasurementMapping> mapping;
  AvatarOptions ao;
  if (!settings.mapping_path.empty()) {
    mapping = MeasurementMapping::load(settings.mapping_path);
    ao.mapping = &*mapping;
    out.mapping_path = settings.mapping_path;
  }
  ao.circumferences = false;
  out.avatar = create_avatar(*out.model, *reg, regressor_inputs(*reg, r), ao);
  const smpl::Vertices v = standing(out.avatar.vertices);
  const LandmarkTable lm = landmarks_for(*out.model);
  if (auto it = lm.find("head_top"); it != lm.end())
    out.eye_height = landmark_point(v, it->second).y() - 0.11;
  out.avatar.vertices = v;
  return out;
}

}  // namespace

std::shared_ptr<const smpl::BodyModel> load_default_model(const std::string& dir,
                                                          const std::string& sex) {
  return std::make_shared<const smpl::BodyModel>(
      smpl::load_model(default_model_path(dir, open_model_sex(sex))));
}

smpl::Vertices standing(const smpl::Vertices& v) {
  const Eigen::RowVector3d lo = v.colwise().minCoeff(), hi = v.colwise().maxCoeff();
  smpl::Vertices out = v;
  out.rowwise() -= Eigen::RowVector3d((lo.x() + hi.x()) / 2.0, lo.y(), (lo.z() + hi.z()) / 2.0);
  return out;
}

double head_yaw(const Eigen::Quaterniond& head) {
  const Eigen::Vector3d f = head * Eigen::Vector3d(0.0, 0.0, -1.0);
  if (std::abs(f.x()) + std::abs(f.z()) < 1e-9) return 0.0;
  return std::atan2(f.x(), f.z());
}

TypedFields typed_fields(const MeasuringSession& session) {
  TypedFields t;
  const SessionResult r = session.result();
  if (auto it = r.measurements.find("weight"); it != r.measurements.end())
    t.weight = it->second;
  else if (session.options().weight)
    t.weight = *session.options().weight;
  const std::string sex = !r.sex.empty() ? r.sex : session.options().sex;
  t.sex = sex == "female" ? 0 : sex == "male" ? 1 : -1;
  return t;
}

std::vector<float> MirrorPlane::reflect(const smpl::Vertices& v) const {
  std::vector<float> out(static_cast<size_t>(v.size()));
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    const Eigen::Vector3d r = reflect(Eigen::Vector3d(v.row(i).transpose()));
    for (int c = 0; c < 3; ++c) out[static_cast<size_t>(3 * i + c)] = static_cast<float>(r[c]);
  }
  return out;
}

std::vector<std::uint32_t> MirrorPlane::reflected_triangles(const smpl::Faces& faces) {
  std::vector<std::uint32_t> out;
  out.reserve(static_cast<size_t>(faces.size()));
  for (Eigen::Index i = 0; i < faces.rows(); ++i)
    for (int c : {0, 2, 1}) out.push_back(static_cast<std::uint32_t>(faces(i, c)));
  return out;
}

// ---------------------------------------------------------------------------------------------
// Construction

VrSession::VrSession(VrSessionOptions options)
    : options_(std::move(options)), session_(options_.protocol, options_.session) {
  if (options_.resume) {
    check_journal_protocol(*options_.resume, options_.protocol.name, options_.journal_path);
    for (const JournalRecord& r : options_.resume->records) session_.apply(r);
  }
  if (!options_.journal_path.empty()) {
    Json header = Json::object();
    header.set("protocol", options_.protocol.name);
    header.set("role", options_.session.role);
    journal_ = options_.resume
                   ? JournalWriter::resume(options_.journal_path, *options_.resume, header)
                   : JournalWriter::create(options_.journal_path, header);
  }
}

// ---------------------------------------------------------------------------------------------
// Advance

const std::vector<SessionEvent>& VrSession::advance(const PoseFrame& frame) {
  frame_ = frame;
  time_ = frame.time;
  feedback_.clear();
  events_ = session_.update(session_frame(frame, options_.tips));
  for (const SessionEvent& e : events_) {
    if (e.record && journal_) journal_->append(*e.record);
    switch (e.type) {
      case EventType::SampleAccepted:
        ++accepted_;
        feedback_.push_back({Feedback::Kind::Tone, e.hand, 0.0, 0.0});
        feedback_.push_back({Feedback::Kind::Haptic, e.hand, 0.8, 0.08});
        break;
      case EventType::SampleRejected:
        ++rejected_;
        last_reject_time_ = time_;
        feedback_.push_back({Feedback::Kind::Haptic, e.hand, 0.3, 0.25});
        break;
      case EventType::StepStarted:
      case EventType::Started:
      case EventType::FloorRetry:
        step_started_ = time_;
        break;
      default:
        break;
    }
  }
  if (session_.done() && !finished_) {
    make_avatar();
    finished_ = true;
  }
  if (finished_) {
    drive_avatar();
    const bool menu = (frame.device(Device::Left).valid && frame.device(Device::Left).menu) ||
                      (frame.device(Device::Right).valid && frame.device(Device::Right).menu);
    if (!menu) end_button_released_ = true;
    if (menu && end_button_released_) end_requested_ = true;
  }
  return events_;
}

void VrSession::command(const OperatorCommand& c) {
  std::vector<SessionEvent> ev = session_.command(c, time_);
  for (const SessionEvent& e : ev)
    if (e.record && journal_) journal_->append(*e.record);
  events_.insert(events_.end(), ev.begin(), ev.end());
}

// ---------------------------------------------------------------------------------------------
// Avatar

void VrSession::make_avatar() {
  try {
    AvatarOutcome out = shaped_avatar(options_.avatar, session_.result());
    // Embodiment: the solver, a model for per-frame posing and the first-person faces. Models
    // without SMPL's skeleton keep the rest pose.
    try {
      auto posing = std::make_shared<smpl::BodyModel>(*out.model);
      posing->posedirs.resize(posing->posedirs.rows(), 0);
      out.headless_faces = headless_faces(*out.model);
      const smpl::Vertices& v = out.avatar.vertices;
      const LandmarkTable lm = landmarks_for(*out.model);
      const Eigen::Vector3d top = lm.count("head_top")
                                      ? landmark_point(v, lm.at("head_top"))
                                      : Eigen::Vector3d(0.0, v.col(1).maxCoeff(), 0.0);
      body_ik_.emplace(make_ik_rig(*out.model, out.avatar.betas, eyes_below_head_top(top)));
      out.posing_model = std::move(posing);
    } catch (const IkError&) {
      body_ik_.reset();
    }
    const DevicePose& head = frame_.device(Device::Head);
    const double yaw = head_yaw(head.orientation);
    mirror_.normal = Eigen::Vector3d(std::sin(yaw), 0.0, std::cos(yaw));
    mirror_.centre =
        Eigen::Vector3d(head.position.x(), session_.floor().offset, head.position.z()) +
        kMirrorPlane * mirror_.normal;
    avatar_ = std::move(out);
  } catch (const std::exception& e) {
    avatar_error_ = e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Embodiment

void VrSession::drive_avatar() {
  const DevicePose& head = frame_.device(Device::Head);
  if (!body_ik_ || !head.valid) return;
  IkInput in;
  in.head.position = head.position;
  in.head.orientation = head.orientation;
  for (int h = 0; h < 2; ++h) {
    const DevicePose& d = frame_.device(h == 0 ? Device::Left : Device::Right);
    if (d.valid) in.grips[static_cast<size_t>(h)] = RigidPose{d.position, d.orientation};
  }
  in.floor = session_.floor().offset;
  in.time = time_;
  const double c0 = thread_cpu_seconds();
  const IkPose& p = body_ik_->solve(in);
  stats_.ik_cpu_seconds += thread_cpu_seconds() - c0;
  record_embodiment(p);
}

void VrSession::record_embodiment(const IkPose& p) {
  using namespace ik_joint;
  ++stats_.frames;
  EmbodimentStats::Frame fr;
  fr.time = time_;
  for (int h = 0; h < 2; ++h) {
    const size_t k = static_cast<size_t>(h);
    if (!p.hand_tracked[k] || !p.reachable[k]) continue;
    ++stats_.reachable_wrists;
    const double e = (p.joints[h == 0 ? kLeftWrist : kRightWrist] - p.wrist_target[k]).norm();
    stats_.max_wrist_error = std::max(stats_.max_wrist_error, e);
    fr.wrist_error = std::max(fr.wrist_error, e);
  }
  for (int j : {kLeftWrist, kRightWrist, kLeftHand, kRightHand})
    fr.hand_in_torso =
        fr.hand_in_torso || segment_distance(p.joints[static_cast<size_t>(j)], p.joints[kPelvis],
                                             p.joints[kNeck]) < kTorsoRadius;
  stats_.hands_in_torso += fr.hand_in_torso ? 1 : 0;
  fr.limit_violations =
      static_cast<int>(check_limits(body_ik_->rig(), p, body_ik_->options().limits).size());
  stats_.limit_violations += fr.limit_violations;
  if (!previous_joints_.empty())
    for (size_t j = 0; j < p.joints.size(); ++j) {
      const double step = (p.joints[j] - previous_joints_[j]).norm();
      fr.joint_step = std::max(fr.joint_step, step);
      if (step > stats_.max_joint_step) {
        stats_.max_joint_step = step;
        stats_.max_step_dt = time_ - previous_time_;
      }
    }
  stats_.per_frame.push_back(fr);
  previous_joints_ = p.joints;
  previous_time_ = time_;
}

const smpl::Vertices& VrSession::posed_vertices() const {
  if (!avatar_) return posed_.vertices;
  if (!body_ik_ || !avatar_->posing_model || body_ik_->pose().joints.empty() ||
      stats_.frames == 0) {
    posed_.vertices = avatar_->avatar.vertices;
    return posed_.vertices;
  }
  if (posed_frame_ != stats_.frames) {
    const IkPose& p = body_ik_->pose();
    smpl::evaluate(*avatar_->posing_model, avatar_->avatar.betas, p.axis_angle(), p.translation,
                   posing_workspace_, posed_);
    posed_frame_ = stats_.frames;
  }
  return posed_.vertices;
}

// ---------------------------------------------------------------------------------------------
// Panel

PanelContent VrSession::done_panel() const {
  PanelContent c;
  c.title = "Done";
  const SessionResult r = session_.result();
  for (const auto& kv : r.measurements) {
    std::string line =
        kv.first + ": " +
        (kv.first == "weight" ? std::to_string(static_cast<int>(std::lround(kv.second))) + " kg"
                              : cm(kv.second));
    if (auto t = r.takes.find(kv.first); t != r.takes.end())
      line += "  (" + std::to_string(t->second.size()) + " takes)";
    c.lines.push_back(line);
  }
  if (avatar_ && options_.session.role == "operator")
    c.body = "The avatar (" + avatar_->regressor +
             ") is in the mirror. Hand the headset and the controllers to the participant: "
             "it follows them.";
  else if (avatar_)
    c.body = "Your avatar (" + avatar_->regressor +
             ") is in the mirror in front of you. Look down to see your body.";
  else if (!avatar_error_.empty())
    c.body = "No avatar: " + avatar_error_;
  c.lines.push_back(kEndHint);
  return c;
}

PanelContent VrSession::panel() const {
  PanelContent c;
  const SessionView& v = session_.view();
  const Protocol& p = options_.protocol;
  switch (v.phase) {
    case Phase::WaitingForStart:
      c.title = "The Virtual Caliper";
      c.body = "Welcome. The operator will start the measurements.";
      break;
    case Phase::Floor:
      c.title = "Floor calibration " + std::to_string(v.floor_target + 1) + " / " +
                std::to_string(p.floor.targets.size());
      c.body = p.floor.instruction;
      break;
    case Phase::Steps: {
      const ProtocolStep& s = *session_.current_step();
      const StepState& st = session_.steps()[static_cast<size_t>(v.step)];
      c.title =
          s.title + "  (" + std::to_string(v.step + 1) + "/" + std::to_string(p.steps.size()) + ")";
      c.body = s.instruction;
      for (size_t k = 0; k < st.takes.size(); ++k)
        c.lines.push_back("Take " + std::to_string(k + 1) + ": " + cm(st.takes[k]));
      if (st.takes.size() == 2) c.lines.push_back("The takes differ: one more, please.");
      break;
    }
    case Phase::Done:
      c = done_panel();
      break;
  }
  c.highlight = time_ - v.last_accept_time < kFlashSeconds;
  if (v.holding)
    c.footer = "Hold still... " + std::to_string(static_cast<int>(v.hold_progress * 100.0)) + " %";
  else
    c.footer = v.message;
  if (c.footer == c.body || v.phase == Phase::Done) c.footer.clear();
  return c;
}

std::optional<InstructionVideo> VrSession::instruction_video() const {
  const ProtocolStep* s = session_.current_step();
  if (!s || s->video.empty()) return std::nullopt;
  return InstructionVideo{s->id,
                          (std::filesystem::path(options_.protocol_dir) / s->video).string()};
}

// ---------------------------------------------------------------------------------------------
// Outputs

Json VrSession::session_json() const {
  const SessionResult r = session_.result();
  Json j = format_header("caliper-session");
  j.set("protocol", options_.protocol.name);
  j.set("role", options_.session.role);
  j.set("complete", session_.done());
  Json floor = Json::object();
  floor.set("valid", session_.floor().valid);
  floor.set("offset_m", session_.floor().offset);
  floor.set("tilt_deg", session_.floor().tilt_deg);
  floor.set("residual_m", session_.floor().residual);
  j.set("floor", floor);
  Json m = Json::object();
  for (const auto& kv : r.measurements) {
    Json e = Json::object();
    e.set("value", kv.second);
    if (auto t = r.takes.find(kv.first); t != r.takes.end()) e.set("takes", Json(t->second));
    m.set(kv.first, e);
  }
  j.set("measurements", m);
  j.set("sex", r.sex);
  Json skipped = Json::array();
  for (const std::string& s : r.skipped) skipped.push_back(s);
  j.set("skipped", skipped);
  j.set("accepted_samples_this_run", accepted_);
  j.set("rejected_samples_this_run", rejected_);
  if (avatar_) {
    Json a = Json::object();
    a.set("model", std::filesystem::path(avatar_->model_path).filename().string());
    a.set("regressor", avatar_->regressor);
    a.set("mapping", avatar_->mapping_path.empty() ? Json() : Json(avatar_->mapping_path));
    std::vector<double> betas(avatar_->avatar.betas.data(),
                              avatar_->avatar.betas.data() + avatar_->avatar.betas.size());
    a.set("betas", Json(betas));
    Json achieved = Json::object();
    for (const auto& kv : avatar_->avatar.achieved) achieved.set(kv.first, kv.second);
    a.set("achieved", achieved);
    a.set("plausible", avatar_->avatar.plausibility.plausible);
    j.set("avatar", a);
  } else if (!avatar_error_.empty()) {
    j.set("avatar_error", avatar_error_);
  }
  return j;
}

std::vector<std::string> VrSession::write_outputs() {
  outputs_written_ = true;
  std::vector<std::string> files;
  if (options_.output_dir.empty()) return files;
  std::filesystem::create_directories(options_.output_dir);
  const std::string session_path =
      (std::filesystem::path(options_.output_dir) / "session.json").string();
  write_json_file(session_path, session_json());
  files.push_back(session_path);
  if (avatar_) {
    const std::string glb = (std::filesystem::path(options_.output_dir) / "avatar.glb").string();
    smpl::GltfOptions go;
    go.name = "caliper-avatar";
    go.extras["regressor"] = avatar_->regressor;
    smpl::write_gltf(glb, *avatar_->model, avatar_->avatar.betas, go);
    files.push_back(glb);
  }
  return files;
}

}  // namespace caliper::vr
