/// \file openxr_check.hpp
/// OpenXR calls wrapped once (house style): CALIPER_XR(instance, call) throws with the call's
/// text, the result's name and file:line; a lost session or instance throws PoseSourceLost,
/// which the app treats like the end of the pose source. Shared by the OpenXR units (program,
/// input, graphics plugins).
#pragma once

#include <openxr/openxr.h>

#include <string>

namespace caliper::vr {

/// The result's name (XR_ERROR_...), or its number without an instance.
std::string xr_result_name(XrInstance instance, XrResult result);
/// Throws PoseSourceLost for XR_ERROR_SESSION_LOST / XR_ERROR_INSTANCE_LOST and
/// std::runtime_error naming `expr`, the result and file:line for other failures.
void xr_check(XrInstance instance, XrResult result, const char* expr, const char* file, int line);
/// The results that mean "no runtime installed or running" (NoRuntimeError, exit status 4).
bool is_no_runtime(XrResult result);

/// A zero-initialised OpenXR structure with its type set.
template <typename T>
T xr_struct(XrStructureType type) {
  T v{};
  v.type = type;
  return v;
}

}  // namespace caliper::vr

#define CALIPER_XR(instance, expr) \
  ::caliper::vr::xr_check((instance), (expr), #expr, __FILE__, __LINE__)
