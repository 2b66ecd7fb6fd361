/// \file scalar_types.hpp
/// Binary scalars whose type is known only at run time (a .npy dtype, a PLY property type): one
/// enum of the fixed-size arithmetic types, one list of their C++ types in the same order, and one
/// dispatch from an enumerator to its C++ type, instead of a switch or an if-chain per reader.
/// Used by the .npy and PLY readers; nothing here prints or throws.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <tuple>
#include <type_traits>
#include <utility>

namespace smpl {

/// The fixed-size arithmetic types of the binary formats: PLY's eight first (in the order of its
/// type names char, uchar, short, ushort, int, uint, float, double), then the 64-bit integers that
/// .npy adds.
enum class ScalarType {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64,
  kInt64,
  kUint64
};

/// The C++ type of each ScalarType, in the enum's order.
using ScalarTypes = std::tuple<std::int8_t, std::uint8_t, std::int16_t, std::uint16_t, std::int32_t,
                               std::uint32_t, float, double, std::int64_t, std::uint64_t>;
static_assert(std::tuple_size_v<ScalarTypes> == static_cast<std::size_t>(ScalarType::kUint64) + 1);

namespace detail {
template <typename F, std::size_t... I>
decltype(auto) visit_scalar_type(std::size_t index, F& f, std::index_sequence<I...> /*all*/) {
  using R = decltype(f(std::tuple_element_t<0, ScalarTypes>{}));
  if constexpr (std::is_void_v<R>) {
    (void)((index == I ? (f(std::tuple_element_t<I, ScalarTypes>{}), true) : false) || ...);
  } else {
    R result{};
    (void)((index == I ? (result = f(std::tuple_element_t<I, ScalarTypes>{}), true) : false) ||
           ...);
    return result;
  }
}
}  // namespace detail

/// Calls `f(T{})` with T the C++ type of `type` (std::int8_t for kInt8, ..., double for
/// kFloat64) and returns what it returns: f is a generic lambda that takes the value as a type
/// tag, and it returns the same type for every T (or void). A value outside the enum calls
/// nothing and returns a value-initialised result.
template <typename F>
decltype(auto) visit_scalar_type(ScalarType type, F&& f) {
  return detail::visit_scalar_type(static_cast<std::size_t>(type), f,
                                   std::make_index_sequence<std::tuple_size_v<ScalarTypes>>{});
}

/// Bytes per value of `type`.
inline std::size_t scalar_size(ScalarType type) {
  return visit_scalar_type(type, [](auto tag) { return sizeof(tag); });
}

/// The T stored at `p` in the machine's byte order (little-endian on every supported platform);
/// `p` need not be aligned.
template <typename T>
T load_scalar(const std::uint8_t* p) noexcept {
  static_assert(std::is_arithmetic_v<T>);
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

}  // namespace smpl
