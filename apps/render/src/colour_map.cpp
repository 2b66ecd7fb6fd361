#include "render/colour_map.hpp"

#include <algorithm>
#include <cmath>

namespace caliper::render {

namespace {
struct Stop {
  float t, r, g, b;
};
Rgba lerp_stops(const Stop* stops, int n, float t) {
  t = std::clamp(t, 0.0f, 1.0f);
  for (int i = 1; i < n; ++i) {
    if (t <= stops[i].t) {
      const Stop& a = stops[i - 1];
      const Stop& b = stops[i];
      const float u = (t - a.t) / std::max(1e-6f, b.t - a.t);
      return {a.r + u * (b.r - a.r), a.g + u * (b.g - a.g), a.b + u * (b.b - a.b), 1};
    }
  }
  return {stops[n - 1].r, stops[n - 1].g, stops[n - 1].b, 1};
}
}  // namespace

Rgba colour_at(int map, float t) {
  static constexpr Stop kHeat[] = {{0.0f, 1.0f, 1.0f, 0.9f},
                                   {0.35f, 1.0f, 0.85f, 0.25f},
                                   {0.7f, 0.9f, 0.2f, 0.1f},
                                   {1.0f, 0.45f, 0.0f, 0.05f}};
  static constexpr Stop kDiverging[] = {
      {0.0f, 0.15f, 0.3f, 0.85f}, {0.5f, 0.95f, 0.95f, 0.95f}, {1.0f, 0.85f, 0.15f, 0.1f}};
  static constexpr Stop kTraffic[] = {
      {0.0f, 0.2f, 0.7f, 0.3f}, {0.5f, 0.95f, 0.8f, 0.2f}, {1.0f, 0.85f, 0.15f, 0.1f}};
  switch (map) {
    case kColourMapDiverging:
      return lerp_stops(kDiverging, 3, t);
    case kColourMapTraffic:
      return lerp_stops(kTraffic, 3, t);
    default:
      return lerp_stops(kHeat, 4, t);
  }
}

std::vector<float> colours_from_values(const std::vector<float>& values, float min_value,
                                       float max_value, int map) {
  std::vector<float> out(values.size() * 3);
  const float range = max_value - min_value;
  for (size_t i = 0; i < values.size(); ++i) {
    Rgba c{0.5f, 0.5f, 0.5f, 1};
    if (std::isfinite(values[i])) {
      const float t = range != 0 ? (values[i] - min_value) / range : 0.0f;
      c = colour_at(map, t);
    }
    out[3 * i] = c.r;
    out[3 * i + 1] = c.g;
    out[3 * i + 2] = c.b;
  }
  return out;
}

}  // namespace caliper::render
