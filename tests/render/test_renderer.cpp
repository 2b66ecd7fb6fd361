// Renderer tests that need no reference picture: the OSMesa context and loader, the camera
// maths, and analytic properties of rendered images (background where nothing is drawn, the
// mesh colour where the mesh is, left-right symmetry of a symmetric mesh).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "render/camera.hpp"
#include "render/colour_map.hpp"
#include "render/context.hpp"
#include "render/render_mesh.hpp"
#include "render/renderer.hpp"
#include "render/text.hpp"
#include "smpl/io.hpp"

namespace cr = caliper::render;

namespace {

/// A closed box mesh [-w, w] x [0, h] x [-d, d] (12 triangles, outward winding).
smpl::Vertices box_vertices(double w, double h, double d) {
  smpl::Vertices v(8, 3);
  for (int i = 0; i < 8; ++i) {
    v(i, 0) = (i & 1) ? w : -w;
    v(i, 1) = (i & 2) ? h : 0;
    v(i, 2) = (i & 4) ? d : -d;
  }
  return v;
}
smpl::Faces box_faces() {
  smpl::Faces f(12, 3);
  f << 0, 2, 1, 1, 2, 3,  // z = -d
      4, 5, 6, 5, 7, 6,   // z = +d
      0, 1, 4, 1, 5, 4,   // y = 0
      2, 6, 3, 3, 6, 7,   // y = h
      0, 4, 2, 2, 4, 6,   // x = -w
      1, 3, 5, 3, 7, 5;   // x = +w
  return f;
}

int channel_distance(const std::uint8_t* p, const cr::Rgba& c) {
  const int r = std::abs(p[0] - static_cast<int>(std::lround(c.r * 255)));
  const int g = std::abs(p[1] - static_cast<int>(std::lround(c.g * 255)));
  const int b = std::abs(p[2] - static_cast<int>(std::lround(c.b * 255)));
  return std::max(r, std::max(g, b));
}

}  // namespace

TEST(OsMesa, CreatesCoreContextAndLoadsFunctions) {
  auto ctx = cr::make_osmesa_context(64, 32);
  EXPECT_EQ(ctx->width(), 64);
  EXPECT_EQ(ctx->height(), 32);
  GLint major = 0, minor = 0;
  ctx->gl().GetIntegerv(GL_MAJOR_VERSION, &major);
  ctx->gl().GetIntegerv(GL_MINOR_VERSION, &minor);
  EXPECT_GE(major * 10 + minor, 33);
  ASSERT_NE(ctx->gl().Clear, nullptr);
}

TEST(OsMesa, ClearColourIsReadBackExactly) {
  auto ctx = cr::make_osmesa_context(16, 8);
  const auto& gl = ctx->gl();
  gl.ClearColor(1.0f, 0.0f, 0.0f, 1.0f);
  gl.Clear(GL_COLOR_BUFFER_BIT);
  // Bottom half green via scissor: checks that read_pixels puts the top row first.
  gl.Enable(GL_SCISSOR_TEST);
  gl.Scissor(0, 0, 16, 4);
  gl.ClearColor(0.0f, 1.0f, 0.0f, 1.0f);
  gl.Clear(GL_COLOR_BUFFER_BIT);
  gl.Disable(GL_SCISSOR_TEST);
  const cr::Image img = ctx->read_pixels();
  ASSERT_EQ(img.width, 16);
  ASSERT_EQ(img.height, 8);
  EXPECT_EQ(img.pixel(0, 0)[0], 255);  // top row: red
  EXPECT_EQ(img.pixel(0, 0)[1], 0);
  EXPECT_EQ(img.pixel(5, 7)[0], 0);  // bottom row: green
  EXPECT_EQ(img.pixel(5, 7)[1], 255);
}

TEST(OsMesa, RejectsAbsurdSize) {
  EXPECT_THROW(cr::make_osmesa_context(0, 10), cr::RenderError);
}

