// smpl/text.hpp and smpl/constants.hpp: the helpers every layer shares. The expected strings are
// what the copies they replaced produced (printf formats, std::tolower), so a change here is a
// change of the programs' messages and files.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "smpl/constants.hpp"
#include "smpl/text.hpp"

namespace {

namespace fs = std::filesystem;

TEST(Text, ToLowerChangesAsciiLettersOnly) {
  EXPECT_EQ(smpl::to_lower("5FT6In"), "5ft6in");
  EXPECT_EQ(smpl::to_lower(""), "");
  EXPECT_EQ(smpl::to_lower("caf\xC3\x89 .OBJ"), "caf\xC3\x89 .obj");  // UTF-8 bytes kept
}

TEST(Text, EndsWithIgnoresCase) {
  EXPECT_TRUE(smpl::ends_with_ci("Body.GLB", ".glb"));
  EXPECT_TRUE(smpl::ends_with_ci("body.glb", ".GLB"));
  EXPECT_FALSE(smpl::ends_with_ci("body.gltf", ".glb"));
  EXPECT_FALSE(smpl::ends_with_ci("b", ".glb"));  // shorter than the suffix
  EXPECT_TRUE(smpl::ends_with_ci("", ""));
}

TEST(Text, ReadFileReturnsBytesOrNothing) {
  const fs::path dir = fs::temp_directory_path() / ("caliper-text-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / "bytes.bin";
  const std::string bytes("a\r\nb\0c", 6);  // binary: no newline translation, NUL kept
  std::ofstream(path, std::ios::binary) << bytes;
  EXPECT_EQ(smpl::read_file(path.string()), bytes);
  std::ofstream(dir / "empty.txt", std::ios::binary).flush();
  EXPECT_EQ(smpl::read_file((dir / "empty.txt").string()), std::string());
  EXPECT_FALSE(smpl::read_file((dir / "missing.txt").string()).has_value());
  fs::remove_all(dir);
}

TEST(Text, AppendUtf8EncodesOneToFourBytes) {
  std::string s;
  smpl::append_utf8(s, 0x41);     // A
  smpl::append_utf8(s, 0xE9);     // e acute
  smpl::append_utf8(s, 0x20AC);   // euro sign
  smpl::append_utf8(s, 0x1F600);  // emoji
  EXPECT_EQ(s, "A\xC3\xA9\xE2\x82\xAC\xF0\x9F\x98\x80");
}

TEST(Text, FormatFixedIsPrintfFixed) {
  EXPECT_EQ(smpl::format_fixed(1.5, 2), "1.50");
  EXPECT_EQ(smpl::format_fixed(-0.04, 1), "-0.0");
  EXPECT_EQ(smpl::format_fixed(2.5, 0), "2");  // round half to even, as printf
  EXPECT_EQ(smpl::format_fixed(std::numeric_limits<double>::infinity(), 1), "inf");
  // Longer than any fixed buffer: printed in full, not cut off.
  const std::string big = smpl::format_fixed(1e100, 2);
  EXPECT_EQ(big.size(), 101u + 3u);
  EXPECT_EQ(big.substr(big.size() - 3), ".00");
}

TEST(Text, FormatGeneralIsPrintfG) {
  EXPECT_EQ(smpl::format_general(0.5, 6), "0.5");
  EXPECT_EQ(smpl::format_general(1234567.0, 6), "1.23457e+06");
  EXPECT_EQ(smpl::format_general(1.23456, 3), "1.23");
}

TEST(Text, FormatFixedOrShortKeepsAbsurdValuesShort) {
  EXPECT_EQ(smpl::format_fixed_or_short(12.345, 1), "12.3");
  EXPECT_EQ(smpl::format_fixed_or_short(-999999999.0, 0), "-999999999");
  EXPECT_EQ(smpl::format_fixed_or_short(1e308, 1), "1.000e+308");
  EXPECT_EQ(smpl::format_fixed_or_short(-std::numeric_limits<double>::infinity(), 1), "-inf");
}

TEST(Constants, PiIsTheDoubleAndFloatNearestPi) {
  EXPECT_EQ(smpl::kPi, std::acos(-1.0));
  EXPECT_EQ(smpl::kPiF, static_cast<float>(std::acos(-1.0)));
}

}  // namespace
