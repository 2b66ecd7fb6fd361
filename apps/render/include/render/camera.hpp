/// \file camera.hpp
/// Camera matrices and the standard views of a body (front, side, three-quarter, turntable).
#pragma once

#include <string>
#include <vector>

#include "render/scene.hpp"

namespace caliper::render {

/// Right-handed look-at view matrix.
Mat4 look_at(const Vec3& eye, const Vec3& target, const Vec3& up);
/// OpenGL perspective projection (fov in radians, depth to [-1, 1]).
Mat4 perspective(float fov_y_radians, float aspect, float near_plane, float far_plane);
/// OpenGL orthographic projection.
Mat4 orthographic(float left, float right, float bottom, float top, float near_plane,
                  float far_plane);
/// View and projection of `camera` for a viewport with the given aspect (width / height).
Mat4 view_matrix(const Camera& camera);
Mat4 projection_matrix(const Camera& camera, float aspect);

/// Named standard views. The angle is the camera's azimuth about +Y: 0 = in front (+Z side),
/// 90 = the subject's left (+X side).
enum class StandardView { Front, Side, ThreeQuarter, Back };

/// Azimuth in degrees of a standard view (front 0, side 90, three-quarter 35, back 180).
float view_azimuth_degrees(StandardView view);
/// Parses "front", "side", "three_quarter", "back"; throws std::invalid_argument otherwise.
StandardView parse_standard_view(const std::string& name);

/// A camera that frames the axis-aligned box [lo, hi] from azimuth `azimuth_degrees` and a small
/// elevation, for a viewport of the given aspect; the whole box is visible with a margin.
Camera frame_box(const Vec3& lo, const Vec3& hi, float azimuth_degrees, float aspect,
                 float elevation_degrees = 8.0f);
/// Like frame_box, but the distance is the smallest at which all eight corners of the box fit
/// in the picture with `margin` (a fraction of each half-size, e.g. 0.05) to spare, so the box
/// fills the picture's height or width from this direction (frame_box fits the box's bounding
/// sphere into the narrower side, which leaves a standing body in T-pose half the height of a
/// portrait picture). The distance depends on the direction: use frame_box for turntables.
Camera frame_box_tight(const Vec3& lo, const Vec3& hi, float azimuth_degrees, float aspect,
                       float elevation_degrees = 8.0f, float margin = 0.05f);
/// The same for a set of points (e.g. a mesh's vertices: tighter than their box, whose near
/// corners stand far in front of a body seen from the side). Throws std::invalid_argument when
/// `points` is empty.
Camera frame_points_tight(const std::vector<Vec3>& points, float azimuth_degrees, float aspect,
                          float elevation_degrees = 8.0f, float margin = 0.05f);

}  // namespace caliper::render
