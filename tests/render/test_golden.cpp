// Golden-image tests: pictures rendered under OSMesa (llvmpipe) compared with reviewed PNGs in
// tests/render/golden/. Regenerate with CALIPER_UPDATE_GOLDEN=1 after an intended change and
// look at the new pictures before committing them.
//
// Thresholds (per RGB channel, 0..255):
// - kMaxAbs = 64: llvmpipe is deterministic on one machine (we measured 0 difference between
//   runs), but another LLVM version or CPU (AVX2 vs SSE4 code paths) may move a triangle edge by
//   a fraction of a pixel. With 4x multisampling that flips at most one of the four samples of
//   an edge pixel: a change of a quarter of the local contrast, at most 255 / 4 ~ 64.
// - kMeanAbs = 0.5: such edge changes touch well under 1% of pixels; a real regression (wrong
//   colour, moved camera, missing overlay) moves the mean by several units.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include "render/colour_map.hpp"
#include "render/render_mesh.hpp"
#include "smpl/constants.hpp"

namespace cr = caliper::render;

namespace {

constexpr int kMaxAbs = 64;
constexpr double kMeanAbs = 0.5;

/// A deterministic figure-like test mesh: an ellipsoid torso and a sphere head, 1.7 m tall,
/// feet at y = 0, facing +Z. Independent of every other area's fixtures.
void add_ellipsoid(smpl::Vertices& v, smpl::Faces& f, const Eigen::Vector3d& centre,
                   const Eigen::Vector3d& radii, int rings, int segments) {
  const int base = static_cast<int>(v.rows());
  const int nv = rings * segments + 2;
  v.conservativeResize(base + nv, 3);
  const double pi = smpl::kPi;
  v.row(base) = centre + Eigen::Vector3d(0, radii.y(), 0);
  for (int r = 0; r < rings; ++r) {
    const double theta = pi * (r + 1) / (rings + 1);
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * pi * s / segments;
      v.row(base + 1 + r * segments + s) =
          centre + Eigen::Vector3d(radii.x() * std::sin(theta) * std::sin(phi),
                                   radii.y() * std::cos(theta),
                                   radii.z() * std::sin(theta) * std::cos(phi));
    }
  }
  v.row(base + nv - 1) = centre - Eigen::Vector3d(0, radii.y(), 0);
  std::vector<std::array<int, 3>> tris;
  tris.reserve(2 * static_cast<std::size_t>(rings) * static_cast<std::size_t>(segments));
  auto at = [&](int r, int s) { return base + 1 + r * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) tris.push_back({base, at(0, s), at(0, s + 1)});
  for (int r = 0; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      tris.push_back({at(r, s), at(r + 1, s), at(r + 1, s + 1)});
      tris.push_back({at(r, s), at(r + 1, s + 1), at(r, s + 1)});
    }
  }
  for (int s = 0; s < segments; ++s)
    tris.push_back({base + nv - 1, at(rings - 1, s + 1), at(rings - 1, s)});
  const int fb = static_cast<int>(f.rows());
  f.conservativeResize(fb + static_cast<int>(tris.size()), 3);
  for (size_t i = 0; i < tris.size(); ++i) {
    f.row(fb + static_cast<int>(i)) << tris[i][0], tris[i][1], tris[i][2];
  }
}

struct Figure {
  smpl::Vertices v{0, 3};
  smpl::Faces f{0, 3};
};

Figure figure() {
  Figure m;
  add_ellipsoid(m.v, m.f, {0, 0.75, 0}, {0.2, 0.75, 0.12}, 24, 32);
  add_ellipsoid(m.v, m.f, {0, 1.58, 0.01}, {0.09, 0.12, 0.1}, 12, 16);
  return m;
}

void check_golden(const cr::Image& img, const std::string& name) {
  const std::string path = std::string(CALIPER_GOLDEN_DIR) + "/" + name;
  const char* update = std::getenv("CALIPER_UPDATE_GOLDEN");
  if (update != nullptr && std::string(update) == "1") {
    cr::write_png(img, path);
    GTEST_SKIP() << "golden image rewritten: " << path;
  }
  const cr::Image golden = cr::read_png(path);
  const cr::ImageDifference d = cr::compare_images(img, golden);
  ASSERT_TRUE(d.same_size) << name << ": size " << img.width << "x" << img.height << " vs golden "
                           << golden.width << "x" << golden.height;
  if (d.max_abs > kMaxAbs || d.mean_abs > kMeanAbs) {
    cr::write_png(img, std::string(CALIPER_TEST_DATA_DIR) + "/actual_" + name);
  }
  EXPECT_LE(d.max_abs, kMaxAbs) << name << " (actual picture written to the test data folder)";
  EXPECT_LE(d.mean_abs, kMeanAbs) << name;
}

}  // namespace

