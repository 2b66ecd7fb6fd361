// The live OpenXR path (see openxr_system.hpp). Follows the OpenXR 1.0 specification's frame
// loop: poll events -> xrWaitFrame -> xrBeginFrame -> xrSyncActions / xrLocateViews ->
// render each eye into its swapchain image -> xrEndFrame with one projection layer.
//
// Sections: check macro | instance and system | session and spaces | actions | swapchains |
// frame loop | operator window | run_openxr.
#include "openxr_system.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#define GLFW_EXPOSE_NATIVE_X11
#define GLFW_EXPOSE_NATIVE_GLX
#include <GLFW/glfw3native.h>

#define XR_USE_PLATFORM_XLIB
#define XR_USE_GRAPHICS_API_OPENGL
#include <GL/glx.h>
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <array>
#include <cstring>
#include <iostream>
#include <sstream>

#include "controller_config.hpp"
#include "operator_window.hpp"
#include "pivot.hpp"
#include "render/glfw_context.hpp"
#include "render/renderer.hpp"

namespace caliper::vr {
namespace {

// ---------------------------------------------------------------------------------------------
// Check macro: every OpenXR call is wrapped once, carrying the expression and file:line.

std::string xr_result_name(XrInstance instance, XrResult r) {
  char buf[XR_MAX_RESULT_STRING_SIZE] = {};
  if (instance != XR_NULL_HANDLE && xrResultToString(instance, r, buf) == XR_SUCCESS) return buf;
  return "XrResult " + std::to_string(static_cast<int>(r));
}

void xr_check(XrInstance instance, XrResult r, const char* expr, const char* file, int line) {
  if (XR_SUCCEEDED(r)) return;
  if (r == XR_ERROR_SESSION_LOST || r == XR_ERROR_INSTANCE_LOST)
    throw PoseSourceLost("the OpenXR runtime lost the " +
                         std::string(r == XR_ERROR_SESSION_LOST ? "session" : "instance") + " (" +
                         xr_result_name(instance, r) + " from " + expr + ")");
  std::ostringstream s;
  s << "OpenXR call failed: " << expr << " returned " << xr_result_name(instance, r) << " (" << file
    << ":" << line << ")";
  throw std::runtime_error(s.str());
}

#define CALIPER_XR(instance, expr) \
  ::caliper::vr::xr_check((instance), (expr), #expr, __FILE__, __LINE__)

/// A zero-initialised OpenXR structure with its type set.
template <typename T>
T xr_struct(XrStructureType type) {
  T v{};
  v.type = type;
  return v;
}

bool is_no_runtime(XrResult r) {
  return r == XR_ERROR_RUNTIME_UNAVAILABLE || r == XR_ERROR_RUNTIME_FAILURE ||
         r == XR_ERROR_INSTANCE_LOST || r == XR_ERROR_FILE_ACCESS_ERROR ||
         r == XR_ERROR_FILE_CONTENTS_INVALID;
}

// ---------------------------------------------------------------------------------------------
// Instance and system

struct Hand {
  XrPath path = XR_NULL_PATH;
  XrSpace grip_space = XR_NULL_HANDLE;
};

struct EyeTarget {
  XrSwapchain swapchain = XR_NULL_HANDLE;
  int width = 0, height = 0;
  std::vector<XrSwapchainImageOpenGLKHR> images;
  GLuint depth = 0;
  GLuint fbo = 0;
};

class OpenXrSystem final : public PoseSource {
 public:
  explicit OpenXrSystem(bool operator_window);
  ~OpenXrSystem() override;

  /// Polls events and, while the session runs, waits for and begins the next frame. Returns
  /// std::nullopt when the runtime ends the session.
  std::optional<PoseFrame> next_frame() override;
  std::string interaction_profile() const override { return profile_; }
  /// The runtime's display rate (1 / predictedDisplayPeriod of the last frame).
  double frame_rate() const override {
    return frame_state_.predictedDisplayPeriod > 0
               ? 1e9 / static_cast<double>(frame_state_.predictedDisplayPeriod)
               : 0.0;
  }
  void haptic_pulse(Tip hand, double amplitude, double seconds) override;
  std::string role() const override { return ""; }

  /// Renders the frame begun by next_frame() and ends it.
  void submit(const render::Scene& scene);
  render::GlfwWindowContext& window() { return *window_; }
  render::Renderer& renderer() { return *renderer_; }
  /// The latest views' poses and fields of view (valid after next_frame()).
  bool should_render() const { return frame_state_.shouldRender == XR_TRUE; }

 private:
  void create_instance();
  void create_session();
  void create_actions();
  void create_swapchains();
  bool poll_events();  ///< false when the app must quit
  void update_profile();

  XrInstance instance_ = XR_NULL_HANDLE;
  XrSystemId system_ = XR_NULL_SYSTEM_ID;
  XrSession session_ = XR_NULL_HANDLE;
  XrSpace stage_ = XR_NULL_HANDLE;
  XrSpace view_space_ = XR_NULL_HANDLE;
  XrActionSet action_set_ = XR_NULL_HANDLE;
  XrAction trigger_ = XR_NULL_HANDLE, menu_ = XR_NULL_HANDLE, squeeze_ = XR_NULL_HANDLE;
  XrAction grip_pose_ = XR_NULL_HANDLE, haptic_ = XR_NULL_HANDLE;
  std::array<Hand, 2> hands_;
  std::array<EyeTarget, 2> eyes_;
  std::array<XrView, 2> views_{};
  XrFrameState frame_state_ = xr_struct<XrFrameState>(XR_TYPE_FRAME_STATE);
  XrSessionState state_ = XR_SESSION_STATE_UNKNOWN;
  bool running_ = false;
  bool frame_begun_ = false;
  double start_time_ = -1.0;
  std::string profile_;  ///< "" until the runtime reports the bound controllers
  std::unique_ptr<render::GlfwWindowContext> window_;
  std::unique_ptr<render::Renderer> renderer_;
};

OpenXrSystem::OpenXrSystem(bool operator_window) {
  create_instance();
  // The GL context (and the operator's mirror window when asked for) comes from GLFW.
  window_ = std::make_unique<render::GlfwWindowContext>(960, 540, "The Virtual Caliper - operator",
                                                        operator_window);
  window_->make_current();
  renderer_ = std::make_unique<render::Renderer>(window_->gl());
  create_session();
  create_actions();
  create_swapchains();
}

void OpenXrSystem::create_instance() {
  uint32_t count = 0;
  const XrResult r = xrEnumerateInstanceExtensionProperties(nullptr, 0, &count, nullptr);
  if (is_no_runtime(r)) throw NoRuntimeError(kNoRuntimeMessage);
  CALIPER_XR(XR_NULL_HANDLE, r);
  std::vector<XrExtensionProperties> ext(
      count, xr_struct<XrExtensionProperties>(XR_TYPE_EXTENSION_PROPERTIES));
  CALIPER_XR(XR_NULL_HANDLE,
             xrEnumerateInstanceExtensionProperties(nullptr, count, &count, ext.data()));
  bool has_gl = false;
  for (const XrExtensionProperties& e : ext)
    has_gl = has_gl || std::strcmp(e.extensionName, XR_KHR_OPENGL_ENABLE_EXTENSION_NAME) == 0;
  if (!has_gl)
    throw std::runtime_error(
        "the OpenXR runtime does not offer OpenGL (XR_KHR_opengl_enable); use a runtime that "
        "does (SteamVR, Monado)");
  const char* extensions[] = {XR_KHR_OPENGL_ENABLE_EXTENSION_NAME};
  XrInstanceCreateInfo ci = xr_struct<XrInstanceCreateInfo>(XR_TYPE_INSTANCE_CREATE_INFO);
  std::strncpy(ci.applicationInfo.applicationName, "The Virtual Caliper",
               XR_MAX_APPLICATION_NAME_SIZE - 1);
  ci.applicationInfo.applicationVersion = 1;
  std::strncpy(ci.applicationInfo.engineName, "caliper", XR_MAX_ENGINE_NAME_SIZE - 1);
  ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
  ci.enabledExtensionCount = 1;
  ci.enabledExtensionNames = extensions;
  const XrResult rc = xrCreateInstance(&ci, &instance_);
  if (is_no_runtime(rc)) throw NoRuntimeError(kNoRuntimeMessage);
  CALIPER_XR(XR_NULL_HANDLE, rc);
  XrSystemGetInfo si = xr_struct<XrSystemGetInfo>(XR_TYPE_SYSTEM_GET_INFO);
  si.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  const XrResult rs = xrGetSystem(instance_, &si, &system_);
  if (rs == XR_ERROR_FORM_FACTOR_UNAVAILABLE)
    throw std::runtime_error(
        "the OpenXR runtime is running but no headset is connected: connect and switch on the "
        "headset, then start caliper-vr again");
  CALIPER_XR(instance_, rs);
}

// ---------------------------------------------------------------------------------------------
// Session and spaces

void OpenXrSystem::create_session() {
  PFN_xrGetOpenGLGraphicsRequirementsKHR get_requirements = nullptr;
  CALIPER_XR(instance_,
             xrGetInstanceProcAddr(instance_, "xrGetOpenGLGraphicsRequirementsKHR",
                                   reinterpret_cast<PFN_xrVoidFunction*>(&get_requirements)));
  XrGraphicsRequirementsOpenGLKHR req =
      xr_struct<XrGraphicsRequirementsOpenGLKHR>(XR_TYPE_GRAPHICS_REQUIREMENTS_OPENGL_KHR);
  CALIPER_XR(instance_, get_requirements(instance_, system_, &req));
  if (req.minApiVersionSupported > XR_MAKE_VERSION(3, 3, 0))
    throw std::runtime_error("the OpenXR runtime needs a newer OpenGL than 3.3");

  GLFWwindow* w = window_->window();
  Display* display = glfwGetX11Display();
  GLXContext context = glfwGetGLXContext(w);
  GLXWindow drawable = glfwGetGLXWindow(w);
  int fb_id = 0;
  glXQueryContext(display, context, GLX_FBCONFIG_ID, &fb_id);
  const int attribs[] = {GLX_FBCONFIG_ID, fb_id, None};
  int n = 0;
  GLXFBConfig* configs = glXChooseFBConfig(display, DefaultScreen(display), attribs, &n);
  if (!configs || n < 1)
    throw std::runtime_error("cannot find the GLX frame buffer configuration of the window");
  XVisualInfo* vi = glXGetVisualFromFBConfig(display, configs[0]);
  XrGraphicsBindingOpenGLXlibKHR binding =
      xr_struct<XrGraphicsBindingOpenGLXlibKHR>(XR_TYPE_GRAPHICS_BINDING_OPENGL_XLIB_KHR);
  binding.xDisplay = display;
  binding.visualid = vi ? static_cast<uint32_t>(vi->visualid) : 0;
  binding.glxFBConfig = configs[0];
  binding.glxDrawable = drawable;
  binding.glxContext = context;
  if (vi) XFree(vi);
  XrSessionCreateInfo ci = xr_struct<XrSessionCreateInfo>(XR_TYPE_SESSION_CREATE_INFO);
  ci.next = &binding;
  ci.systemId = system_;
  CALIPER_XR(instance_, xrCreateSession(instance_, &ci, &session_));
  XFree(configs);

  XrReferenceSpaceCreateInfo rs =
      xr_struct<XrReferenceSpaceCreateInfo>(XR_TYPE_REFERENCE_SPACE_CREATE_INFO);
  rs.poseInReferenceSpace.orientation.w = 1.0f;
  rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_STAGE;
  if (XR_FAILED(xrCreateReferenceSpace(session_, &rs, &stage_))) {
    // Not every runtime knows the floor; the floor calibration makes heights independent of it.
    rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
    CALIPER_XR(instance_, xrCreateReferenceSpace(session_, &rs, &stage_));
  }
  rs.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_VIEW;
  CALIPER_XR(instance_, xrCreateReferenceSpace(session_, &rs, &view_space_));
}

// ---------------------------------------------------------------------------------------------
// Actions

void OpenXrSystem::create_actions() {
  XrActionSetCreateInfo asi = xr_struct<XrActionSetCreateInfo>(XR_TYPE_ACTION_SET_CREATE_INFO);
  std::strcpy(asi.actionSetName, "measuring");
  std::strcpy(asi.localizedActionSetName, "Measuring");
  CALIPER_XR(instance_, xrCreateActionSet(instance_, &asi, &action_set_));
  CALIPER_XR(instance_, xrStringToPath(instance_, "/user/hand/left", &hands_[0].path));
  CALIPER_XR(instance_, xrStringToPath(instance_, "/user/hand/right", &hands_[1].path));
  const XrPath subpaths[2] = {hands_[0].path, hands_[1].path};
  const auto make = [&](XrAction& a, XrActionType type, const char* name, const char* label) {
    XrActionCreateInfo ai = xr_struct<XrActionCreateInfo>(XR_TYPE_ACTION_CREATE_INFO);
    ai.actionType = type;
    std::strcpy(ai.actionName, name);
    std::strcpy(ai.localizedActionName, label);
    ai.countSubactionPaths = 2;
    ai.subactionPaths = subpaths;
    CALIPER_XR(instance_, xrCreateAction(action_set_, &ai, &a));
  };
  make(trigger_, XR_ACTION_TYPE_FLOAT_INPUT, "take_sample", "Take a sample (hold)");
  make(menu_, XR_ACTION_TYPE_BOOLEAN_INPUT, "menu", "Menu");
  make(squeeze_, XR_ACTION_TYPE_BOOLEAN_INPUT, "squeeze", "Squeeze");
  make(grip_pose_, XR_ACTION_TYPE_POSE_INPUT, "grip_pose", "Controller pose");
  make(haptic_, XR_ACTION_TYPE_VIBRATION_OUTPUT, "confirm_haptic", "Confirmation vibration");

  const auto path = [&](const std::string& s) {
    XrPath p = XR_NULL_PATH;
    CALIPER_XR(instance_, xrStringToPath(instance_, s.c_str(), &p));
    return p;
  };
  struct Binding {
    XrAction action;
    const char* input;  // after /user/hand/<side>
    bool left = true, right = true;
  };
  const auto suggest = [&](const char* profile, const std::vector<Binding>& list) {
    std::vector<XrActionSuggestedBinding> b;
    for (const Binding& x : list)
      for (int side = 0; side < 2; ++side) {
        if ((side == 0 && !x.left) || (side == 1 && !x.right)) continue;
        b.push_back(
            {x.action,
             path(std::string(side == 0 ? "/user/hand/left" : "/user/hand/right") + x.input)});
      }
    XrInteractionProfileSuggestedBinding sb = xr_struct<XrInteractionProfileSuggestedBinding>(
        XR_TYPE_INTERACTION_PROFILE_SUGGESTED_BINDING);
    sb.interactionProfile = path(profile);
    sb.suggestedBindings = b.data();
    sb.countSuggestedBindings = static_cast<uint32_t>(b.size());
    CALIPER_XR(instance_, xrSuggestInteractionProfileBindings(instance_, &sb));
  };
  suggest(kProfiles[0], {{trigger_, "/input/trigger/value"},
                         {menu_, "/input/menu/click"},
                         {squeeze_, "/input/squeeze/click"},
                         {grip_pose_, "/input/grip/pose"},
                         {haptic_, "/output/haptic"}});
  suggest(kProfiles[1], {{trigger_, "/input/trigger/value"},
                         {menu_, "/input/b/click"},
                         {squeeze_, "/input/squeeze/value"},
                         {grip_pose_, "/input/grip/pose"},
                         {haptic_, "/output/haptic"}});
  suggest(kProfiles[2], {{trigger_, "/input/trigger/value"},
                         {menu_, "/input/menu/click", true, false},
                         {squeeze_, "/input/squeeze/value"},
                         {grip_pose_, "/input/grip/pose"},
                         {haptic_, "/output/haptic"}});
  suggest(kProfiles[3], {{trigger_, "/input/select/click"},
                         {menu_, "/input/menu/click"},
                         {grip_pose_, "/input/grip/pose"},
                         {haptic_, "/output/haptic"}});
  for (Hand& h : hands_) {
    XrActionSpaceCreateInfo sci =
        xr_struct<XrActionSpaceCreateInfo>(XR_TYPE_ACTION_SPACE_CREATE_INFO);
    sci.action = grip_pose_;
    sci.subactionPath = h.path;
    sci.poseInActionSpace.orientation.w = 1.0f;
    CALIPER_XR(instance_, xrCreateActionSpace(session_, &sci, &h.grip_space));
  }
  XrSessionActionSetsAttachInfo at =
      xr_struct<XrSessionActionSetsAttachInfo>(XR_TYPE_SESSION_ACTION_SETS_ATTACH_INFO);
  at.countActionSets = 1;
  at.actionSets = &action_set_;
  CALIPER_XR(instance_, xrAttachSessionActionSets(session_, &at));
}

// ---------------------------------------------------------------------------------------------
// Swapchains

void OpenXrSystem::create_swapchains() {
  uint32_t n = 0;
  CALIPER_XR(instance_,
             xrEnumerateViewConfigurationViews(
                 instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, 0, &n, nullptr));
  std::vector<XrViewConfigurationView> cfg(
      n, xr_struct<XrViewConfigurationView>(XR_TYPE_VIEW_CONFIGURATION_VIEW));
  CALIPER_XR(instance_,
             xrEnumerateViewConfigurationViews(
                 instance_, system_, XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO, n, &n, cfg.data()));
  if (n != 2) throw std::runtime_error("the headset does not offer a stereo view configuration");
  uint32_t nf = 0;
  CALIPER_XR(instance_, xrEnumerateSwapchainFormats(session_, 0, &nf, nullptr));
  std::vector<int64_t> formats(nf);
  CALIPER_XR(instance_, xrEnumerateSwapchainFormats(session_, nf, &nf, formats.data()));
  int64_t format = formats.empty() ? 0 : formats[0];
  for (int64_t f : formats)
    if (f == 0x8C43 /* GL_SRGB8_ALPHA8 */ || f == 0x8058 /* GL_RGBA8 */) {
      format = f;
      break;
    }
  const render::GlFunctions& gl = window_->gl();
  for (int e = 0; e < 2; ++e) {
    EyeTarget& eye = eyes_[static_cast<size_t>(e)];
    eye.width = static_cast<int>(cfg[static_cast<size_t>(e)].recommendedImageRectWidth);
    eye.height = static_cast<int>(cfg[static_cast<size_t>(e)].recommendedImageRectHeight);
    XrSwapchainCreateInfo sc = xr_struct<XrSwapchainCreateInfo>(XR_TYPE_SWAPCHAIN_CREATE_INFO);
    sc.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_SAMPLED_BIT;
    sc.format = format;
    sc.sampleCount = 1;
    sc.width = static_cast<uint32_t>(eye.width);
    sc.height = static_cast<uint32_t>(eye.height);
    sc.faceCount = 1;
    sc.arraySize = 1;
    sc.mipCount = 1;
    CALIPER_XR(instance_, xrCreateSwapchain(session_, &sc, &eye.swapchain));
    uint32_t ni = 0;
    CALIPER_XR(instance_, xrEnumerateSwapchainImages(eye.swapchain, 0, &ni, nullptr));
    eye.images.assign(ni, xr_struct<XrSwapchainImageOpenGLKHR>(XR_TYPE_SWAPCHAIN_IMAGE_OPENGL_KHR));
    CALIPER_XR(instance_, xrEnumerateSwapchainImages(
                              eye.swapchain, ni, &ni,
                              reinterpret_cast<XrSwapchainImageBaseHeader*>(eye.images.data())));
    gl.GenFramebuffers(1, &eye.fbo);
    gl.GenRenderbuffers(1, &eye.depth);
    gl.BindRenderbuffer(GL_RENDERBUFFER, eye.depth);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, eye.width, eye.height);
    gl.BindRenderbuffer(GL_RENDERBUFFER, 0);
  }
}

OpenXrSystem::~OpenXrSystem() {
  if (window_) {
    window_->make_current();
    const render::GlFunctions& gl = window_->gl();
    for (EyeTarget& e : eyes_) {
      if (e.fbo) gl.DeleteFramebuffers(1, &e.fbo);
      if (e.depth) gl.DeleteRenderbuffers(1, &e.depth);
    }
  }
  for (EyeTarget& e : eyes_)
    if (e.swapchain) xrDestroySwapchain(e.swapchain);
  for (Hand& h : hands_)
    if (h.grip_space) xrDestroySpace(h.grip_space);
  if (view_space_) xrDestroySpace(view_space_);
  if (stage_) xrDestroySpace(stage_);
  if (action_set_) xrDestroyActionSet(action_set_);
  if (session_) xrDestroySession(session_);
  renderer_.reset();
  window_.reset();
  if (instance_) xrDestroyInstance(instance_);
}

// ---------------------------------------------------------------------------------------------
// Frame loop

void OpenXrSystem::update_profile() {
  XrInteractionProfileState st =
      xr_struct<XrInteractionProfileState>(XR_TYPE_INTERACTION_PROFILE_STATE);
  if (XR_FAILED(xrGetCurrentInteractionProfile(session_, hands_[1].path, &st)) ||
      st.interactionProfile == XR_NULL_PATH)
    return;
  char buf[XR_MAX_PATH_LENGTH] = {};
  uint32_t len = 0;
  if (XR_SUCCEEDED(xrPathToString(instance_, st.interactionProfile, sizeof buf, &len, buf)))
    profile_ = buf;
}

bool OpenXrSystem::poll_events() {
  XrEventDataBuffer ev = xr_struct<XrEventDataBuffer>(XR_TYPE_EVENT_DATA_BUFFER);
  while (xrPollEvent(instance_, &ev) == XR_SUCCESS) {
    switch (ev.type) {
      case XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED: {
        const auto& e = *reinterpret_cast<const XrEventDataSessionStateChanged*>(&ev);
        state_ = e.state;
        if (state_ == XR_SESSION_STATE_READY) {
          XrSessionBeginInfo bi = xr_struct<XrSessionBeginInfo>(XR_TYPE_SESSION_BEGIN_INFO);
          bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
          CALIPER_XR(instance_, xrBeginSession(session_, &bi));
          running_ = true;
        } else if (state_ == XR_SESSION_STATE_STOPPING) {
          CALIPER_XR(instance_, xrEndSession(session_));
          running_ = false;
        } else if (state_ == XR_SESSION_STATE_LOSS_PENDING) {
          throw PoseSourceLost(
              "the OpenXR runtime is losing the session (XR_SESSION_STATE_LOSS_PENDING)");
        } else if (state_ == XR_SESSION_STATE_EXITING) {
          return false;
        }
        break;
      }
      case XR_TYPE_EVENT_DATA_INTERACTION_PROFILE_CHANGED:
        update_profile();
        break;
      case XR_TYPE_EVENT_DATA_INSTANCE_LOSS_PENDING:
        throw PoseSourceLost(
            "the OpenXR runtime is going away (XR_TYPE_EVENT_DATA_INSTANCE_LOSS_PENDING)");
      default:
        break;
    }
    ev = xr_struct<XrEventDataBuffer>(XR_TYPE_EVENT_DATA_BUFFER);
  }
  return true;
}

std::optional<PoseFrame> OpenXrSystem::next_frame() {
  while (true) {
    glfwPollEvents();
    if (window_->should_close()) return std::nullopt;
    if (!poll_events()) return std::nullopt;
    if (running_) break;
  }
  frame_state_ = xr_struct<XrFrameState>(XR_TYPE_FRAME_STATE);
  XrFrameWaitInfo wi = xr_struct<XrFrameWaitInfo>(XR_TYPE_FRAME_WAIT_INFO);
  CALIPER_XR(instance_, xrWaitFrame(session_, &wi, &frame_state_));
  XrFrameBeginInfo bi = xr_struct<XrFrameBeginInfo>(XR_TYPE_FRAME_BEGIN_INFO);
  CALIPER_XR(instance_, xrBeginFrame(session_, &bi));
  frame_begun_ = true;

  const XrActiveActionSet active{action_set_, XR_NULL_PATH};
  XrActionsSyncInfo sync = xr_struct<XrActionsSyncInfo>(XR_TYPE_ACTIONS_SYNC_INFO);
  sync.countActiveActionSets = 1;
  sync.activeActionSets = &active;
  CALIPER_XR(instance_, xrSyncActions(session_, &sync));
  if (profile_.empty()) update_profile();  // some runtimes bind without sending the event

  const XrTime t = frame_state_.predictedDisplayTime;
  if (start_time_ < 0.0) start_time_ = static_cast<double>(t) * 1e-9;
  PoseFrame f;
  f.time = static_cast<double>(t) * 1e-9 - start_time_;
  const auto to_pose = [](const XrSpaceLocation& loc, DevicePose& d) {
    const XrSpaceLocationFlags need = XR_SPACE_LOCATION_POSITION_VALID_BIT |
                                      XR_SPACE_LOCATION_ORIENTATION_VALID_BIT |
                                      XR_SPACE_LOCATION_POSITION_TRACKED_BIT;
    d.valid = (loc.locationFlags & need) == need;
    d.position = Eigen::Vector3d(loc.pose.position.x, loc.pose.position.y, loc.pose.position.z);
    d.orientation = Eigen::Quaterniond(loc.pose.orientation.w, loc.pose.orientation.x,
                                       loc.pose.orientation.y, loc.pose.orientation.z)
                        .normalized();
  };
  XrSpaceLocation head = xr_struct<XrSpaceLocation>(XR_TYPE_SPACE_LOCATION);
  CALIPER_XR(instance_, xrLocateSpace(view_space_, stage_, t, &head));
  to_pose(head, f.device(Device::Head));
  for (int h = 0; h < 2; ++h) {
    DevicePose& d = f.device(h == 0 ? Device::Left : Device::Right);
    XrSpaceLocation loc = xr_struct<XrSpaceLocation>(XR_TYPE_SPACE_LOCATION);
    CALIPER_XR(instance_,
               xrLocateSpace(hands_[static_cast<size_t>(h)].grip_space, stage_, t, &loc));
    to_pose(loc, d);
    XrActionStateGetInfo gi = xr_struct<XrActionStateGetInfo>(XR_TYPE_ACTION_STATE_GET_INFO);
    gi.subactionPath = hands_[static_cast<size_t>(h)].path;
    gi.action = trigger_;
    XrActionStateFloat fs = xr_struct<XrActionStateFloat>(XR_TYPE_ACTION_STATE_FLOAT);
    CALIPER_XR(instance_, xrGetActionStateFloat(session_, &gi, &fs));
    d.trigger = fs.isActive ? std::clamp(static_cast<double>(fs.currentState), 0.0, 1.0) : 0.0;
    XrActionStateBoolean bs = xr_struct<XrActionStateBoolean>(XR_TYPE_ACTION_STATE_BOOLEAN);
    gi.action = menu_;
    CALIPER_XR(instance_, xrGetActionStateBoolean(session_, &gi, &bs));
    d.menu = bs.isActive && bs.currentState;
    gi.action = squeeze_;
    CALIPER_XR(instance_, xrGetActionStateBoolean(session_, &gi, &bs));
    d.squeeze = bs.isActive && bs.currentState;
  }
  XrViewLocateInfo vli = xr_struct<XrViewLocateInfo>(XR_TYPE_VIEW_LOCATE_INFO);
  vli.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  vli.displayTime = t;
  vli.space = stage_;
  XrViewState vs = xr_struct<XrViewState>(XR_TYPE_VIEW_STATE);
  uint32_t nv = 2;
  views_ = {xr_struct<XrView>(XR_TYPE_VIEW), xr_struct<XrView>(XR_TYPE_VIEW)};
  CALIPER_XR(instance_, xrLocateViews(session_, &vli, &vs, 2, &nv, views_.data()));
  return f;
}

void OpenXrSystem::haptic_pulse(Tip hand, double amplitude, double seconds) {
  XrHapticVibration v = xr_struct<XrHapticVibration>(XR_TYPE_HAPTIC_VIBRATION);
  v.amplitude = static_cast<float>(amplitude);
  v.duration = static_cast<XrDuration>(seconds * 1e9);
  v.frequency = XR_FREQUENCY_UNSPECIFIED;
  XrHapticActionInfo hi = xr_struct<XrHapticActionInfo>(XR_TYPE_HAPTIC_ACTION_INFO);
  hi.action = haptic_;
  hi.subactionPath = hands_[hand == Tip::Left ? 0 : 1].path;
  CALIPER_XR(instance_,
             xrApplyHapticFeedback(session_, &hi, reinterpret_cast<XrHapticBaseHeader*>(&v)));
}

void OpenXrSystem::submit(const render::Scene& scene) {
  if (!frame_begun_) return;
  frame_begun_ = false;
  std::array<XrCompositionLayerProjectionView, 2> proj{};
  const render::GlFunctions& gl = window_->gl();
  const bool render = frame_state_.shouldRender == XR_TRUE;
  if (render) {
    for (int e = 0; e < 2; ++e) {
      EyeTarget& eye = eyes_[static_cast<size_t>(e)];
      uint32_t index = 0;
      XrSwapchainImageAcquireInfo ai =
          xr_struct<XrSwapchainImageAcquireInfo>(XR_TYPE_SWAPCHAIN_IMAGE_ACQUIRE_INFO);
      CALIPER_XR(instance_, xrAcquireSwapchainImage(eye.swapchain, &ai, &index));
      XrSwapchainImageWaitInfo wi =
          xr_struct<XrSwapchainImageWaitInfo>(XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO);
      wi.timeout = XR_INFINITE_DURATION;
      CALIPER_XR(instance_, xrWaitSwapchainImage(eye.swapchain, &wi));
      gl.BindFramebuffer(GL_FRAMEBUFFER, eye.fbo);
      gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
                              eye.images[index].image, 0);
      gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER,
                                 eye.depth);
      const XrView& v = views_[static_cast<size_t>(e)];
      render::View view;
      view.viewport = {0, 0, eye.width, eye.height};
      view.camera.use_matrices = true;
      const Eigen::Quaternionf q(v.pose.orientation.w, v.pose.orientation.x, v.pose.orientation.y,
                                 v.pose.orientation.z);
      render::Mat4 pose = render::Mat4::Identity();
      pose.block<3, 3>(0, 0) = q.normalized().toRotationMatrix();
      pose.block<3, 1>(0, 3) =
          render::Vec3(v.pose.position.x, v.pose.position.y, v.pose.position.z);
      view.camera.view = pose.inverse();
      // Asymmetric projection from the four field-of-view angles (OpenGL clip space).
      const float n = 0.05f, far = 50.0f;
      const float l = std::tan(v.fov.angleLeft), r = std::tan(v.fov.angleRight);
      const float d = std::tan(v.fov.angleDown), u = std::tan(v.fov.angleUp);
      render::Mat4 p = render::Mat4::Zero();
      p(0, 0) = 2.0f / (r - l);
      p(0, 2) = (r + l) / (r - l);
      p(1, 1) = 2.0f / (u - d);
      p(1, 2) = (u + d) / (u - d);
      p(2, 2) = -(far + n) / (far - n);
      p(2, 3) = -2.0f * far * n / (far - n);
      p(3, 2) = -1.0f;
      view.camera.projection = p;
      renderer_->draw(scene, view);
      gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
      XrSwapchainImageReleaseInfo ri =
          xr_struct<XrSwapchainImageReleaseInfo>(XR_TYPE_SWAPCHAIN_IMAGE_RELEASE_INFO);
      CALIPER_XR(instance_, xrReleaseSwapchainImage(eye.swapchain, &ri));
      XrCompositionLayerProjectionView& pv = proj[static_cast<size_t>(e)];
      pv = xr_struct<XrCompositionLayerProjectionView>(XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW);
      pv.pose = v.pose;
      pv.fov = v.fov;
      pv.subImage.swapchain = eye.swapchain;
      pv.subImage.imageRect.extent = {eye.width, eye.height};
    }
  }
  XrCompositionLayerProjection layer =
      xr_struct<XrCompositionLayerProjection>(XR_TYPE_COMPOSITION_LAYER_PROJECTION);
  layer.space = stage_;
  layer.viewCount = 2;
  layer.views = proj.data();
  const XrCompositionLayerBaseHeader* layers[] = {
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&layer)};
  XrFrameEndInfo ei = xr_struct<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
  ei.displayTime = frame_state_.predictedDisplayTime;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  ei.layerCount = render ? 1 : 0;
  ei.layers = render ? layers : nullptr;
  CALIPER_XR(instance_, xrEndFrame(session_, &ei));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// run_openxr

