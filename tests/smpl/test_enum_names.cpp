// smpl/enum_names.hpp: one name table an enum, read both ways.
#include <gtest/gtest.h>

#include <array>
#include <cstddef>

#include "smpl/enum_names.hpp"
#include "smpl/simd.hpp"

namespace {

enum class Colour { kRed, kGreen, kBlue };
constexpr std::array<const char*, 3> kColourNames = {"red", "green", "blue"};
static_assert(kColourNames.size() == static_cast<std::size_t>(Colour::kBlue) + 1);

// Both directions work at compile time.
static_assert(smpl::enum_from_name<Colour>("green", kColourNames) == Colour::kGreen);
static_assert(!smpl::enum_from_name<Colour>("purple", kColourNames).has_value());

TEST(EnumNames, NameOfEveryEnumerator) {
  EXPECT_STREQ(smpl::enum_name(Colour::kRed, kColourNames), "red");
  EXPECT_STREQ(smpl::enum_name(Colour::kGreen, kColourNames), "green");
  EXPECT_STREQ(smpl::enum_name(Colour::kBlue, kColourNames), "blue");
}

TEST(EnumNames, ValueOutsideTheTableGetsTheFallback) {
  const auto bad = static_cast<Colour>(7);
  EXPECT_STREQ(smpl::enum_name(bad, kColourNames), "?");
  EXPECT_STREQ(smpl::enum_name(bad, kColourNames, "unknown"), "unknown");
}

TEST(EnumNames, ParseIsExactAndRoundTrips) {
  for (std::size_t i = 0; i < kColourNames.size(); ++i) {
    const auto c = static_cast<Colour>(i);
    EXPECT_EQ(smpl::enum_from_name<Colour>(smpl::enum_name(c, kColourNames), kColourNames), c);
  }
  EXPECT_FALSE(smpl::enum_from_name<Colour>("Red", kColourNames).has_value());  // case-sensitive
  EXPECT_FALSE(smpl::enum_from_name<Colour>("", kColourNames).has_value());
}

// A user of the tables: the SIMD level names and their parse agree for every level.
TEST(EnumNames, SimdLevelNamesRoundTrip) {
  for (smpl::SimdLevel l :
       {smpl::SimdLevel::kBaseline, smpl::SimdLevel::kAvx2, smpl::SimdLevel::kAvx512})
    EXPECT_EQ(smpl::parse_simd_level(smpl::simd_level_name(l)), l);
}

}  // namespace
