/// \file openxr_graphics.hpp
/// The graphics-plugin interface of the live path (the shape of Khronos hello_xr): everything
/// the OpenXR program needs from a graphics API, so that another API or platform is one new
/// file implementing it. The program (openxr_program.hpp) creates the instance with the
/// plugin's extensions, the session with its binding and the swapchains in its format; the
/// plugin owns the context, the renderer and the per-eye render targets.
#pragma once

#include <openxr/openxr.h>

#include <cstdint>
#include <string>
#include <vector>

#include "render/renderer.hpp"
#include "render/scene.hpp"
#include "smpl/non_copyable.hpp"

namespace caliper::vr {

class XrGraphicsPlugin : smpl::NonCopyable {
 public:
  virtual ~XrGraphicsPlugin() = default;

  /// The instance extensions this API needs (e.g. XR_KHR_opengl_enable).
  virtual std::vector<std::string> instance_extensions() const = 0;
  /// Checks the runtime's requirements for this API on (instance, system) and creates the
  /// context and renderer. Throws std::runtime_error saying what is missing.
  virtual void initialize_device(XrInstance instance, XrSystemId system) = 0;
  /// The XrGraphicsBinding*KHR structure to chain into XrSessionCreateInfo (valid after
  /// initialize_device(), while the plugin lives).
  virtual const void* graphics_binding() const = 0;
  /// The colour format to create the swapchains with, from the runtime's list (in its order of
  /// preference).
  virtual int64_t select_color_format(const std::vector<int64_t>& runtime_formats) const = 0;
  /// Takes the images of eye `eye`'s swapchain (width x height pixels) and makes its render
  /// target.
  virtual void attach_swapchain(XrInstance instance, int eye, XrSwapchain swapchain, int width,
                                int height) = 0;
  /// Draws `scene` into image `image` of eye `eye`'s swapchain, seen from `view` (pose and
  /// field of view in the stage space).
  virtual void render_view(int eye, std::uint32_t image, const XrView& view,
                           const render::Scene& scene) = 0;
  /// Frees the render targets (before the program destroys the swapchains and the session).
  virtual void release_targets() = 0;
  /// The renderer the app uploads its meshes and textures to (valid after initialize_device()).
  virtual render::Renderer& renderer() = 0;
  /// Processes the desktop window's events; false when the user closed the window.
  virtual bool poll_window() = 0;
};

}  // namespace caliper::vr