int run_openxr(const LiveOptions& o) {
  auto system = std::make_unique<OpenXrSystem>(o.operator_window);
  OpenXrSystem& xr = *system;
  if (!o.calibrate_tip.empty()) {
    if (o.calibrate_tip != "left" && o.calibrate_tip != "right")
      throw std::invalid_argument("--calibrate-tip needs left or right");
    std::cout << "Pivot calibration of the " << o.calibrate_tip
              << " controller: rest its tip on a fixed point, hold the trigger, and rotate the "
                 "controller for "
                 "five seconds while the tip stays put. Release the trigger to finish.\n";
    PivotCollector pivot(o.calibrate_tip == "left" ? Tip::Left : Tip::Right);
    render::Scene empty;
    while (std::optional<PoseFrame> f = xr.next_frame()) {
      std::optional<PivotCalibration> r = pivot.feed(*f);
      xr.submit(empty);
      if (r) {
        ControllerConfig cc = read_controller_config(o.controllers_path);
        TipOffsets t = cc.offsets(xr.interaction_profile());
        (o.calibrate_tip == "left" ? t.left : t.right) = r->tip_offset;
        cc.profiles[xr.interaction_profile()] = t;
        write_controller_config(o.controllers_path, cc);
        std::printf(
            "tip offset %.4f %.4f %.4f m, RMS residual %.2f mm over %d poses (%.0f degrees of "
            "rotation); "
            "saved for %s in %s\n",
            r->tip_offset.x(), r->tip_offset.y(), r->tip_offset.z(), r->rms_residual * 1e3,
            r->num_samples, r->max_rotation_degrees, xr.interaction_profile().c_str(),
            o.controllers_path.c_str());
        return 0;
      }
    }
    return 3;
  }
  VrAppOptions ao = o.make_app_options(xr.interaction_profile());
  const std::string journal = ao.journal_path;
  std::unique_ptr<Audio> audio = o.open_audio();
  VrApp app(std::move(ao), *audio, &xr.renderer());
  PoseSource* source = &xr;
  std::unique_ptr<RecordingPoseSource> recorder;
  if (!o.record_path.empty()) {
    PoseLogHeader h;  // profile and frame rate are filled in with the first frame
    h.role = o.role;
    h.source = "openxr";
    h.weight = o.weight;
    h.sex = o.sex;
    recorder = std::make_unique<RecordingPoseSource>(std::move(system), o.record_path, h);
    source = recorder.get();
  }
  std::optional<OperatorWindow> window;
  if (o.operator_window) window.emplace(xr.window());
  render::Scene scene;
  const ControllerConfig controllers = read_controller_config(o.controllers_path);
  std::string profile = xr.interaction_profile();
  try {
    while (std::optional<PoseFrame> f = source->next_frame()) {
      if (xr.interaction_profile() != profile) {  // the runtime told us which controllers are used
        profile = xr.interaction_profile();
        app.set_tips(controllers.offsets(profile));
      }
      app.advance(*f, source);
      app.build_scene(scene);
      xr.submit(scene);
      if (window)
        for (const OperatorCommand& c : window->frame(app, xr.renderer(), scene)) {
          if (recorder) recorder->record_command(c);
          app.command(c);
        }
      if (window) xr.window().swap_buffers();
      if (app.finished()) o.write_outputs(app);
      if (app.end_requested()) break;
    }
  } catch (const PoseSourceLost& e) {
    // Like the end of the pose source: the journal holds every accepted sample.
    std::cerr << "caliper-vr: " << e.what() << "\n";
    if (recorder) recorder->mark_lost(e.what());
  }
  return o.finish(app, *audio, journal);
}

}  // namespace caliper::vr
