/// \file non_copyable.hpp
/// A base for classes that own something a copy must not share (a GL context, an OpenXR graphics
/// binding, an audio device, a tracking source): deriving from NonCopyable deletes the copy
/// constructor and copy assignment once, here, instead of in every such class. Moves are not
/// declared either, so a derived class is neither copyable nor movable unless it says so.
#pragma once

namespace smpl {

class NonCopyable {
 public:
  NonCopyable(const NonCopyable&) = delete;
  NonCopyable& operator=(const NonCopyable&) = delete;

 protected:
  NonCopyable() = default;
  ~NonCopyable() = default;
};

}  // namespace smpl
