// The editor's message log: bounded, stale errors go, and failures become one error message.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "app/messages.hpp"

namespace ca = caliper::app;
using Level = ca::Message::Level;

TEST(MessageLog, KeepsTheLastMessagesInOrder) {
  ca::MessageLog log(3);
  for (int i = 0; i < 5; ++i) log.post(Level::Info, std::to_string(i));
  ASSERT_EQ(log.messages().size(), 3u);
  EXPECT_EQ(log.messages().front().text, "2");
  EXPECT_EQ(log.messages().back().text, "4");
}

TEST(MessageLog, ClearingStaleMessagesKeepsOnlyInfo) {
  ca::MessageLog log;
  log.post(Level::Info, "one");
  log.post(Level::Error, "bad");
  log.post(Level::Warning, "odd");
  log.post(Level::Info, "two");
  log.clear_stale();
  ASSERT_EQ(log.messages().size(), 2u);
  EXPECT_EQ(log.messages()[0].text, "one");
  EXPECT_EQ(log.messages()[1].text, "two");
}

TEST(MessageLog, AttemptTurnsAFailureIntoOneErrorMessage) {
  ca::MessageLog log;
  bool ran = false;
  EXPECT_TRUE(log.attempt([&] { ran = true; }, "never: "));
  EXPECT_TRUE(ran);
  EXPECT_TRUE(log.messages().empty());
  EXPECT_FALSE(
      log.attempt([] { throw std::runtime_error("the reason"); }, "could not x: ", " (unchanged)"));
  ASSERT_EQ(log.messages().size(), 1u);
  EXPECT_EQ(log.messages().back().level, Level::Error);
  EXPECT_EQ(log.messages().back().text, "could not x: the reason (unchanged)");
  EXPECT_FALSE(log.attempt([] { throw std::invalid_argument("plain"); }));
  EXPECT_EQ(log.messages().back().text, "plain");
}

TEST(MessageLog, AttemptPassesOnWhatTheCommandReturns) {
  ca::MessageLog log;
  EXPECT_FALSE(log.attempt([] { return false; }));
  EXPECT_TRUE(log.attempt([] { return true; }));
  EXPECT_TRUE(log.messages().empty());  // a command's own false is not an exception
}
