// The live path's program unit (see openxr_program.hpp). Follows the OpenXR 1.0 specification's
// frame loop.
//
// Sections: check | instance and system | session and spaces | swapchains | events | frame loop.
#include "openxr_program.hpp"

#include <cstring>
#include <sstream>
#include <stdexcept>

#include "openxr_check.hpp"
#include "openxr_errors.hpp"

namespace caliper::vr {

// ---------------------------------------------------------------------------------------------
// Check: every OpenXR call is wrapped once, carrying the expression and file:line.

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

bool is_no_runtime(XrResult r) {
  return r == XR_ERROR_RUNTIME_UNAVAILABLE || r == XR_ERROR_RUNTIME_FAILURE ||
         r == XR_ERROR_INSTANCE_LOST || r == XR_ERROR_FILE_ACCESS_ERROR ||
         r == XR_ERROR_FILE_CONTENTS_INVALID;
}

// ---------------------------------------------------------------------------------------------
// Instance and system

OpenXrProgram::OpenXrProgram(std::unique_ptr<XrGraphicsPlugin> graphics)
    : graphics_(std::move(graphics)) {
  frame_state_ = xr_struct<XrFrameState>(XR_TYPE_FRAME_STATE);
  create_instance();
  graphics_->initialize_device(instance_, system_);
  create_session();
  input_ = std::make_unique<XrInput>(instance_, session_);
  create_swapchains();
}

void OpenXrProgram::create_instance() {
  uint32_t count = 0;
  const XrResult r = xrEnumerateInstanceExtensionProperties(nullptr, 0, &count, nullptr);
  if (is_no_runtime(r)) throw NoRuntimeError(kNoRuntimeMessage);
  CALIPER_XR(XR_NULL_HANDLE, r);
  std::vector<XrExtensionProperties> ext(
      count, xr_struct<XrExtensionProperties>(XR_TYPE_EXTENSION_PROPERTIES));
  CALIPER_XR(XR_NULL_HANDLE,
             xrEnumerateInstanceExtensionProperties(nullptr, count, &count, ext.data()));
  const std::vector<std::string> wanted = graphics_->instance_extensions();
  std::vector<const char*> names;
  for (const std::string& w : wanted) {
    bool offered = false;
    for (const XrExtensionProperties& e : ext) offered = offered || w == e.extensionName;
    if (!offered)
      throw std::runtime_error("the OpenXR runtime does not offer " + w +
                               ", which the graphics API needs; use a runtime that does "
                               "(SteamVR, Monado)");
    names.push_back(w.c_str());
  }
  XrInstanceCreateInfo ci = xr_struct<XrInstanceCreateInfo>(XR_TYPE_INSTANCE_CREATE_INFO);
  std::strncpy(ci.applicationInfo.applicationName, "The Virtual Caliper",
               XR_MAX_APPLICATION_NAME_SIZE - 1);
  ci.applicationInfo.applicationVersion = 1;
  std::strncpy(ci.applicationInfo.engineName, "caliper", XR_MAX_ENGINE_NAME_SIZE - 1);
  ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
  ci.enabledExtensionCount = static_cast<uint32_t>(names.size());
  ci.enabledExtensionNames = names.data();
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

void OpenXrProgram::create_session() {
  XrSessionCreateInfo ci = xr_struct<XrSessionCreateInfo>(XR_TYPE_SESSION_CREATE_INFO);
  ci.next = graphics_->graphics_binding();
  ci.systemId = system_;
  CALIPER_XR(instance_, xrCreateSession(instance_, &ci, &session_));
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
// Swapchains

void OpenXrProgram::create_swapchains() {
  const XrViewConfigurationType stereo = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  uint32_t n = 0;
  CALIPER_XR(instance_,
             xrEnumerateViewConfigurationViews(instance_, system_, stereo, 0, &n, nullptr));
  std::vector<XrViewConfigurationView> cfg(
      n, xr_struct<XrViewConfigurationView>(XR_TYPE_VIEW_CONFIGURATION_VIEW));
  CALIPER_XR(instance_,
             xrEnumerateViewConfigurationViews(instance_, system_, stereo, n, &n, cfg.data()));
  if (n != 2) throw std::runtime_error("the headset does not offer a stereo view configuration");
  uint32_t nf = 0;
  CALIPER_XR(instance_, xrEnumerateSwapchainFormats(session_, 0, &nf, nullptr));
  std::vector<int64_t> formats(nf);
  CALIPER_XR(instance_, xrEnumerateSwapchainFormats(session_, nf, &nf, formats.data()));
  const int64_t format = graphics_->select_color_format(formats);
  for (int e = 0; e < 2; ++e) {
    Eye& eye = eyes_[static_cast<size_t>(e)];
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
    graphics_->attach_swapchain(instance_, e, eye.swapchain, eye.width, eye.height);
  }
}

OpenXrProgram::~OpenXrProgram() {
  if (graphics_) graphics_->release_targets();
  for (Eye& e : eyes_)
    if (e.swapchain) xrDestroySwapchain(e.swapchain);
  input_.reset();
  if (view_space_) xrDestroySpace(view_space_);
  if (stage_) xrDestroySpace(stage_);
  if (session_) xrDestroySession(session_);
  graphics_.reset();
  if (instance_) xrDestroyInstance(instance_);
}

// ---------------------------------------------------------------------------------------------
// Events

void OpenXrProgram::update_profile() {
  const std::string p = input_->current_profile();
  if (!p.empty()) profile_ = p;
}

bool OpenXrProgram::on_state_change(XrSessionState state) {
  if (state == XR_SESSION_STATE_READY) {
    XrSessionBeginInfo bi = xr_struct<XrSessionBeginInfo>(XR_TYPE_SESSION_BEGIN_INFO);
    bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
    CALIPER_XR(instance_, xrBeginSession(session_, &bi));
    running_ = true;
  } else if (state == XR_SESSION_STATE_STOPPING) {
    CALIPER_XR(instance_, xrEndSession(session_));
    running_ = false;
  } else if (state == XR_SESSION_STATE_LOSS_PENDING) {
    throw PoseSourceLost(
        "the OpenXR runtime is losing the session (XR_SESSION_STATE_LOSS_PENDING)");
  } else if (state == XR_SESSION_STATE_EXITING) {
    return false;
  }
  return true;
}

bool OpenXrProgram::poll_events() {
  XrEventDataBuffer ev = xr_struct<XrEventDataBuffer>(XR_TYPE_EVENT_DATA_BUFFER);
  while (xrPollEvent(instance_, &ev) == XR_SUCCESS) {
    switch (ev.type) {
      case XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED:
        if (!on_state_change(reinterpret_cast<const XrEventDataSessionStateChanged*>(&ev)->state))
          return false;
        break;
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

// ---------------------------------------------------------------------------------------------
// Frame loop

double OpenXrProgram::frame_rate() const {
  return frame_state_.predictedDisplayPeriod > 0
             ? 1e9 / static_cast<double>(frame_state_.predictedDisplayPeriod)
             : 0.0;
}

std::optional<PoseFrame> OpenXrProgram::next_frame() {
  while (true) {
    if (!graphics_->poll_window()) return std::nullopt;
    if (!poll_events()) return std::nullopt;
    if (running_) break;
  }
  frame_state_ = xr_struct<XrFrameState>(XR_TYPE_FRAME_STATE);
  XrFrameWaitInfo wi = xr_struct<XrFrameWaitInfo>(XR_TYPE_FRAME_WAIT_INFO);
  CALIPER_XR(instance_, xrWaitFrame(session_, &wi, &frame_state_));
  XrFrameBeginInfo bi = xr_struct<XrFrameBeginInfo>(XR_TYPE_FRAME_BEGIN_INFO);
  CALIPER_XR(instance_, xrBeginFrame(session_, &bi));
  frame_begun_ = true;
  input_->sync();
  if (profile_.empty()) update_profile();  // some runtimes bind without sending the event

  const XrTime t = frame_state_.predictedDisplayTime;
  if (start_time_ < 0.0) start_time_ = static_cast<double>(t) * 1e-9;
  PoseFrame f;
  f.time = static_cast<double>(t) * 1e-9 - start_time_;
  XrSpaceLocation head = xr_struct<XrSpaceLocation>(XR_TYPE_SPACE_LOCATION);
  CALIPER_XR(instance_, xrLocateSpace(view_space_, stage_, t, &head));
  f.device(Device::Head) = device_pose(head);
  input_->read(stage_, t, f);
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

void OpenXrProgram::render_eye(int e, const render::Scene& scene,
                               XrCompositionLayerProjectionView& layer) {
  Eye& eye = eyes_[static_cast<size_t>(e)];
  uint32_t index = 0;
  XrSwapchainImageAcquireInfo ai =
      xr_struct<XrSwapchainImageAcquireInfo>(XR_TYPE_SWAPCHAIN_IMAGE_ACQUIRE_INFO);
  CALIPER_XR(instance_, xrAcquireSwapchainImage(eye.swapchain, &ai, &index));
  XrSwapchainImageWaitInfo wi =
      xr_struct<XrSwapchainImageWaitInfo>(XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO);
  wi.timeout = XR_INFINITE_DURATION;
  CALIPER_XR(instance_, xrWaitSwapchainImage(eye.swapchain, &wi));
  const XrView& v = views_[static_cast<size_t>(e)];
  graphics_->render_view(e, index, v, scene);
  XrSwapchainImageReleaseInfo ri =
      xr_struct<XrSwapchainImageReleaseInfo>(XR_TYPE_SWAPCHAIN_IMAGE_RELEASE_INFO);
  CALIPER_XR(instance_, xrReleaseSwapchainImage(eye.swapchain, &ri));
  layer = xr_struct<XrCompositionLayerProjectionView>(XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW);
  layer.pose = v.pose;
  layer.fov = v.fov;
  layer.subImage.swapchain = eye.swapchain;
  layer.subImage.imageRect.extent = {eye.width, eye.height};
}

void OpenXrProgram::submit(const render::Scene& scene) {
  if (!frame_begun_) return;
  frame_begun_ = false;
  std::array<XrCompositionLayerProjectionView, 2> proj{};
  const bool render = frame_state_.shouldRender == XR_TRUE;
  if (render)
    for (int e = 0; e < 2; ++e) render_eye(e, scene, proj[static_cast<size_t>(e)]);
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

}  // namespace caliper::vr
