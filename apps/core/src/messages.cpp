// The editor's status messages.
#include "app/messages.hpp"

#include <algorithm>

namespace caliper::app {

void MessageLog::post(Message::Level level, const std::string& text) {
  messages_.push_back({level, text});
  while (messages_.size() > capacity_) messages_.pop_front();
}

void MessageLog::clear_stale() {
  messages_.erase(std::remove_if(messages_.begin(), messages_.end(),
                                 [](const Message& m) { return m.level != Message::Level::Info; }),
                  messages_.end());
}

}  // namespace caliper::app
