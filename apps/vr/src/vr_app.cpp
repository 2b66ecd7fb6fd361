// The VR measuring app's frame logic and scene (see vr_app.hpp).
//
// Sections: helpers | construction | advance (session, journal, tones, haptics) | avatar |
// panel | scene (floor targets, controllers, demonstration, mirror) | views | outputs.
#include "vr_app.hpp"

#include <cmath>
#include <filesystem>
#include <sstream>

#include "caliper/assets.hpp"
#include "caliper/cpu_time.hpp"
#include "caliper/errors.hpp"
#include "caliper/measurements.hpp"
#include "caliper/regressor.hpp"
#include "render/camera.hpp"
#include "smpl/constants.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"

namespace caliper::vr {
namespace {

using smpl::kPiF;

/// The open default model for a sex: "female" and "male" have their own, anything else
/// (unknown, not given) the neutral one.
std::string open_model_sex(const std::string& sex) {
  return (sex == "female" || sex == "male") ? sex : "neutral";
}
constexpr double kFlashSeconds = 0.4;   ///< green tip after an accepted sample
constexpr double kIpd = 0.064;          ///< m, interpupillary distance of the stereo views
constexpr float kFovYDegrees = 100.0f;  ///< vertical field of view of the stereo views
const Eigen::Vector3d kPanelCentre(-0.15, 1.35, 0.95);  ///< in front of the user (who faces +Z)
constexpr double kPanelHalfWidth = 0.36;
const Eigen::Vector3d kDemoPosition(0.8, 0.0, 1.7);  ///< reference avatar beside the panel
constexpr double kMirrorDistance = 1.6;              ///< m in front of the head (rest avatar)
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

render::Vec3 f3(const Eigen::Vector3d& v) {
  return v.cast<float>();
}

/// The mirror's frame: a rectangle 2.1 m high and 2 x `half_width` wide standing on the floor
/// point `centre`, in the vertical plane whose horizontal normal is `normal`.
void add_mirror_frame(render::Scene& scene, const Eigen::Vector3d& centre,
                      const Eigen::Vector3d& normal, double half_width) {
  const Eigen::Vector3d side = Eigen::Vector3d(normal.z(), 0.0, -normal.x()) * half_width;
  const Eigen::Vector3d up(0.0, 2.1, 0.0);
  const Eigen::Vector3d corners[4] = {centre - side, centre + side, centre + side + up,
                                      centre - side + up};
  for (int i = 0; i < 4; ++i) {
    render::Line l;
    l.a = f3(corners[i]);
    l.b = f3(corners[(i + 1) % 4]);
    l.colour = {0.35f, 0.3f, 0.25f, 1};
    l.on_top = false;
    scene.lines.push_back(l);
  }
}

std::string cm(double metres) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(1);
  s << metres * 100.0 << " cm";
  return s.str();
}

render::Mat4 pose_matrix(const Eigen::Quaterniond& q, const Eigen::Vector3d& p) {
  render::Mat4 m = render::Mat4::Identity();
  m.block<3, 3>(0, 0) = q.toRotationMatrix().cast<float>();
  m.block<3, 1>(0, 3) = p.cast<float>();
  return m;
}

void add_circle(render::Scene& scene, const Eigen::Vector3d& centre, double radius,
                const render::Rgba& colour, double fraction = 1.0, int segments = 40) {
  const int n = std::max(1, static_cast<int>(std::ceil(segments * fraction)));
  for (int i = 0; i < n; ++i) {
    const double a0 = 2.0 * kPiF * fraction * i / n, a1 = 2.0 * kPiF * fraction * (i + 1) / n;
    render::Line l;
    l.a = f3(centre + radius * Eigen::Vector3d(std::sin(a0), 0.0, std::cos(a0)));
    l.b = f3(centre + radius * Eigen::Vector3d(std::sin(a1), 0.0, std::cos(a1)));
    l.colour = colour;
    l.on_top = false;
    scene.lines.push_back(l);
  }
}

render::MeshData mesh_data(const smpl::Vertices& v, const smpl::Faces& f) {
  render::MeshData m;
  m.positions.resize(static_cast<size_t>(v.size()));
  for (Eigen::Index i = 0; i < v.rows(); ++i)
    for (int c = 0; c < 3; ++c)
      m.positions[static_cast<size_t>(3 * i + c)] = static_cast<float>(v(i, c));
  m.indices.resize(static_cast<size_t>(f.size()));
  for (Eigen::Index i = 0; i < f.rows(); ++i)
    for (int c = 0; c < 3; ++c)
      m.indices[static_cast<size_t>(3 * i + c)] = static_cast<std::uint32_t>(f(i, c));
  return m;
}

/// Rest-pose vertices standing on y = 0 and centred in x and z.
smpl::Vertices standing(const smpl::Vertices& v) {
  const Eigen::RowVector3d lo = v.colwise().minCoeff(), hi = v.colwise().maxCoeff();
  smpl::Vertices out = v;
  out.rowwise() -= Eigen::RowVector3d((lo.x() + hi.x()) / 2.0, lo.y(), (lo.z() + hi.z()) / 2.0);
  return out;
}

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3.0 - 2.0 * x);
}

