// caliper::find_assets_dir(): $CALIPER_ASSETS wins (and a wrong one is not silently replaced);
// without it the folders next to the running executable are tried in a fixed order.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <optional>
#include <string>

#include "caliper/assets.hpp"

namespace {

namespace fs = std::filesystem;

/// Sets (or clears, for nullopt) an environment variable for one scope.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::optional<std::string>& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    if (value) {
      setenv(name, value->c_str(), 1);
    } else {
      unsetenv(name);
    }
  }
  ~ScopedEnv() {
    if (old_) {
      setenv(name_, old_->c_str(), 1);
    } else {
      unsetenv(name_);
    }
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

}  // namespace

TEST(Assets, EnvironmentVariableWinsAndIsTheOnlyCandidate) {
  const fs::path dir = fs::temp_directory_path() / "caliper-assets-test";
  fs::create_directories(dir);
  ScopedEnv env("CALIPER_ASSETS", dir.string());
  ASSERT_EQ(caliper::assets_dir_candidates().size(), 1u);
  const std::optional<std::string> found = caliper::find_assets_dir();
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(*found, dir.string());
  fs::remove_all(dir);
  EXPECT_FALSE(caliper::find_assets_dir().has_value()) << "a wrong setting must not be replaced";
}

TEST(Assets, WithoutTheVariableLooksBesideTheExecutable) {
  ScopedEnv env("CALIPER_ASSETS", std::nullopt);
  const auto c = caliper::assets_dir_candidates();
  ASSERT_EQ(c.size(), 3u);
  const fs::path exe_dir = fs::read_symlink("/proc/self/exe").parent_path();
  EXPECT_EQ(c[0], (exe_dir / "../../assets").lexically_normal().string());
  EXPECT_EQ(c[1], (exe_dir / "../share/virtual-caliper/assets").lexically_normal().string());
  EXPECT_EQ(c[2], (exe_dir / "../assets").lexically_normal().string());
  // The tests run from build/bin, so the build tree's assets (the source tree) are found.
  const auto found = caliper::find_assets_dir();
  ASSERT_TRUE(found.has_value());
  EXPECT_TRUE(fs::exists(fs::path(*found) / "models" / "caliper-female.npz")) << *found;
}

TEST(Assets, DefaultModelPathJoinsFolderAndSex) {
  EXPECT_EQ(caliper::default_model_file_name("neutral"), "caliper-neutral.npz");
  EXPECT_EQ(caliper::default_model_path("assets/models", "male"), "assets/models/caliper-male.npz");
  // Joined as std::filesystem::path joins: a trailing separator is not doubled.
  EXPECT_EQ(caliper::default_model_path("assets/models/", "female"),
            "assets/models/caliper-female.npz");
  // The sex is used as given; loading reports a file that does not exist.
  EXPECT_EQ(caliper::default_model_path("m", "other"), "m/caliper-other.npz");
}