TEST(Camera, LookAtMapsTargetToNegativeZAxis) {
  const cr::Mat4 v = cr::look_at(cr::Vec3(0, 1, 5), cr::Vec3(0, 1, 0), cr::Vec3(0, 1, 0));
  const Eigen::Vector4f t = v * Eigen::Vector4f(0, 1, 0, 1);
  EXPECT_NEAR(t.x(), 0, 1e-6);
  EXPECT_NEAR(t.y(), 0, 1e-6);
  EXPECT_NEAR(t.z(), -5, 1e-5);
}

TEST(Camera, FrameBoxKeepsEveryCornerInsideTheImage) {
  const cr::Vec3 lo(-0.3f, 0, -0.15f), hi(0.3f, 1.8f, 0.15f);
  for (float az : {0.0f, 35.0f, 90.0f, 180.0f}) {
    const cr::Camera c = cr::frame_box(lo, hi, az, 0.75f);
    const cr::Mat4 m = cr::projection_matrix(c, 0.75f) * cr::view_matrix(c);
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector4f p((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(),
                              (i & 4) ? hi.z() : lo.z(), 1);
      const Eigen::Vector4f q = m * p;
      EXPECT_LT(std::abs(q.x() / q.w()), 1.0f) << "azimuth " << az << " corner " << i;
      EXPECT_LT(std::abs(q.y() / q.w()), 1.0f) << "azimuth " << az << " corner " << i;
    }
  }
}

TEST(Camera, ParsesStandardViews) {
  EXPECT_EQ(cr::parse_standard_view("side"), cr::StandardView::Side);
  EXPECT_FLOAT_EQ(cr::view_azimuth_degrees(cr::parse_standard_view("three_quarter")), 35.0f);
  EXPECT_THROW(cr::parse_standard_view("top"), std::invalid_argument);
}

TEST(ColourMap, EndpointsAndClampingAndNaN) {
  const cr::Rgba lo = cr::colour_at(cr::kColourMapTraffic, 0),
                 hi = cr::colour_at(cr::kColourMapTraffic, 1);
  EXPECT_GT(lo.g, lo.r);  // green for plausible
  EXPECT_GT(hi.r, hi.g);  // red for implausible
  const cr::Rgba over = cr::colour_at(cr::kColourMapTraffic, 5);
  EXPECT_FLOAT_EQ(over.r, hi.r);
  const auto c = cr::colours_from_values({0.0f, std::nanf(""), 1.0f}, 0, 1, cr::kColourMapHeat);
  ASSERT_EQ(c.size(), 9u);
  EXPECT_FLOAT_EQ(c[3], 0.5f);  // NaN is grey
}

TEST(Text, WidthGrowsWithLengthAndScale) {
  EXPECT_GT(cr::text_width("170.0 cm", 2), cr::text_width("17", 2));
  EXPECT_FLOAT_EQ(cr::text_width("abc", 2), 2 * cr::text_width("abc", 1));
  std::vector<float> xy;
  cr::text_triangles("A", 0, 0, 1, xy);
  EXPECT_GT(xy.size(), 0u);
  EXPECT_EQ(xy.size() % 6, 0u);
}