/// Yaw (about +Y) that turns +Z into the head's horizontal forward direction.
double head_yaw(const Eigen::Quaterniond& head) {
  const Eigen::Vector3d f = head * Eigen::Vector3d(0.0, 0.0, -1.0);
  if (std::abs(f.x()) + std::abs(f.z()) < 1e-9) return 0.0;
  return std::atan2(f.x(), f.z());
}

}  // namespace

std::shared_ptr<const smpl::BodyModel> load_default_model(const std::string& dir,
                                                          const std::string& sex) {
  return std::make_shared<const smpl::BodyModel>(
      smpl::load_model(default_model_path(dir, open_model_sex(sex))));
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

// ---------------------------------------------------------------------------------------------
// Construction

VrApp::VrApp(VrAppOptions options, Audio& audio, render::Renderer* renderer)
    : options_(std::move(options)),
      audio_(audio),
      renderer_(renderer),
      session_(options_.protocol, options_.session) {
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
  if (options_.demo_avatar) {
    try {
      demo_model_ = options_.avatar.model_path.empty()
                        ? load_default_model(options_.avatar.models_dir, "")
                        : std::make_shared<const smpl::BodyModel>(
                              smpl::load_model(options_.avatar.model_path));
      demo_vertices_ = standing(demo_model_->v_template);
      for (const auto& kv : landmarks_for(*demo_model_))
        demo_landmarks_[kv.first] = landmark_point(demo_vertices_, kv.second);
    } catch (const std::exception&) {
      demo_model_.reset();  // no model: the demonstration shows the controllers and targets only
    }
  }
}

VrApp::~VrApp() = default;

// ---------------------------------------------------------------------------------------------
// Advance

const std::vector<SessionEvent>& VrApp::advance(const PoseFrame& frame, PoseSource* haptics) {
  frame_ = frame;
  time_ = frame.time;
  events_ = session_.update(session_frame(frame, options_.tips));
  for (const SessionEvent& e : events_) {
    if (e.record && journal_) journal_->append(*e.record);
    switch (e.type) {
      case EventType::SampleAccepted:
        ++accepted_;
        audio_.confirm();
        if (haptics) haptics->haptic_pulse(e.hand, 0.8, 0.08);
        break;
      case EventType::SampleRejected:
        ++rejected_;
        last_reject_time_ = time_;
        if (haptics) haptics->haptic_pulse(e.hand, 0.3, 0.25);
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
  if (finished_) drive_avatar();
  if (finished_) {
    const bool menu = (frame.device(Device::Left).valid && frame.device(Device::Left).menu) ||
                      (frame.device(Device::Right).valid && frame.device(Device::Right).menu);
    if (!menu) end_button_released_ = true;
    if (menu && end_button_released_) end_requested_ = true;
  }
  return events_;
}

void VrApp::command(const OperatorCommand& c) {
  std::vector<SessionEvent> ev = session_.command(c, time_);
  for (const SessionEvent& e : ev)
    if (e.record && journal_) journal_->append(*e.record);
  events_.insert(events_.end(), ev.begin(), ev.end());
}

// ---------------------------------------------------------------------------------------------
// Avatar

void VrApp::make_avatar() {
  const SessionResult r = session_.result();
  try {
    AvatarOutcome out;
    out.model_path = options_.avatar.model_path;
    if (out.model_path.empty()) {
      out.model_path = default_model_path(options_.avatar.models_dir, open_model_sex(r.sex));
    }
    out.model = std::make_shared<const smpl::BodyModel>(smpl::load_model(out.model_path));
    const RegressorSet set = options_.avatar.regressors_path.empty()
                                 ? train_regressors(*out.model)
                                 : RegressorSet::load(options_.avatar.regressors_path);
    const LinearRegressor* reg = set.find(options_.avatar.regressor);
    if (!reg)
      throw InvalidInputError("no regressor \"" + options_.avatar.regressor +
                              "\" (use R2, R4, R5 or R6)");
    out.regressor = reg->name();
    std::optional<MeasurementMapping> mapping;
    AvatarOptions ao;
    if (!options_.avatar.mapping_path.empty()) {
      mapping = MeasurementMapping::load(options_.avatar.mapping_path);
      ao.mapping = &*mapping;
      out.mapping_path = options_.avatar.mapping_path;
    }
    ao.circumferences = false;
    MeasurementMap inputs;
    for (const std::string& id : reg->inputs()) {
      auto it = r.measurements.find(id);
      if (it == r.measurements.end())
        throw InvalidInputError("the " + out.regressor + " regressor needs \"" + id +
                                "\", which was skipped");
      inputs[id] = it->second;
    }
    out.avatar = create_avatar(*out.model, *reg, inputs, ao);
    const smpl::Vertices v = standing(out.avatar.vertices);
    const LandmarkTable lm = landmarks_for(*out.model);
    if (auto it = lm.find("head_top"); it != lm.end())
      out.eye_height = landmark_point(v, it->second).y() - 0.11;
    out.avatar.vertices = v;
    // Embodiment: the solver, a model for per-frame posing and the first-person faces (no head
    // or neck, so that they do not block the own view). Models without SMPL's skeleton keep the
    // rest pose.
    try {
      auto posing = std::make_shared<smpl::BodyModel>(*out.model);
      posing->posedirs.resize(posing->posedirs.rows(), 0);
      const smpl::Faces& f = out.model->faces;
      for (Eigen::Index i = 0; i < f.rows(); ++i) {
        bool head = false;
        for (int c = 0; c < 3; ++c)
          head = head || out.model->weights.coeff(f(i, c), ik_joint::kHead) +
                                 out.model->weights.coeff(f(i, c), ik_joint::kNeck) >
                             0.5;
        if (head) continue;
        for (int c = 0; c < 3; ++c)
          out.headless_faces.push_back(static_cast<std::uint32_t>(f(i, c)));
      }
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

void VrApp::drive_avatar() {
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
  ++stats_.frames;
  using namespace ik_joint;
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

const smpl::Vertices& VrApp::posed_vertices() {
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

PanelContent VrApp::panel_content() const {
  PanelContent c;
  const SessionView& v = session_.view();
  const Protocol& p = options_.protocol;
  c.highlight = time_ - v.last_accept_time < kFlashSeconds;
  switch (v.phase) {
    case Phase::WaitingForStart:
      c.title = "The Virtual Caliper";
      c.body = "Welcome. The operator will start the measurements.";
      break;
    case Phase::Floor: {
      c.title = "Floor calibration " + std::to_string(v.floor_target + 1) + " / " +
                std::to_string(p.floor.targets.size());
      c.body = p.floor.instruction;
      break;
    }
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
    case Phase::Done: {
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
      break;
    }
  }
  if (v.holding)
    c.footer = "Hold still... " + std::to_string(static_cast<int>(v.hold_progress * 100.0)) + " %";
  else
    c.footer = v.message;
  if (c.footer == c.body || v.phase == Phase::Done) c.footer.clear();
  return c;
}

// ---------------------------------------------------------------------------------------------
// Scene

render::MeshHandle VrApp::ensure_mesh(render::MeshHandle& handle, const smpl::Vertices& v,
                                      const smpl::Faces& f) {
  if (!handle && renderer_) handle = renderer_->upload_mesh(mesh_data(v, f));
  return handle;
}

void VrApp::add_floor_targets(render::Scene& scene) const {
  const SessionView& v = session_.view();
  const std::vector<Eigen::Vector2d>& targets = options_.protocol.floor.targets;
  const double y = 0.003;  // runtime floor until calibrated
  for (size_t i = 0; i < targets.size(); ++i) {
    const Eigen::Vector3d c(targets[i].x(), y, targets[i].y());
    const bool done = static_cast<int>(i) < v.floor_target;
    const bool current = static_cast<int>(i) == v.floor_target;
    const render::Rgba colour = done      ? render::Rgba{0.1f, 0.7f, 0.2f, 1}
                                : current ? render::Rgba{0.1f, 0.35f, 0.95f, 1}
                                          : render::Rgba{0.5f, 0.5f, 0.55f, 1};
    add_circle(scene, c, 0.08, colour);
    add_circle(scene, c, 0.075, colour);
    if (current) {
      const double pulse = 0.10 + 0.01 * std::sin(6.0 * time_);
      add_circle(scene, c, pulse, colour);
      if (v.holding)
        add_circle(scene, c + Eigen::Vector3d(0, 0.002, 0), 0.13,
                   render::Rgba{0.95f, 0.6f, 0.05f, 1}, v.hold_progress);
    }
    render::Label label;
    label.text = std::to_string(i + 1);
    label.anchor = f3(c + Eigen::Vector3d(0.0, 0.02, -0.16));
    label.scale = 2.0f;
    scene.labels.push_back(label);
  }
}

void VrApp::add_controllers(render::Scene& scene) const {
  const SessionView& v = session_.view();
  const bool flash = time_ - v.last_accept_time < kFlashSeconds;
  const bool rejected = time_ - last_reject_time_ < kFlashSeconds;
  for (Device d : {Device::Left, Device::Right}) {
    const DevicePose& p = frame_.device(d);
    if (!p.valid) continue;
    render::Box box;
    box.transform = pose_matrix(p.orientation, p.position);
    box.half_extents = {0.02f, 0.025f, 0.07f};
    scene.boxes.push_back(box);
    const Eigen::Vector3d& offset = d == Device::Left ? options_.tips.left : options_.tips.right;
    render::Point tip;
    tip.position = f3(tip_position(p, offset));
    tip.colour = flash      ? render::Rgba{0.1f, 0.8f, 0.2f, 1}
                 : rejected ? render::Rgba{0.9f, 0.15f, 0.1f, 1}
                            : render::Rgba{1.0f, 0.55f, 0.0f, 1};
    tip.size_px = flash ? 16.0f : 10.0f;
    scene.points.push_back(tip);
    const Tip hand = d == Device::Left ? Tip::Left : Tip::Right;
    if (v.holding && v.phase == Phase::Steps && hand == v.hold_hand)
      add_circle(scene, tip_position(p, offset), 0.05, render::Rgba{0.95f, 0.6f, 0.05f, 1},
                 v.hold_progress, 24);
  }
}

void VrApp::add_demo(render::Scene& scene) {
  const ProtocolStep* s = session_.current_step();
  if (!demo_model_ || !s) return;
  // The reference avatar faces the user (turned by 180 degrees), half size beside the panel.
  const double scale = 0.45;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(kPiF, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d base =
      kDemoPosition + Eigen::Vector3d(0.0, session_.floor().offset + 0.9, 0.0);
  const auto place = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector3d(base + scale * (R * p));
  };
  render::MeshInstance inst;
  inst.mesh = ensure_mesh(demo_mesh_, demo_vertices_, demo_model_->faces);
  inst.model = render::Mat4::Identity();
  inst.model.block<3, 3>(0, 0) = (scale * R).cast<float>();
  inst.model.block<3, 1>(0, 3) = base.cast<float>();
  inst.colour = {0.72f, 0.74f, 0.80f, 1.0f};
  if (inst.mesh) scene.meshes.push_back(inst);
  // Controllers move from the avatar's sides to the landmarks, hold, and start again.
  const double cycle = 3.0;
  const double phase = std::fmod(std::max(0.0, step_time()), cycle) / cycle;
  const double a = smoothstep(phase / 0.6);
  for (size_t k = 0; k < s->landmarks.size(); ++k) {
    auto it = demo_landmarks_.find(s->landmarks[k]);
    if (it == demo_landmarks_.end()) continue;
    const Eigen::Vector3d target = place(it->second);
    const Eigen::Vector3d start =
        place(Eigen::Vector3d(s->tips[k] == Tip::Left ? 0.35 : -0.35, 0.9, 0.35));
    const Eigen::Vector3d tip = start + a * (target - start);
    render::Point lmk;
    lmk.position = f3(target);
    lmk.colour = {0.9f, 0.1f, 0.5f, 1};
    lmk.size_px = 9.0f;
    scene.points.push_back(lmk);
    render::Box ctl;
    ctl.transform =
        pose_matrix(Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitX())),
                    tip + Eigen::Vector3d(0.0, 0.0, -0.04));
    ctl.half_extents = {0.01f, 0.0125f, 0.035f};
    ctl.colour = {0.25f, 0.25f, 0.3f, 1};
    scene.boxes.push_back(ctl);
    render::Line l;
    l.a = f3(tip);
    l.b = f3(target);
    l.colour = {0.9f, 0.1f, 0.5f, 1};
    l.on_top = true;
    if (a < 1.0) scene.lines.push_back(l);
  }
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

void VrApp::add_mirror(render::Scene& scene, bool own_head) {
  if (!avatar_) return;
  if (body_ik_ && renderer_ && stats_.frames > 0) {
    // The driven body: the user's own (first person, without the head) and its reflection in
    // a mirror fixed in the room (reflected vertices, triangles turned round so they still face
    // out).
    const smpl::Vertices& v = posed_vertices();
    std::vector<float> own(static_cast<size_t>(v.size()));
    for (Eigen::Index i = 0; i < v.rows(); ++i)
      for (int c = 0; c < 3; ++c) own[static_cast<size_t>(3 * i + c)] = static_cast<float>(v(i, c));
    const std::vector<float> mirrored = mirror_.reflect(v);
    if (!own_mesh_) {
      render::MeshData m;
      m.positions = own;
      m.indices = avatar_->headless_faces;
      own_mesh_ = renderer_->upload_mesh(m);
      const smpl::Faces& f = avatar_->model->faces;
      render::MeshData r;
      r.positions = mirrored;
      r.indices = MirrorPlane::reflected_triangles(f);
      mirror_mesh_ = renderer_->upload_mesh(r);
      render::MeshData full;
      full.positions = own;
      full.indices = mesh_data(v, f).indices;
      full_mesh_ = renderer_->upload_mesh(full);
    } else {
      renderer_->update_positions(own_mesh_, own);
      renderer_->update_positions(mirror_mesh_, mirrored);
      if (own_head) renderer_->update_positions(full_mesh_, own);
    }
    render::MeshInstance reflection;
    reflection.mesh = mirror_mesh_;
    scene.meshes.push_back(reflection);
    render::MeshInstance self;
    self.mesh = own_head ? full_mesh_ : own_mesh_;
    self.colour = {0.80f, 0.66f, 0.56f, 1.0f};
    scene.meshes.push_back(self);
    add_mirror_frame(scene, mirror_.centre, mirror_.normal, 0.7);
    return;
  }
  const smpl::Vertices& v = avatar_->avatar.vertices;
  const render::MeshHandle h = ensure_mesh(avatar_mesh_, v, avatar_->model->faces);
  const double floor = session_.floor().offset;
  const DevicePose& head = frame_.device(Device::Head);
  const double yaw = head_yaw(head.orientation);
  const Eigen::Vector3d forward(std::sin(yaw), 0.0, std::cos(yaw));
  const Eigen::Vector3d head_floor(head.position.x(), floor, head.position.z());
  // In the mirror: facing the user, kMirrorDistance in front of the head.
  {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(yaw + kPiF, Eigen::Vector3d::UnitY()).toRotationMatrix();
    render::MeshInstance inst;
    inst.mesh = h;
    inst.model.block<3, 3>(0, 0) = R.cast<float>();
    inst.model.block<3, 1>(0, 3) = f3(head_floor + kMirrorDistance * forward);
    if (h) scene.meshes.push_back(inst);
    add_mirror_frame(scene, head_floor + (kMirrorDistance + 0.25) * forward, forward, 0.55);
  }
  // First person: aligned to the headset (eyes at the head, facing where the head looks).
  {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Vector3d eye_offset(0.0, 0.0, 0.16);  // eyes in front of the head's centre line
    render::MeshInstance inst;
    inst.mesh = h;
    inst.model.block<3, 3>(0, 0) = R.cast<float>();
    inst.model.block<3, 1>(0, 3) = f3(head_floor - R * eye_offset);
    inst.colour = {0.80f, 0.66f, 0.56f, 1.0f};
    if (h) scene.meshes.push_back(inst);
  }
}

void VrApp::build_scene(render::Scene& scene, bool own_head) {
  scene = render::Scene{};
  scene.background = {0.80f, 0.86f, 0.92f, 1.0f};
  scene.grid.visible = true;
  scene.grid.height = static_cast<float>(session_.floor().valid ? session_.floor().offset : 0.0);
  scene.grid.extent = 2.5f;
  scene.light_direction = {0.3f, 0.7f, -0.65f};  // from behind the user, who faces +Z
  if (session_.view().phase == Phase::Floor) add_floor_targets(scene);
  add_controllers(scene);

  // Instruction panel: redrawn only when its text changes.
  const PanelContent content = panel_content();
  if (renderer_ && (!panel_texture_ || content != panel_)) {
    const render::Image img =
        panel_image(content, options_.panel_pixels, options_.panel_pixels * 5 / 8);
    if (!panel_texture_)
      panel_texture_ = renderer_->upload_texture(img);
    else
      renderer_->update_texture(panel_texture_, img);
  }
  panel_ = content;
  const double floor = session_.floor().offset;
  render::TexturedQuad quad;
  quad.texture = panel_texture_;
  quad.centre = f3(kPanelCentre + Eigen::Vector3d(0.0, floor, 0.0));
  quad.right = render::Vec3(static_cast<float>(-kPanelHalfWidth), 0,
                            0);  // the user faces +Z: their right is -X
  quad.up = render::Vec3(0, static_cast<float>(kPanelHalfWidth * 5.0 / 8.0), 0);
  if (panel_texture_ && session_.view().phase != Phase::Done) scene.quads.push_back(quad);
  if (session_.view().phase == Phase::Done && panel_texture_) {
    quad.centre = f3(kPanelCentre + Eigen::Vector3d(-0.7, floor, 0.3));
    scene.quads.push_back(quad);
  }

  // Instruction video of the current step, under the panel.
  const ProtocolStep* s = session_.current_step();
  const std::string want = s && !s->video.empty() ? s->id : "";
  if (want != video_step_) {
    video_.reset();
    video_step_ = want;
    if (!want.empty()) {
      try {
        video_ = std::make_unique<VideoPlayer>(
            (std::filesystem::path(options_.protocol_dir) / s->video).string());
      } catch (const VideoError&) {
        video_.reset();  // the panel text still explains the step
      }
    }
  }
  if (video_ && renderer_) {
    if (video_->seek_to(std::max(0.0, step_time())) || !video_texture_) {
      if (!video_texture_)
        video_texture_ = renderer_->upload_texture(video_->image());
      else
        renderer_->update_texture(video_texture_, video_->image());
    }
    render::TexturedQuad vq;
    vq.texture = video_texture_;
    const float aspect = static_cast<float>(video_->image().height) /
                         static_cast<float>(std::max(1, video_->image().width));
    // Under the panel, a little tilted towards the user's eyes.
    const float half = 0.15f;
    vq.centre =
        f3(kPanelCentre +
           Eigen::Vector3d(0.0, floor - kPanelHalfWidth * 5.0 / 8.0 - half * aspect - 0.02, 0.0));
    vq.right = render::Vec3(-half, 0, 0);
    vq.up = render::Vec3(0, half * aspect, 0);
    scene.quads.push_back(vq);
  }
  if (session_.view().phase == Phase::Steps) add_demo(scene);
  if (session_.view().phase == Phase::Done) add_mirror(scene, own_head);
}

// ---------------------------------------------------------------------------------------------
// Views

std::vector<render::View> VrApp::stereo_views(int eye_width, int eye_height) const {
  const DevicePose& head = frame_.device(Device::Head);
  std::vector<render::View> views;
  for (int eye = 0; eye < 2; ++eye) {
    const Eigen::Vector3d offset((eye == 0 ? -0.5 : 0.5) * kIpd, 0.0, 0.0);
    const Eigen::Vector3d pos = head.position + head.orientation * offset;
    render::View v;
    v.viewport = {eye * eye_width, 0, eye_width, eye_height};
    v.camera.use_matrices = true;
    v.camera.view = pose_matrix(head.orientation, pos).inverse();
    v.camera.projection = render::perspective(
        kFovYDegrees * kPiF / 180.0f,
        static_cast<float>(eye_width) / static_cast<float>(eye_height), 0.05f, 50.0f);
    views.push_back(v);
  }
  return views;
}

render::View VrApp::first_person_view(int width, int height, float pitch_degrees) const {
  const DevicePose& head = frame_.device(Device::Head);
  const double yaw = head_yaw(head.orientation);
  // OpenXR looks along -Z: turn by yaw + 180 degrees about Y, then pitch down.
  const Eigen::Quaterniond q =
      Eigen::Quaterniond(Eigen::AngleAxisd(yaw + kPiF, Eigen::Vector3d::UnitY())) *
      Eigen::Quaterniond(
          Eigen::AngleAxisd(-pitch_degrees * kPiF / 180.0, Eigen::Vector3d::UnitX()));
  render::View v;
  v.viewport = {0, 0, width, height};
  v.camera.use_matrices = true;
  v.camera.view = pose_matrix(q, head.position).inverse();
  v.camera.projection =
      render::perspective(kFovYDegrees * kPiF / 180.0f,
                          static_cast<float>(width) / static_cast<float>(height), 0.05f, 50.0f);
  return v;
}

render::View VrApp::operator_view(int width, int height) const {
  if (!body_ik_ || stats_.frames == 0) {
    render::View v = stereo_views(width, height)[0];
    v.viewport = {0, 0, width, height};
    return v;
  }
  const IkPose& p = body_ik_->pose();
  const Eigen::Vector3d chest = p.joints[ik_joint::kSpine3];
  const Eigen::Vector3d eye =
      chest + Eigen::AngleAxisd(p.body_yaw, Eigen::Vector3d::UnitY()) *
                  Eigen::Vector3d(1.2, 0.25, 1.9);  // the user's front left, a little higher
  render::View v;
  v.viewport = {0, 0, width, height};
  v.camera.eye = f3(eye);
  v.camera.target = f3(chest - Eigen::Vector3d(0.0, 0.25, 0.0));
  v.camera.fov_y_degrees = 55.0f;
  return v;
}

render::View VrApp::overview(int width, int height) const {
  render::View v;
  v.viewport = {0, 0, width, height};
  v.camera.eye = {0.9f, 2.3f, -2.0f};
  v.camera.target = {0.0f, 0.9f, 0.9f};
  v.camera.fov_y_degrees = 50.0f;
  return v;
}

// ---------------------------------------------------------------------------------------------
// Outputs

Json VrApp::session_json() const {
  const SessionResult r = session_.result();
  Json j = Json::object();
  j.set("format", "caliper-session");
  j.set("version", 1);
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

std::vector<std::string> VrApp::write_outputs() {
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
