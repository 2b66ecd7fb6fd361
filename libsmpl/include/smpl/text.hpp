/// \file text.hpp
/// Small text helpers used by every layer (libsmpl, libcaliper, the apps): ASCII lower-casing,
/// whole-file reading, UTF-8 encoding and printf-style number formatting. They live in the lowest
/// library so that each exists once. None prints or throws for ordinary input.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace smpl {

/// `s` with every character passed through std::tolower (the "C" locale: ASCII A-Z to a-z; other
/// bytes, including UTF-8 sequences, unchanged).
std::string to_lower(std::string s);

/// True when `s` ends with `suffix`, ignoring ASCII case ("MODEL.GLB" ends with ".glb").
bool ends_with_ci(const std::string& s, const std::string& suffix);

/// The whole content of the file at `path`, read in binary mode (no newline translation).
/// std::nullopt when the file cannot be opened; the caller reports that in its own words.
std::optional<std::string> read_file(const std::string& path);

/// Appends code point `cp` to `out` as UTF-8 (1 to 4 bytes). Precondition: cp <= 0x10FFFF and not
/// a surrogate (the callers check; other values are encoded without complaint).
void append_utf8(std::string& out, std::uint32_t cp);

/// printf "%.*f": `v` with `decimals` digits after the point ("1.50", "-0.0", "nan", "inf").
std::string format_fixed(double v, int decimals);

/// printf "%.*g": `v` with at most `significant` significant digits ("0.5", "1.2e+06").
std::string format_general(double v, int significant);

/// format_fixed(v, decimals) for |v| < 1e9; anything larger (or NaN, infinite) as printf "%.3e",
/// so an absurd value is printed short: 1e308 as "1.000e+308", not as 309 digits.
std::string format_fixed_or_short(double v, int decimals);

}  // namespace smpl
