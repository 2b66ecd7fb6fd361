// Private to libsmpl: the one way its file readers report a problem.
#pragma once

#include <string>

#include "smpl/body_model.hpp"

namespace smpl::detail {

/// Throws ModelError("<context>: <what>"): context names the file (and the entry in it), what
/// says what was wrong with it.
[[noreturn]] inline void fail(const std::string& context, const std::string& what) {
  throw ModelError(context + ": " + what);
}

}  // namespace smpl::detail
