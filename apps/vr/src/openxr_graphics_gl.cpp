// The OpenGL/Xlib graphics plugin of the live path (see openxr_graphics_gl.hpp).
#include "openxr_graphics_gl.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#define GLFW_EXPOSE_NATIVE_X11
#define GLFW_EXPOSE_NATIVE_GLX
#include <GLFW/glfw3native.h>

#define XR_USE_PLATFORM_XLIB
#define XR_USE_GRAPHICS_API_OPENGL
#include <GL/glx.h>
#include <openxr/openxr_platform.h>

#include <array>
#include <cmath>
#include <stdexcept>

#include "openxr_check.hpp"

namespace caliper::vr {

render::Mat4 gl_projection(const XrFovf& fov, float near_plane, float far_plane) {
  const float n = near_plane, f = far_plane;
  const float l = std::tan(fov.angleLeft), r = std::tan(fov.angleRight);
  const float d = std::tan(fov.angleDown), u = std::tan(fov.angleUp);
  render::Mat4 p = render::Mat4::Zero();
  p(0, 0) = 2.0f / (r - l);
  p(0, 2) = (r + l) / (r - l);
  p(1, 1) = 2.0f / (u - d);
  p(1, 2) = (u + d) / (u - d);
  p(2, 2) = -(f + n) / (f - n);
  p(2, 3) = -2.0f * f * n / (f - n);
  p(3, 2) = -1.0f;
  return p;
}

int64_t gl_color_format(const std::vector<int64_t>& runtime_formats) {
  for (int64_t f : runtime_formats)
    if (f == 0x8C43 /* GL_SRGB8_ALPHA8 */ || f == 0x8058 /* GL_RGBA8 */) return f;
  return runtime_formats.empty() ? 0 : runtime_formats[0];
}

namespace {

/// One eye's render target: the swapchain's images and a framebuffer with a depth buffer.
struct EyeTarget {
  int width = 0, height = 0;
  std::vector<XrSwapchainImageOpenGLKHR> images;
  GLuint depth = 0;
  GLuint fbo = 0;
};

class OpenGlXlibGraphicsImpl final : public OpenGlXlibGraphics {
 public:
  explicit OpenGlXlibGraphicsImpl(bool operator_window) : operator_window_(operator_window) {}
  ~OpenGlXlibGraphicsImpl() override {
    release_targets();
    renderer_.reset();
    window_.reset();
  }

  std::vector<std::string> instance_extensions() const override {
    return {XR_KHR_OPENGL_ENABLE_EXTENSION_NAME};
  }
  void initialize_device(XrInstance instance, XrSystemId system) override;
  const void* graphics_binding() const override { return &binding_; }
  int64_t select_color_format(const std::vector<int64_t>& formats) const override {
    return gl_color_format(formats);
  }
  void attach_swapchain(XrInstance instance, int eye, XrSwapchain swapchain, int width,
                        int height) override;
  void render_view(int eye, std::uint32_t image, const XrView& view,
                   const render::Scene& scene) override;
  void release_targets() override;
  render::Renderer& renderer() override { return *renderer_; }
  bool poll_window() override {
    glfwPollEvents();
    return !window_->should_close();
  }
  render::GlfwWindowContext& window() override { return *window_; }

 private:
  void bind_context();

