/// \file messages.hpp
/// The editor's status messages: a bounded log of info, warnings and errors that the window
/// shows, and the one place where a failed command becomes an error message
/// (MessageLog::attempt).
#pragma once

#include <cstddef>
#include <deque>
#include <exception>
#include <string>
#include <type_traits>

namespace caliper::app {

/// A message for the window's status area.
struct Message {
  enum class Level { Info, Warning, Error } level = Level::Info;
  std::string text;
};

class MessageLog {
 public:
  /// Keeps the last `capacity` messages.
  explicit MessageLog(std::size_t capacity = 50) : capacity_(capacity) {}

  void post(Message::Level level, const std::string& text);
  /// Drops the errors and warnings of earlier commands (each edit starts with a clean status).
  void clear_stale();
  const std::deque<Message>& messages() const { return messages_; }

  /// Runs `f`. When it throws a std::exception, posts the error "<prefix><what()><suffix>" and
  /// returns false; otherwise returns what `f` returns when that is a bool, else true.
  template <class F>
  bool attempt(F&& f, const std::string& prefix = "", const std::string& suffix = "") {
    try {
      if constexpr (std::is_same_v<std::invoke_result_t<F>, bool>) {
        return f();
      } else {
        f();
        return true;
      }
    } catch (const std::exception& e) {
      post(Message::Level::Error, prefix + e.what() + suffix);
      return false;
    }
  }

 private:
  std::size_t capacity_;
  std::deque<Message> messages_;
};

}  // namespace caliper::app
