/// \file colour_map.hpp
/// Colour maps for per-vertex values (plausibility, uncertainty, differences between avatars).
#pragma once

#include <vector>

#include "render/scene.hpp"

namespace caliper::render {

enum ColourMap : int {
  kColourMapHeat = 0,       ///< white-yellow-red-dark red: magnitudes (differences, uncertainty)
  kColourMapDiverging = 1,  ///< blue-white-red: signed values centred on 0
  kColourMapTraffic = 2,    ///< green-yellow-red: plausibility (0 good, 1 bad)
};

/// Colour of `t` in [0, 1] (clamped) under `map`.
Rgba colour_at(int map, float t);

/// Per-vertex RGB (3V floats) of values mapped linearly from [min_value, max_value] to [0, 1].
/// NaN values get mid-grey. min_value == max_value maps everything to 0.
std::vector<float> colours_from_values(const std::vector<float>& values, float min_value,
                                       float max_value, int map);

}  // namespace caliper::render
