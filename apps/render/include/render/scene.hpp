/// \file scene.hpp
/// The plain description of what to draw: the renderer draws a const Scene snapshot for one or
/// more views (window, off-screen image, or each eye of a headset). World units are metres,
/// +Y up, the body faces +Z (the shared frame). Colours are linear RGBA in [0, 1].
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

namespace caliper::render {

using Vec3 = Eigen::Vector3f;
using Mat4 = Eigen::Matrix4f;

/// Linear RGBA colour, each channel in [0, 1].
struct Rgba {
  float r = 1, g = 1, b = 1, a = 1;
};

/// A triangle mesh on the CPU. Upload it with Renderer::upload_mesh() and refer to it by handle.
struct MeshData {
  std::vector<float> positions;        ///< 3V, xyz interleaved, metres
  std::vector<float> normals;          ///< 3V unit normals, or empty: computed (area-weighted)
  std::vector<float> colours;          ///< 3V per-vertex RGB in [0, 1], or empty
  std::vector<std::uint32_t> indices;  ///< 3F, counter-clockwise seen from outside
};

/// Handle of a mesh uploaded to the renderer; 0 is "none".
using MeshHandle = std::uint32_t;
/// Handle of a texture uploaded to the renderer; 0 is "none".
using TextureHandle = std::uint32_t;

/// One drawn instance of an uploaded mesh.
struct MeshInstance {
  MeshHandle mesh = 0;
  Mat4 model = Mat4::Identity();           ///< model-to-world transform
  Rgba colour{0.80f, 0.68f, 0.58f, 1.0f};  ///< base colour when per-vertex colours are off
  bool vertex_colours = false;             ///< use MeshData::colours (colour maps)
  bool wireframe = false;                  ///< overlay the triangle edges
  Rgba wireframe_colour{0.1f, 0.1f, 0.1f, 1.0f};
};

/// A straight segment in world space (measurement lines, axes).
struct Line {
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();
  Rgba colour;
  bool on_top = true;  ///< drawn without depth test, so that lines inside the body show
};

/// A round dot in world space (landmarks), size in pixels.
struct Point {
  Vec3 position = Vec3::Zero();
  Rgba colour;
  float size_px = 8.0f;
};

/// Text anchored at a world point (measurement values) or at a pixel position of the viewport.
struct Label {
  std::string text;            ///< printable ASCII; other bytes are drawn as '?'
  Vec3 anchor = Vec3::Zero();  ///< world position (when `screen` is false)
  bool screen = false;  ///< true: anchor.x(), anchor.y() are pixels from the viewport's top-left
  Rgba colour{0, 0, 0, 1};
  float scale = 2.0f;      ///< glyph scale: 1 = 7 px tall letters
  bool background = true;  ///< a translucent white box behind the text
  /// Moved down, when needed, so as not to cover any other label (earlier labels with
  /// keep_clear, and every label without it, which stays where it is): values beside
  /// measurement lines. Off for labels whose place is their meaning (VR floor-target numbers).
  bool keep_clear = false;
};

/// A solid box (controllers, markers): unit cube scaled by `half_extents` then `transform`.
struct Box {
  Mat4 transform = Mat4::Identity();
  Vec3 half_extents{0.02f, 0.02f, 0.08f};
  Rgba colour{0.2f, 0.2f, 0.25f, 1.0f};
};

/// A textured rectangle in world space (instruction panel, video frame): centre +- right +- up.
struct TexturedQuad {
  TextureHandle texture = 0;
  Vec3 centre = Vec3::Zero();
  Vec3 right{0.5f, 0, 0};  ///< half width vector
  Vec3 up{0, 0.5f, 0};     ///< half height vector
};

/// Floor grid in the plane y = height.
struct FloorGrid {
  bool visible = true;
  float height = 0.0f;   ///< metres
  float extent = 2.0f;   ///< half size, metres
  float spacing = 0.1f;  ///< metres between lines (every 10th line is darker)
  Rgba colour{0.55f, 0.55f, 0.58f, 1.0f};
};

/// Colour legend box for a per-vertex colour map (drawn in the viewport's top-right corner).
struct Legend {
  bool visible = false;
  std::string title;  ///< e.g. "difference (cm)"
  float min_value = 0, max_value = 1;
  int colour_map = 0;  ///< a ColourMap value (colour_map.hpp)
};

/// Everything to draw.
struct Scene {
  Rgba background{0.96f, 0.96f, 0.97f, 1.0f};
  std::vector<MeshInstance> meshes;
  std::vector<Line> lines;
  std::vector<Point> points;
  std::vector<Label> labels;
  std::vector<Box> boxes;
  std::vector<TexturedQuad> quads;
  FloorGrid grid;
  Legend legend;
  Vec3 light_direction{-0.3f, 0.6f, 0.75f};  ///< towards the light, world space
};

/// A pinhole (or orthographic) camera.
struct Camera {
  Vec3 eye{0, 1, 4};
  Vec3 target{0, 1, 0};
  Vec3 up{0, 1, 0};
  float fov_y_degrees = 30.0f;
  float near_plane = 0.05f, far_plane = 100.0f;
  bool orthographic = false;
  float ortho_half_height = 1.0f;  ///< metres, when orthographic
  /// Explicit matrices (VR eyes): when `use_matrices` is set, view and projection are used as is.
  bool use_matrices = false;
  Mat4 view = Mat4::Identity();
  Mat4 projection = Mat4::Identity();
};

/// A rectangle of the framebuffer in pixels, origin at the bottom-left (GL convention).
struct Viewport {
  int x = 0, y = 0, width = 0, height = 0;
};

/// One view of the scene: where and from where.
struct View {
  Viewport viewport;
  Camera camera;
  bool clear = true;  ///< clear this viewport to the scene background first
};

}  // namespace caliper::render
