// A comparison avatar and its distance to the current one.
#include "app/comparison.hpp"

namespace caliper::app {

Comparison pin(const std::string& label, const AvatarView& avatar) {
  Comparison c;
  c.label = label;
  c.vertices = avatar.vertices;
  c.values = avatar.achieved;
  c.difference.assign(static_cast<size_t>(c.vertices.rows()), 0.0f);
  return c;
}

void update_difference(Comparison& c, const smpl::Vertices& current) {
  if (c.vertices.rows() != current.rows()) {
    c.difference.clear();
    return;
  }
  c.difference.resize(static_cast<size_t>(current.rows()));
  for (Eigen::Index v = 0; v < current.rows(); ++v) {
    c.difference[static_cast<size_t>(v)] =
        static_cast<float>((current.row(v) - c.vertices.row(v)).norm());
  }
}

}  // namespace caliper::app