TEST(Text, SeparateBoxesMovesOverlappingLabelsDownUntilClear) {
  const float gap = 2;
  auto overlap = [](const cr::TextBox& a, const cr::TextBox& b) {
    return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
  };
  // The editor's case: arm span and arm length anchored a few pixels apart.
  std::vector<cr::TextBox> b = {{100, 50, 400, 70}, {200, 55, 450, 75}, {500, 52, 600, 72}};
  cr::separate_boxes(b, gap);
  EXPECT_FLOAT_EQ(b[0].y0, 50);  // the first stays
  EXPECT_FLOAT_EQ(b[1].y0, 72);  // below the first, 2 px apart, same height
  EXPECT_FLOAT_EQ(b[1].y1, 92);
  EXPECT_FLOAT_EQ(b[1].x0, 200);  // never moved sideways
  EXPECT_FLOAT_EQ(b[2].y0, 52);   // overlapped nothing: stays
  // A fixed (screen) box stays and pushes a later one down; a chain of three clears each other.
  std::vector<cr::TextBox> c = {{0, 10, 100, 30}, {0, 0, 100, 20}, {0, 5, 100, 25}};
  c[1].fixed = true;
  cr::separate_boxes(c, gap);
  EXPECT_FLOAT_EQ(c[1].y0, 0);
  for (size_t i = 0; i < c.size(); ++i) {
    for (size_t j = i + 1; j < c.size(); ++j) EXPECT_FALSE(overlap(c[i], c[j])) << i << " " << j;
  }
  EXPECT_FLOAT_EQ(c[0].y0, 22);
  EXPECT_FLOAT_EQ(c[2].y0, 44);
}

TEST(Renderer, BackgroundOutsideAndMeshColourInsideABox) {
  cr::RenderOptions o;
  o.width = 120;
  o.height = 160;
  o.floor_grid = false;
  o.samples = 1;
  o.colour = {0.2f, 0.4f, 0.9f, 1};
  const cr::Image img = cr::render_mesh_image(box_vertices(0.2, 1.0, 0.1), box_faces(), o);
  ASSERT_EQ(img.width, 120);
  // Corners are background, exactly (nothing is drawn there).
  EXPECT_EQ(channel_distance(img.pixel(0, 0), o.background), 0);
  EXPECT_EQ(channel_distance(img.pixel(119, 159), o.background), 0);
  // The centre shows the front face: the blue base colour, shaded (blue channel dominant).
  const std::uint8_t* c = img.pixel(60, 80);
  EXPECT_GT(c[2], c[0]);
  EXPECT_GT(c[2], c[1]);
  EXPECT_GT(channel_distance(c, o.background), 40);
}

TEST(Renderer, SymmetricMeshGivesMirrorSymmetricFrontImage) {
  cr::RenderOptions o;
  o.width = 100;
  o.height = 140;
  o.floor_grid = false;
  o.samples = 1;
  const cr::Image img = cr::render_mesh_image(box_vertices(0.25, 1.0, 0.1), box_faces(), o);
  // Coverage (non-background pixels) must be mirror symmetric to within one pixel column of
  // rasterisation rounding per row.
  int asym = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width / 2; ++x) {
      const bool a = channel_distance(img.pixel(x, y), o.background) > 0;
      const bool b = channel_distance(img.pixel(img.width - 1 - x, y), o.background) > 0;
      asym += a != b;
    }
  }
  EXPECT_LE(asym, img.height);
}

TEST(Renderer, RejectsBadMeshes) {
  auto ctx = cr::make_osmesa_context(8, 8);
  cr::Renderer r(ctx->gl());
  cr::MeshData m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.indices = {0, 1, 3};  // index 3 out of range
  EXPECT_THROW(r.upload_mesh(m), cr::RenderError);
  m.indices = {0, 1};  // not a multiple of 3
  EXPECT_THROW(r.upload_mesh(m), cr::RenderError);
  m.indices = {0, 1, 2};
  m.colours = {1, 1};  // wrong colour count
  EXPECT_THROW(r.upload_mesh(m), cr::RenderError);
  m.colours.clear();
  const cr::MeshHandle h = r.upload_mesh(m);
  EXPECT_THROW(r.update_positions(h, {0, 0, 0}), cr::RenderError);
  EXPECT_THROW(r.update_positions(h + 100, m.positions), cr::RenderError);
}