TEST(Golden, FigureFront) {
  const Figure m = figure();
  cr::RenderOptions o;
  o.width = 160;
  o.height = 220;
  check_golden(cr::render_mesh_image(m.v, m.f, o), "figure_front.png");
}

TEST(Golden, FigureThreeQuarterWireframe) {
  const Figure m = figure();
  cr::RenderOptions o;
  o.width = 160;
  o.height = 220;
  o.width = 240;
  o.height = 300;
  o.view = "three_quarter";
  o.wireframe = true;
  check_golden(cr::render_mesh_image(m.v, m.f, o), "figure_three_quarter_wire.png");
}

TEST(Golden, HeatMapLegendLinesLandmarksLabels) {
  const Figure m = figure();
  cr::RenderOptions o;
  o.width = 420;
  o.height = 300;
  o.view = "front";
  // Heat map of the height above the floor, 0..1.7 m, with its legend.
  std::vector<float> values;
  values.reserve(static_cast<std::size_t>(m.v.rows()));
  for (int i = 0; i < m.v.rows(); ++i) values.push_back(static_cast<float>(m.v(i, 1)));
  o.vertex_colours = cr::colours_from_values(values, 0, 1.7f, cr::kColourMapHeat);
  o.legend.visible = true;
  o.legend.title = "height (m)";
  o.legend.max_value = 1.7f;
  o.legend.colour_map = cr::kColourMapHeat;
  cr::Line l;
  l.a = {-0.2f, 0.75f, 0.15f};
  l.b = {0.2f, 0.75f, 0.15f};
  l.colour = {0.1f, 0.2f, 0.8f, 1};
  o.lines.push_back(l);
  o.points.push_back({l.a, {0.9f, 0.1f, 0.1f, 1}, 8});
  o.points.push_back({l.b, {0.9f, 0.1f, 0.1f, 1}, 8});
  cr::Label label;
  label.text = "waist 40.0 cm";
  label.anchor = l.b;
  o.labels.push_back(label);
  check_golden(cr::render_mesh_image(m.v, m.f, o), "figure_heatmap_overlay.png");
}

// Measurement labels as the editor draws them: human names with units, anchored at the middle
// of their lines, keep_clear. Arm span and arm length have anchors a few pixels apart; the
// renderer moves the second label below the first instead of drawing one over the other.
TEST(Golden, MeasurementLabelsNeverOverlap) {
  const Figure m = figure();
  cr::RenderOptions o;
  o.width = 640;
  o.height = 300;
  o.view = "front";
  auto measurement = [&](const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                         const std::string& text) {
    cr::Line l;
    l.a = a;
    l.b = b;
    l.colour = {0.1f, 0.3f, 0.85f, 1};
    o.lines.push_back(l);
    o.points.push_back({l.a, {0.85f, 0.15f, 0.1f, 1}, 7});
    o.points.push_back({l.b, {0.85f, 0.15f, 0.1f, 1}, 7});
    cr::Label label;
    label.text = text;
    label.anchor = (a + b) / 2;
    label.colour = {0.05f, 0.1f, 0.4f, 1};
    label.scale = 1.6f;
    label.keep_clear = true;
    o.labels.push_back(label);
  };
  measurement({-0.9f, 1.32f, 0.15f}, {0.3f, 1.32f, 0.15f}, "Arm span (fingertips) 191.8 cm");
  measurement({-0.7f, 1.3f, 0.15f}, {-0.1f, 1.3f, 0.15f}, "Arm length (shoulder to wrist) 60.3 cm");
  cr::Label weight;
  weight.text = "Weight 90.3 kg";
  weight.screen = true;
  weight.anchor = {12, 34, 0};
  o.labels.push_back(weight);
  check_golden(cr::render_mesh_image(m.v, m.f, o), "figure_measurement_labels.png");
}
