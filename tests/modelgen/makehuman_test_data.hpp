/// \file makehuman_test_data.hpp
/// Where the model generator's tests find MakeHuman's CC0 assets (CALIPER_MAKEHUMAN_DIR, i.e.
/// ../shared/data/makehuman), read once per test program; REQUIRE_ASSETS() skips a test on a
/// machine without them.
#pragma once

#include <fstream>
#include <string>

#include "makehuman.hpp"
#include "makehuman_rig.hpp"

namespace makehuman_test {

inline const std::string kMh = CALIPER_MAKEHUMAN_DIR;

inline bool have_assets() {
  return static_cast<bool>(std::ifstream(kMh + "/3dobjs/base.obj"));
}

/// The assets, read on first use.
inline const modelgen::mh::Assets& assets() {
  static const modelgen::mh::Assets a = modelgen::mh::read_assets(kMh);
  return a;
}

}  // namespace makehuman_test

#define REQUIRE_ASSETS()                                                    \
  if (!makehuman_test::have_assets()) {                                     \
    GTEST_SKIP() << "MakeHuman assets not found at " << makehuman_test::kMh \
                 << " (../shared/data/...)";                                \
  }