TEST(Renderer, StereoViewsDrawIntoTheirOwnHalves) {
  cr::OffscreenRenderer off(80, 40, 1);
  cr::Scene scene;
  scene.grid.visible = false;
  scene.background = {0, 0, 0, 1};
  cr::Box box;
  box.half_extents = {0.5f, 0.5f, 0.5f};
  box.colour = {1, 1, 1, 1};
  scene.boxes.push_back(box);
  cr::View left, right;
  left.viewport = {0, 0, 40, 40};
  right.viewport = {40, 0, 40, 40};
  left.camera.eye = {0, 0, 3};
  left.camera.target = {0, 0, 0};
  right.camera = left.camera;
  right.camera.eye = {3, 0, 0};  // looks at the box from its side
  right.clear = true;
  const cr::Image img = off.render(scene, {left, right});
  EXPECT_GT(img.pixel(20, 20)[0], 30);  // box in the middle of the left eye
  EXPECT_GT(img.pixel(60, 20)[0], 30);  // and of the right eye
  EXPECT_EQ(img.pixel(1, 1)[0], 0);     // background in the corners
  EXPECT_EQ(img.pixel(78, 38)[0], 0);
}

namespace {

/// Fraction of pixels that differ from the background when the camera looks at a box mesh of
/// half size 1 around the origin from `eye`, with `model` as its transform.
double covered_fraction(const smpl::Faces& faces, const cr::Vec3& eye,
                        const cr::Mat4& model = cr::Mat4::Identity(), bool cull = true) {
  smpl::Vertices v = box_vertices(1.0, 2.0, 1.0);
  v.col(1).array() -= 1.0;
  cr::OffscreenRenderer off(48, 48, 1);
  off.renderer().set_cull_closed_meshes(cull);
  const cr::MeshHandle h = off.renderer().upload_mesh(cr::mesh_data(v, faces));
  cr::Scene scene;
  scene.grid.visible = false;
  scene.background = {0, 0, 0, 1};
  cr::MeshInstance inst;
  inst.mesh = h;
  inst.model = model;
  inst.colour = {1, 1, 1, 1};
  scene.meshes.push_back(inst);
  cr::View view;
  view.viewport = {0, 0, 48, 48};
  view.camera.eye = eye;
  view.camera.target = {0, 0, 0};
  view.camera.near_plane = 0.05f;
  const cr::Image img = off.render(scene, {view});
  int covered = 0;
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x)
      covered += channel_distance(img.pixel(x, y), {0, 0, 0, 1}) > 0;
  }
  return static_cast<double>(covered) / (img.width * img.height);
}

smpl::Faces reversed(const smpl::Faces& f) {
  smpl::Faces r = f;
  r.col(1).swap(r.col(2));
  return r;
}

}  // namespace

// Closed, consistently wound meshes (every avatar) are drawn with back faces culled: from
// inside an outward-wound box nothing is visible. Everything else stays two-sided, so the
// culling never removes a surface the viewer should see.
TEST(Renderer, CullsBackFacesOnlyOfClosedConsistentlyWoundMeshes) {
  const cr::Vec3 inside(0.2f, 0.1f, 0.3f), outside(0.5f, 0.8f, 4.0f);
  EXPECT_GT(covered_fraction(box_faces(), outside), 0.05);
  EXPECT_EQ(covered_fraction(box_faces(), inside), 0.0);
  EXPECT_EQ(covered_fraction(box_faces(), inside, cr::Mat4::Identity(), false), 1.0);  // off
  // Wound the other way round (negative signed volume, e.g. a file with flipped faces): the
  // renderer detects it, so the outside still shows, with the same coverage.
  EXPECT_NEAR(covered_fraction(reversed(box_faces()), outside),
              covered_fraction(box_faces(), outside), 0.02);
  EXPECT_EQ(covered_fraction(reversed(box_faces()), inside), 0.0);
  // Open (one face missing): two-sided, so the inside shows.
  const smpl::Faces open = box_faces().topRows(10);
  EXPECT_EQ(covered_fraction(open, inside), 1.0);
  // A mirroring transform reverses the winding on screen; the box must still show.
  cr::Mat4 mirror = cr::Mat4::Identity();
  mirror(0, 0) = -1;
  EXPECT_NEAR(covered_fraction(box_faces(), outside, mirror),
              covered_fraction(box_faces(), outside), 0.02);
  EXPECT_EQ(covered_fraction(box_faces(), inside, mirror), 0.0);
}

