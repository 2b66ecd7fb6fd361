// The live path's OpenGL graphics plugin (apps/vr/src/openxr_graphics_gl.hpp): the projection
// from an OpenXR field of view and the swapchain format. No runtime or display needed.
#include <gtest/gtest.h>

#include <cmath>

#include "openxr_graphics_gl.hpp"
#include "render/camera.hpp"

namespace caliper::vr {
namespace {

/// Float round-off of a 4x4 projection built from tangents.
constexpr float kMatrixTolerance = 1e-5f;

TEST(OpenXrGraphicsGl, ASymmetricFieldOfViewGivesTheUsualPerspective) {
  const float half_y = 0.8f, aspect = 0.9f;
  const float half_x = std::atan(aspect * std::tan(half_y));
  const XrFovf fov{-half_x, half_x, half_y, -half_y};
  const render::Mat4 p = gl_projection(fov, 0.05f, 50.0f);
  const render::Mat4 q = render::perspective(2.0f * half_y, aspect, 0.05f, 50.0f);
  EXPECT_LT((p - q).cwiseAbs().maxCoeff(), kMatrixTolerance) << p << "\n\n" << q;
}

TEST(OpenXrGraphicsGl, TheEdgesOfAnAsymmetricFieldOfViewMapToTheClipEdges) {
  const XrFovf fov{-0.9f, 0.6f, 0.7f, -0.85f};  // left, right, up, down (radians)
  const render::Mat4 p = gl_projection(fov, 0.1f, 20.0f);
  const auto ndc = [&](const Eigen::Vector3f& v) {
    const Eigen::Vector4f c = p * v.homogeneous();
    return Eigen::Vector3f(c.head<3>() / c.w());
  };
  const float z = -2.0f;  // in front of the eye (OpenXR looks along -Z)
  EXPECT_NEAR(ndc({std::tan(fov.angleLeft) * -z, 0, z}).x(), -1.0f, kMatrixTolerance);
  EXPECT_NEAR(ndc({std::tan(fov.angleRight) * -z, 0, z}).x(), 1.0f, kMatrixTolerance);
  EXPECT_NEAR(ndc({0, std::tan(fov.angleUp) * -z, z}).y(), 1.0f, kMatrixTolerance);
  EXPECT_NEAR(ndc({0, std::tan(fov.angleDown) * -z, z}).y(), -1.0f, kMatrixTolerance);
  EXPECT_NEAR(ndc({0, 0, -0.1f}).z(), -1.0f, kMatrixTolerance) << "near plane";
  EXPECT_NEAR(ndc({0, 0, -20.0f}).z(), 1.0f, 1e-4f) << "far plane";
}

TEST(OpenXrGraphicsGl, TheSwapchainFormatIsTheRuntimesFirstEightBitRgba) {
  const int64_t srgb = 0x8C43, rgba8 = 0x8058, rgba16f = 0x881A, rgb10a2 = 0x8059;
  EXPECT_EQ(gl_color_format({rgba16f, srgb, rgba8}), srgb);
  EXPECT_EQ(gl_color_format({rgb10a2, rgba8, srgb}), rgba8);
  EXPECT_EQ(gl_color_format({rgba16f, rgb10a2}), rgba16f) << "else the runtime's first";
  EXPECT_EQ(gl_color_format({}), 0);
}

TEST(OpenXrGraphicsGl, NothingOpensBeforeTheDevice) {
  // Creating the plugin opens no window (a missing runtime is reported first).
  const std::unique_ptr<OpenGlXlibGraphics> gl = OpenGlXlibGraphics::create(true);
  ASSERT_TRUE(gl);
  EXPECT_EQ(gl->instance_extensions(), std::vector<std::string>{"XR_KHR_opengl_enable"});
  EXPECT_EQ(gl->select_color_format({0x881A, 0x8058}), 0x8058);
}

}  // namespace
}  // namespace caliper::vr
