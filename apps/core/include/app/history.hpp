/// \file history.hpp
/// A bounded undo/redo history of whole states (the editor keeps its Document in one). Each
/// step stores the state before an edit; undo and redo swap the current state with the stored
/// one through a caller-given `apply`, and change the history only when `apply` succeeded, so a
/// state that cannot be applied any more (apply throws) leaves state and history as they were.
#pragma once

#include <cstddef>
#include <deque>
#include <utility>

namespace caliper::app {

template <class State>
class History {
 public:
  /// Keeps at most `max_steps` undo steps (the oldest go first); 0 keeps none.
  explicit History(std::size_t max_steps = 200) : max_steps_(max_steps) {}

  bool can_undo() const { return !undo_.empty(); }
  bool can_redo() const { return !redo_.empty(); }
  std::size_t undo_steps() const { return undo_.size(); }
  std::size_t redo_steps() const { return redo_.size(); }
  std::size_t max_steps() const { return max_steps_; }

  /// Records `before` (the state an edit is about to leave) as one undo step and clears what
  /// could be redone.
  void record(const State& before) {
    undo_.push_back(before);
    while (undo_.size() > max_steps_) undo_.pop_front();
    redo_.clear();
  }

  /// Undo: calls `apply(target)` with the state of the last undo step. When `apply` returns,
  /// the step leaves the undo list and `current` (the state before the call; copied first, so
  /// `apply` may change the object it refers to) becomes the next redo step. When `apply`
  /// throws, the history is unchanged and the exception propagates. False when there is
  /// nothing to undo (`apply` is not called).
  template <class Apply>
  bool undo(const State& current, Apply&& apply) {
    return step(undo_, redo_, current, std::forward<Apply>(apply));
  }
  /// Redo: the mirror of undo().
  template <class Apply>
  bool redo(const State& current, Apply&& apply) {
    return step(redo_, undo_, current, std::forward<Apply>(apply));
  }

  /// Forgets every step.
  void clear() {
    undo_.clear();
    redo_.clear();
  }

 private:
  template <class Apply>
  static bool step(std::deque<State>& from, std::deque<State>& to, const State& current,
                   Apply&& apply) {
    if (from.empty()) return false;
    State now = current;
    const State target = from.back();
    apply(target);  // may throw: nothing has changed yet
    from.pop_back();
    to.push_back(std::move(now));
    return true;
  }

  std::size_t max_steps_;
  std::deque<State> undo_;
  std::deque<State> redo_;
};

}  // namespace caliper::app