namespace {

/// The open female model's mean body, framed whole from the front in a w x h view (the editor's
/// view while a slider is dragged) or, with `close_up`, its head filling the view.
struct BodyScene {
  smpl::BodyModel model = smpl::load_model(CALIPER_SOURCE_ASSETS "/models/caliper-female.npz");
  cr::Scene scene;
  cr::View view;

  BodyScene(cr::Renderer& r, int w, int h, bool close_up = false) {
    scene.grid.visible = false;
    scene.background = {0, 0, 0, 1};
    cr::MeshInstance inst;
    inst.mesh = r.upload_mesh(cr::mesh_data(model.v_template, model.faces));
    inst.colour = {1, 1, 1, 1};
    scene.meshes.push_back(inst);
    view.viewport = {0, 0, w, h};
    const Eigen::Vector3f lo = model.v_template.colwise().minCoeff().cast<float>();
    const Eigen::Vector3f hi = model.v_template.colwise().maxCoeff().cast<float>();
    const Eigen::Vector3f head_lo(-0.12f, hi.y() - 0.25f, lo.z()), head_hi(0.12f, hi.y(), hi.z());
    view.camera = close_up ? cr::frame_box(head_lo, head_hi, 0, static_cast<float>(w) / h)
                           : cr::frame_box(lo, hi, 0, static_cast<float>(w) / h);
  }
};

/// Pixels not black: the body's coverage.
std::vector<bool> coverage(const cr::Image& img) {
  std::vector<bool> c(static_cast<size_t>(img.width) * static_cast<size_t>(img.height));
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      c[static_cast<size_t>(y) * static_cast<size_t>(img.width) + static_cast<size_t>(x)] =
          channel_distance(img.pixel(x, y), {0, 0, 0, 1}) > 0;
    }
  }
  return c;
}

}  // namespace

// Level of detail (the editor's while a slider is dragged): a whole body in view is drawn from a
// simplified index buffer, under half of the triangles, with its silhouette where the full
// mesh's is: every pixel whose coverage changes touches the full mesh's outline, and fewer
// change than half the outline's pixels. Close up: nearly the full mesh; wireframes and with it
// off: the full mesh.
TEST(Renderer, LevelOfDetailKeepsTheSilhouetteAndHalvesTheTrianglesOfAWholeBody) {
  const int w = 600, h = 1000;
  cr::OffscreenRenderer off(w, h, 1);
  cr::Renderer& r = off.renderer();
  BodyScene body(r, w, h);
  const size_t full = static_cast<size_t>(body.model.faces.rows());
  EXPECT_FALSE(r.level_of_detail());  // off by default
  const std::vector<bool> a = coverage(off.render(body.scene, {body.view}));
  EXPECT_EQ(r.triangles_drawn(), full);
  r.set_level_of_detail(true);
  const std::vector<bool> b = coverage(off.render(body.scene, {body.view}));
  EXPECT_LT(r.triangles_drawn(), full / 2);
  EXPECT_GT(r.triangles_drawn(), full / 10);
  size_t outline = 0, changed = 0, changed_off_outline = 0;
  const auto at = [&](int x, int y) {
    return a[static_cast<size_t>(std::clamp(y, 0, h - 1)) * static_cast<size_t>(w) +
             static_cast<size_t>(std::clamp(x, 0, w - 1))];
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      // On the outline: a pixel of the full mesh's picture whose 3 x 3 neighbourhood holds both.
      bool any_in = false, any_out = false;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) (at(x + dx, y + dy) ? any_in : any_out) = true;
      }
      const bool on_outline = any_in && any_out;
      outline += on_outline && at(x, y);
      const size_t i = static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x);
      if (a[i] != b[i]) {
        ++changed;
        changed_off_outline += !on_outline;
      }
    }
  }
  EXPECT_GT(outline, 1000u);
  EXPECT_EQ(changed_off_outline, 0u);
  EXPECT_LT(changed, outline / 2) << "of " << outline << " outline pixels";
  // The wireframe shows the real mesh, over the full mesh.
  body.scene.meshes[0].wireframe = true;
  off.render(body.scene, {body.view});
  EXPECT_EQ(r.triangles_drawn(), 2 * full);
  body.scene.meshes[0].wireframe = false;
  // Close up (the head fills the view, a pixel is 0.25 mm): at most the finest level (a fifth
  // of a millimetre of error, 4/5 of the triangles).
  BodyScene head(r, w, h, true);
  off.render(head.scene, {head.view});
  EXPECT_GT(r.triangles_drawn(), full * 3 / 4);
  // Small meshes get no levels.
  cr::Scene box_scene;
  cr::MeshInstance box;
  box.mesh = r.upload_mesh(cr::mesh_data(box_vertices(0.2, 0.2, 0.2), box_faces()));
  box_scene.meshes.push_back(box);
  off.render(box_scene, {body.view});
  EXPECT_EQ(r.triangles_drawn(), 12u);
}