  bool operator_window_;
  std::unique_ptr<render::GlfwWindowContext> window_;
  std::unique_ptr<render::Renderer> renderer_;
  XrGraphicsBindingOpenGLXlibKHR binding_ =
      xr_struct<XrGraphicsBindingOpenGLXlibKHR>(XR_TYPE_GRAPHICS_BINDING_OPENGL_XLIB_KHR);
  std::array<EyeTarget, 2> eyes_;
};

void OpenGlXlibGraphicsImpl::initialize_device(XrInstance instance, XrSystemId system) {
  PFN_xrGetOpenGLGraphicsRequirementsKHR get_requirements = nullptr;
  CALIPER_XR(instance,
             xrGetInstanceProcAddr(instance, "xrGetOpenGLGraphicsRequirementsKHR",
                                   reinterpret_cast<PFN_xrVoidFunction*>(&get_requirements)));
  XrGraphicsRequirementsOpenGLKHR req =
      xr_struct<XrGraphicsRequirementsOpenGLKHR>(XR_TYPE_GRAPHICS_REQUIREMENTS_OPENGL_KHR);
  CALIPER_XR(instance, get_requirements(instance, system, &req));
  if (req.minApiVersionSupported > XR_MAKE_VERSION(3, 3, 0))
    throw std::runtime_error("the OpenXR runtime needs a newer OpenGL than 3.3");
  // The GL context (and the operator's mirror window when asked for) comes from GLFW.
  window_ = std::make_unique<render::GlfwWindowContext>(960, 540, "The Virtual Caliper - operator",
                                                        operator_window_);
  window_->make_current();
  renderer_ = std::make_unique<render::Renderer>(window_->gl());
  bind_context();
}

void OpenGlXlibGraphicsImpl::bind_context() {
  GLFWwindow* w = window_->window();
  Display* display = glfwGetX11Display();
  int fb_id = 0;
  glXQueryContext(display, glfwGetGLXContext(w), GLX_FBCONFIG_ID, &fb_id);
  const int attribs[] = {GLX_FBCONFIG_ID, fb_id, None};
  int n = 0;
  GLXFBConfig* configs = glXChooseFBConfig(display, DefaultScreen(display), attribs, &n);
  if (!configs || n < 1)
    throw std::runtime_error("cannot find the GLX frame buffer configuration of the window");
  XVisualInfo* vi = glXGetVisualFromFBConfig(display, configs[0]);
  binding_.xDisplay = display;
  binding_.visualid = vi ? static_cast<uint32_t>(vi->visualid) : 0;
  binding_.glxFBConfig = configs[0];
  binding_.glxDrawable = glfwGetGLXWindow(w);
  binding_.glxContext = glfwGetGLXContext(w);
  if (vi) XFree(vi);
  XFree(configs);  // the GLXFBConfig handle itself stays valid
}

void OpenGlXlibGraphicsImpl::attach_swapchain(XrInstance instance, int e, XrSwapchain swapchain,
                                              int width, int height) {
  EyeTarget& eye = eyes_[static_cast<size_t>(e)];
  eye.width = width;
  eye.height = height;
  uint32_t ni = 0;
  CALIPER_XR(instance, xrEnumerateSwapchainImages(swapchain, 0, &ni, nullptr));
  eye.images.assign(ni, xr_struct<XrSwapchainImageOpenGLKHR>(XR_TYPE_SWAPCHAIN_IMAGE_OPENGL_KHR));
  CALIPER_XR(instance, xrEnumerateSwapchainImages(
                           swapchain, ni, &ni,
                           reinterpret_cast<XrSwapchainImageBaseHeader*>(eye.images.data())));
  const render::GlFunctions& gl = window_->gl();
  gl.GenFramebuffers(1, &eye.fbo);
  gl.GenRenderbuffers(1, &eye.depth);
  gl.BindRenderbuffer(GL_RENDERBUFFER, eye.depth);
  gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, eye.width, eye.height);
  gl.BindRenderbuffer(GL_RENDERBUFFER, 0);
}

void OpenGlXlibGraphicsImpl::render_view(int e, std::uint32_t image, const XrView& v,
                                         const render::Scene& scene) {
  EyeTarget& eye = eyes_[static_cast<size_t>(e)];
  const render::GlFunctions& gl = window_->gl();
  gl.BindFramebuffer(GL_FRAMEBUFFER, eye.fbo);
  gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
                          eye.images[image].image, 0);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER,
                             eye.depth);
  render::View view;
  view.viewport = {0, 0, eye.width, eye.height};
  view.camera.use_matrices = true;
  const Eigen::Quaternionf q(v.pose.orientation.w, v.pose.orientation.x, v.pose.orientation.y,
                             v.pose.orientation.z);
  render::Mat4 pose = render::Mat4::Identity();
  pose.block<3, 3>(0, 0) = q.normalized().toRotationMatrix();
  pose.block<3, 1>(0, 3) = render::Vec3(v.pose.position.x, v.pose.position.y, v.pose.position.z);
  view.camera.view = pose.inverse();
  view.camera.projection = gl_projection(v.fov, 0.05f, 50.0f);
  renderer_->draw(scene, view);
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
}

void OpenGlXlibGraphicsImpl::release_targets() {
  if (!window_) return;
  window_->make_current();
  const render::GlFunctions& gl = window_->gl();
  for (EyeTarget& e : eyes_) {
    if (e.fbo) gl.DeleteFramebuffers(1, &e.fbo);
    if (e.depth) gl.DeleteRenderbuffers(1, &e.depth);
    e.fbo = e.depth = 0;
  }
}

}  // namespace

std::unique_ptr<OpenGlXlibGraphics> OpenGlXlibGraphics::create(bool operator_window) {
  return std::make_unique<OpenGlXlibGraphicsImpl>(operator_window);
}

}  // namespace caliper::vr
