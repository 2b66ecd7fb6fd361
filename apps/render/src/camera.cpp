#include "render/camera.hpp"
#include "smpl/constants.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace caliper::render {

namespace {
using smpl::kPiF;
}

Mat4 look_at(const Vec3& eye, const Vec3& target, const Vec3& up) {
  const Vec3 f = (target - eye).normalized();
  Vec3 s = f.cross(up);
  if (s.norm() < 1e-6f) s = f.cross(Vec3(0, 0, 1));  // looking straight up or down
  s.normalize();
  const Vec3 u = s.cross(f);
  Mat4 m = Mat4::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Mat4 perspective(float fov_y_radians, float aspect, float near_plane, float far_plane) {
  const float t = 1.0f / std::tan(fov_y_radians / 2);
  Mat4 m = Mat4::Zero();
  m(0, 0) = t / aspect;
  m(1, 1) = t;
  m(2, 2) = (far_plane + near_plane) / (near_plane - far_plane);
  m(2, 3) = 2 * far_plane * near_plane / (near_plane - far_plane);
  m(3, 2) = -1;
  return m;
}

Mat4 orthographic(float left, float right, float bottom, float top, float near_plane,
                  float far_plane) {
  Mat4 m = Mat4::Identity();
  m(0, 0) = 2 / (right - left);
  m(1, 1) = 2 / (top - bottom);
  m(2, 2) = -2 / (far_plane - near_plane);
  m(0, 3) = -(right + left) / (right - left);
  m(1, 3) = -(top + bottom) / (top - bottom);
  m(2, 3) = -(far_plane + near_plane) / (far_plane - near_plane);
  return m;
}

Mat4 view_matrix(const Camera& camera) {
  return camera.use_matrices ? camera.view : look_at(camera.eye, camera.target, camera.up);
}

Mat4 projection_matrix(const Camera& camera, float aspect) {
  if (camera.use_matrices) return camera.projection;
  if (camera.orthographic) {
    const float h = camera.ortho_half_height;
    return orthographic(-h * aspect, h * aspect, -h, h, camera.near_plane, camera.far_plane);
  }
  return perspective(camera.fov_y_degrees * kPiF / 180, aspect, camera.near_plane,
                     camera.far_plane);
}

float view_azimuth_degrees(StandardView view) {
  switch (view) {
    case StandardView::Front:
      return 0;
    case StandardView::Side:
      return 90;
    case StandardView::ThreeQuarter:
      return 35;
    case StandardView::Back:
      return 180;
  }
  return 0;
}

StandardView parse_standard_view(const std::string& name) {
  if (name == "front") return StandardView::Front;
  if (name == "side") return StandardView::Side;
  if (name == "three_quarter" || name == "three-quarter") return StandardView::ThreeQuarter;
  if (name == "back") return StandardView::Back;
  throw std::invalid_argument("unknown view '" + name +
                              "': use front, side, three_quarter or back");
}

Camera frame_box(const Vec3& lo, const Vec3& hi, float azimuth_degrees, float aspect,
                 float elevation_degrees) {
  Camera c;
  const Vec3 centre = (lo + hi) / 2;
  const float radius = std::max(0.05f, (hi - lo).norm() / 2);
  const float az = azimuth_degrees * kPiF / 180;
  const float el = elevation_degrees * kPiF / 180;
  const Vec3 dir(std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el));
  const float fov = c.fov_y_degrees * kPiF / 180;
  // Distance so that the bounding sphere fits the narrower of the two fields of view.
  const float half = std::min(fov / 2, std::atan(std::tan(fov / 2) * aspect));
  const float distance = radius / std::sin(half) * 1.02f;
  c.target = centre;
  c.eye = centre + dir * distance;
  c.near_plane = std::max(0.01f, distance - radius * 2);
  c.far_plane = distance + radius * 4;
  return c;
}

Camera frame_points_tight(const std::vector<Vec3>& points, float azimuth_degrees, float aspect,
                          float elevation_degrees, float margin) {
  if (points.empty()) throw std::invalid_argument("frame_points_tight: no points");
  Vec3 lo = points.front(), hi = points.front();
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Camera c = frame_box(lo, hi, azimuth_degrees, aspect, elevation_degrees);
  const Vec3 centre = c.target;
  const Vec3 back = (c.eye - centre).normalized();  // from the target towards the eye
  const Vec3 right = c.up.cross(back).normalized();
  const Vec3 up = back.cross(right);
  const float tan_v = std::tan(c.fov_y_degrees * kPiF / 360) * (1 - margin);
  const float tan_h = tan_v * aspect;
  // A point at (x, y, z) in the camera's axes around the target is inside the picture when
  // |x| <= tan_h * (d - z) and |y| <= tan_v * (d - z), with d the eye's distance to the target.
  const float radius = std::max(0.05f, (hi - lo).norm() / 2);
  float distance = radius * 0.5f;
  for (const Vec3& p : points) {
    const Vec3 q = p - centre;
    const float z = q.dot(back);
    distance =
        std::max({distance, z + std::abs(q.dot(right)) / tan_h, z + std::abs(q.dot(up)) / tan_v});
  }
  c.eye = centre + back * distance;
  c.near_plane = std::max(0.01f, distance - radius * 2);
  c.far_plane = distance + radius * 4;
  return c;
}

Camera frame_box_tight(const Vec3& lo, const Vec3& hi, float azimuth_degrees, float aspect,
                       float elevation_degrees, float margin) {
  std::vector<Vec3> corners;
  corners.reserve(8);
  for (int i = 0; i < 8; ++i)
    corners.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(),
                         (i & 4) ? hi.z() : lo.z());
  return frame_points_tight(corners, azimuth_degrees, aspect, elevation_degrees, margin);
}

}  // namespace caliper::render
