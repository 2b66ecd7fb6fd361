#include "smpl/text.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace smpl {

std::string to_lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool ends_with_ci(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(), [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) ==
           std::tolower(static_cast<unsigned char>(b));
  });
}

std::optional<std::string> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void append_utf8(std::string& out, std::uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

namespace {

// The output of `print(buffer, size)` (an snprintf call) as a std::string of the exact length:
// no truncation of long outputs.
template <class Print>
std::string printed(Print print) {
  char buf[64];
  const int n = print(buf, sizeof buf);
  if (n < 0) return std::string();
  if (static_cast<size_t>(n) < sizeof buf) return std::string(buf, static_cast<size_t>(n));
  std::string out(static_cast<size_t>(n) + 1, '\0');
  print(out.data(), out.size());
  out.resize(static_cast<size_t>(n));
  return out;
}

}  // namespace

std::string format_fixed(double v, int decimals) {
  return printed([&](char* b, size_t n) { return std::snprintf(b, n, "%.*f", decimals, v); });
}

std::string format_general(double v, int significant) {
  return printed([&](char* b, size_t n) { return std::snprintf(b, n, "%.*g", significant, v); });
}

std::string format_fixed_or_short(double v, int decimals) {
  if (std::abs(v) < 1e9) return format_fixed(v, decimals);
  return printed([&](char* b, size_t n) { return std::snprintf(b, n, "%.3e", v); });
}

}  // namespace smpl
