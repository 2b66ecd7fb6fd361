// The generic undo/redo history: bounded, a new edit drops the redo branch, and a state that
// cannot be applied leaves state and history as they were (the editor once crashed on Undo).
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "app/history.hpp"

namespace ca = caliper::app;

namespace {
/// A stand-in for the editor: a current state changed by edits, restored through apply.
struct Editor {
  ca::History<std::string> history{3};
  std::string state = "a";
  void edit(const std::string& next) {
    history.record(state);
    state = next;
  }
  bool undo() {
    return history.undo(state, [&](const std::string& s) { state = s; });
  }
  bool redo() {
    return history.redo(state, [&](const std::string& s) { state = s; });
  }
};
}  // namespace

TEST(History, UndoAndRedoWalkTheEdits) {
  Editor e;
  EXPECT_FALSE(e.history.can_undo());
  EXPECT_FALSE(e.undo());
  e.edit("b");
  e.edit("c");
  ASSERT_TRUE(e.undo());
  EXPECT_EQ(e.state, "b");
  ASSERT_TRUE(e.undo());
  EXPECT_EQ(e.state, "a");
  EXPECT_FALSE(e.undo());
  EXPECT_EQ(e.state, "a");
  ASSERT_TRUE(e.redo());
  EXPECT_EQ(e.state, "b");
  ASSERT_TRUE(e.redo());
  EXPECT_EQ(e.state, "c");
  EXPECT_FALSE(e.redo());
}

TEST(History, ANewEditDropsTheRedoBranch) {
  Editor e;
  e.edit("b");
  e.edit("c");
  ASSERT_TRUE(e.undo());
  EXPECT_TRUE(e.history.can_redo());
  e.edit("x");
  EXPECT_FALSE(e.history.can_redo());
  ASSERT_TRUE(e.undo());
  EXPECT_EQ(e.state, "b");
}

TEST(History, KeepsOnlyTheLastMaxSteps) {
  Editor e;  // at most 3 steps
  for (const char* s : {"b", "c", "d", "e", "f"}) e.edit(s);
  EXPECT_EQ(e.history.undo_steps(), 3u);
  int undone = 0;
  while (e.undo()) ++undone;
  EXPECT_EQ(undone, 3);
  EXPECT_EQ(e.state, "c");  // a and b were dropped, oldest first
  EXPECT_EQ(e.history.redo_steps(), 3u);
}

TEST(History, AStateThatCannotBeAppliedChangesNothing) {
  Editor e;
  e.edit("b");
  e.edit("c");
  const auto refuse = [](const std::string&) { throw std::runtime_error("cannot apply"); };
  EXPECT_THROW(e.history.undo(e.state, refuse), std::runtime_error);
  EXPECT_EQ(e.state, "c");
  EXPECT_EQ(e.history.undo_steps(), 2u);
  EXPECT_EQ(e.history.redo_steps(), 0u);
  ASSERT_TRUE(e.undo());  // the step is still there and works
  EXPECT_EQ(e.state, "b");
  EXPECT_THROW(e.history.redo(e.state, refuse), std::runtime_error);
  EXPECT_EQ(e.history.redo_steps(), 1u);
  ASSERT_TRUE(e.redo());
  EXPECT_EQ(e.state, "c");
}

TEST(History, ApplyMayChangeTheStateItWasGiven) {
  // `current` is the editor's own state, which apply overwrites: the redo step must hold the
  // state from before the call, not the restored one.
  Editor e;
  e.edit("b");
  ASSERT_TRUE(e.undo());
  EXPECT_EQ(e.state, "a");
  ASSERT_TRUE(e.redo());
  EXPECT_EQ(e.state, "b");
}

TEST(History, ClearAndZeroCapacity) {
  Editor e;
  e.edit("b");
  e.history.clear();
  EXPECT_FALSE(e.history.can_undo());
  ca::History<int> none(0);
  none.record(1);
  EXPECT_FALSE(none.can_undo());
  EXPECT_EQ(none.max_steps(), 0u);
}