// The shader helper shared by the renderer and the editor's ImGui backend reports the
// compiler's complaint and the program's name.
TEST(Renderer, LinkProgramNamesTheShaderThatFailsToCompile) {
  auto ctx = cr::make_osmesa_context(8, 8);
  const char* vs = "#version 330 core\nvoid main() { gl_Position = vec4(0.0); }\n";
  const char* fs = "#version 330 core\nout vec4 c;\nvoid main() { c = vec4(1.0); }\n";
  const GLuint p = cr::link_program(ctx->gl(), vs, fs, "tiny");
  EXPECT_NE(p, 0u);
  ctx->gl().DeleteProgram(p);
  try {
    cr::link_program(ctx->gl(), vs, "#version 330 core\nvoid main() { oops }\n", "broken");
    FAIL() << "a shader with a syntax error linked";
  } catch (const cr::RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("shader broken failed to compile"), std::string::npos)
        << e.what();
  }
}

// A vertex prelude (shaders::kUnlitVertex for the flat and overlay programs) is compiled in after
// the #version line; the compiler's line numbers still count the lines of the shader's own file.
TEST(Renderer, LinkProgramCompilesTheVertexPreludeAfterTheVersionLine) {
  auto ctx = cr::make_osmesa_context(8, 8);
  const char* prelude = "vec4 origin() { return vec4(0.0, 0.0, 0.0, 1.0); }\n";
  const char* vs = "#version 330 core\nvoid main() { gl_Position = origin(); }\n";
  const char* fs = "#version 330 core\nout vec4 c;\nvoid main() { c = vec4(1.0); }\n";
  const GLuint p = cr::link_program(ctx->gl(), vs, fs, "with_prelude", prelude);
  EXPECT_NE(p, 0u);
  ctx->gl().DeleteProgram(p);
  EXPECT_THROW(cr::link_program(ctx->gl(), vs, fs, "without_prelude"), cr::RenderError);
  try {
    cr::link_program(ctx->gl(), "#version 330 core\n// line 2\nvoid main() { oops }\n", fs,
                     "broken_line_3", prelude);
    FAIL() << "a shader with a syntax error linked";
  } catch (const cr::RenderError& e) {
    EXPECT_NE(std::string(e.what()).find("shader broken_line_3 failed to compile"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find(":3("), std::string::npos) << e.what();  // Mesa: 0:3(n)
  }
  EXPECT_THROW(cr::link_program(ctx->gl(), "#version 330 core", fs, "one_line", prelude),
               cr::RenderError);
}
