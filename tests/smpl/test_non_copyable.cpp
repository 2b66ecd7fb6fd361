// smpl/non_copyable.hpp: the base of the interfaces that must not be copied (GL context, OpenXR
// graphics binding, audio, pose source). Compile-time checks; the test only makes them run in CI.
#include <gtest/gtest.h>

#include <type_traits>

#include "smpl/non_copyable.hpp"

namespace {

struct Resource : smpl::NonCopyable {
  int handle = 0;
};
static_assert(!std::is_copy_constructible_v<Resource>);
static_assert(!std::is_copy_assignable_v<Resource>);
static_assert(!std::is_move_constructible_v<Resource>);  // no moves unless the class declares them
static_assert(!std::is_move_assignable_v<Resource>);
static_assert(std::is_default_constructible_v<Resource>);

// An interface in the shape of render::GlContext: deriving adds no storage.
class Interface : smpl::NonCopyable {
 public:
  virtual ~Interface() = default;
  virtual int value() const = 0;
};
class Implementation final : public Interface {
 public:
  int value() const override { return 3; }
};
static_assert(!std::is_copy_constructible_v<Implementation>);
static_assert(sizeof(Interface) == sizeof(void*));

TEST(NonCopyable, DerivedClassesStillConstructAndDispatch) {
  Implementation impl;
  const Interface& i = impl;
  EXPECT_EQ(i.value(), 3);
}

}  // namespace
