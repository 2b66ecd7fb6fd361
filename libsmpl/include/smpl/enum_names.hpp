/// \file enum_names.hpp
/// Names of the values of an enum whose enumerators run 0, 1, ..., N - 1: one constexpr table of
/// names an enum, read in both directions, instead of a switch for the name and an if-chain for
/// the parse. Beside each table its user writes
///     static_assert(kNames.size() == static_cast<std::size_t>(Enum::Last) + 1);
/// with the enum's last enumerator (or the enum's count constant), so that a table with a name too
/// many or too few does not compile. Used by every layer; nothing here prints or throws.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>

namespace smpl {

/// The name of `value`: names[static_cast<std::size_t>(value)]; `fallback` for a value outside
/// the table (an integer cast to the enum that names no enumerator).
template <typename Enum, std::size_t N>
constexpr const char* enum_name(Enum value, const std::array<const char*, N>& names,
                                const char* fallback = "?") noexcept {
  const auto i = static_cast<std::size_t>(value);
  return i < N ? names[i] : fallback;
}

/// The enumerator whose name is exactly `name` (case-sensitive), or std::nullopt.
template <typename Enum, std::size_t N>
constexpr std::optional<Enum> enum_from_name(std::string_view name,
                                             const std::array<const char*, N>& names) noexcept {
  for (std::size_t i = 0; i < N; ++i)
    if (name == names[i]) return static_cast<Enum>(i);
  return std::nullopt;
}

}  // namespace smpl
