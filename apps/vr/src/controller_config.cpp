#include "controller_config.hpp"

#include <stdexcept>

#include "caliper/json.hpp"

namespace caliper::vr {
namespace {

Eigen::Vector3d vec3(const Json& j, const std::string& where) {
  const std::vector<double> v = j.as_numbers();
  if (v.size() != 3) throw std::runtime_error(where + " must be [x, y, z] in metres (grip frame)");
  return {v[0], v[1], v[2]};
}

Json vec_json(const Eigen::Vector3d& v) {
  return Json(std::vector<double>{v.x(), v.y(), v.z()});
}

TipOffsets parse_offsets(const Json& j, const std::string& where) {
  TipOffsets t;
  t.left = vec3(j.at("left"), where + ".left");
  t.right = vec3(j.at("right"), where + ".right");
  return t;
}

Json offsets_json(const TipOffsets& t) {
  Json j = Json::object();
  j.set("left", vec_json(t.left));
  j.set("right", vec_json(t.right));
  return j;
}

TipOffsets symmetric(double x, double y, double z) {
  TipOffsets t;
  t.left = Eigen::Vector3d(-x, y, z);
  t.right = Eigen::Vector3d(x, y, z);
  return t;
}

}  // namespace

TipOffsets ControllerConfig::offsets(const std::string& profile) const {
  auto it = profiles.find(profile);
  return it == profiles.end() ? fallback : it->second;
}

ControllerConfig default_controller_config() {
  ControllerConfig c;
  // Approximate handle-bottom points in each profile's grip frame (+Y up, -Z along the fingers);
  // run the pivot calibration to measure your own controllers.
  c.profiles[kProfiles[0]] = symmetric(0.0, -0.03, 0.09);  // HTC Vive wand
  c.profiles[kProfiles[1]] = symmetric(0.0, -0.05, 0.07);  // Valve Index
  c.profiles[kProfiles[2]] = symmetric(0.0, -0.04, 0.06);  // Oculus Touch
  c.profiles[kProfiles[3]] = symmetric(0.0, 0.0, 0.0);     // simple controller: grip = tip
  c.fallback = symmetric(0.0, -0.03, 0.09);
  return c;
}

ControllerConfig read_controller_config(const std::string& path) {
  const Json j = read_json_file(path);
  ControllerConfig c;
  try {
    if (!j.contains("format") || j.at("format").as_string() != "caliper-controllers")
      throw std::runtime_error(
          "not a controller config (expected {\"format\": \"caliper-controllers\"})");
    for (const auto& kv : j.at("profiles").as_object())
      c.profiles[kv.first] = parse_offsets(kv.second, "profiles[\"" + kv.first + "\"]");
    c.fallback = parse_offsets(j.at("fallback"), "fallback");
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  return c;
}

void write_controller_config(const std::string& path, const ControllerConfig& c) {
  Json j = format_header("caliper-controllers");
  j.set("comment",
        "Controller tip offsets in the grip frame (metres) per OpenXR interaction profile; "
        "measure yours with caliper-vr --calibrate-tip.");
  Json p = Json::object();
  for (const auto& kv : c.profiles) p.set(kv.first, offsets_json(kv.second));
  j.set("profiles", p);
  j.set("fallback", offsets_json(c.fallback));
  write_json_file(path, j);
}

}  // namespace caliper::vr
