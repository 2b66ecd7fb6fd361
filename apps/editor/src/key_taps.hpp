/// \file key_taps.hpp
/// Dear ImGui 1.86 reads the key state once per frame (io.KeysDown): a key pressed and
/// released between two frames (a quick Enter tap) would never be seen down. KeyTaps holds
/// such releases back until the frame after the press. Plain C++ (the GLFW glue in main.cpp
/// forwards events through it), so it is tested without a window.
#pragma once

#include <algorithm>
#include <vector>

namespace caliper::editor {

class KeyTaps {
 public:
  struct Key {
    int key, scancode, mods;
  };
  /// A key event (GLFW action codes: press 1, release 0, repeat 2). Returns true when the
  /// caller forwards it to ImGui now, false when the release is held back.
  bool on_key(int key, int scancode, int action, int mods) {
    constexpr int kPress = 1, kRelease = 0;
    if (action == kPress) pressed_.push_back(key);
    if (action == kRelease && std::find(pressed_.begin(), pressed_.end(), key) != pressed_.end()) {
      held_.push_back({key, scancode, mods});
      return false;
    }
    return true;
  }
  /// After a frame: returns the held-back releases (to forward now) and starts a new frame.
  std::vector<Key> frame_done() {
    pressed_.clear();
    std::vector<Key> out;
    out.swap(held_);
    return out;
  }

 private:
  std::vector<int> pressed_;
  std::vector<Key> held_;
};

}  // namespace caliper::editor
