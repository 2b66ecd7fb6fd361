/// \file comparison.hpp
/// A comparison avatar pinned from an earlier state of the editor, and its per-vertex distance
/// to the current avatar (the difference colour map). Values are metres.
#pragma once

#include <string>
#include <vector>

#include "app/recompute.hpp"
#include "caliper/measurements.hpp"
#include "smpl/body_model.hpp"

namespace caliper::app {

/// A comparison avatar pinned from an earlier state.
struct Comparison {
  std::string label;
  smpl::Vertices vertices;  ///< floor at y = 0
  MeasurementMap values;
  std::vector<float> difference;  ///< per-vertex |current - pinned|, metres (same model only)
};

/// Pins `avatar` under `label`: its vertices and measurements, a difference of 0 everywhere.
Comparison pin(const std::string& label, const AvatarView& avatar);

/// Sets `c.difference` to the per-vertex distance between `current` and the pinned vertices;
/// empty when the vertex counts differ (another model).
void update_difference(Comparison& c, const smpl::Vertices& current);

}  // namespace caliper::app
