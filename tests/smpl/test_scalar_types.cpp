// smpl/scalar_types.hpp: one dispatch from a run-time scalar type to its C++ type.
#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <type_traits>

#include "smpl/scalar_types.hpp"

namespace {

using smpl::ScalarType;

// The C++ type a dispatch hands to its function, by name.
template <typename T>
std::string type_name() {
  if constexpr (std::is_same_v<T, std::int8_t>) return "int8";
  if constexpr (std::is_same_v<T, std::uint8_t>) return "uint8";
  if constexpr (std::is_same_v<T, std::int16_t>) return "int16";
  if constexpr (std::is_same_v<T, std::uint16_t>) return "uint16";
  if constexpr (std::is_same_v<T, std::int32_t>) return "int32";
  if constexpr (std::is_same_v<T, std::uint32_t>) return "uint32";
  if constexpr (std::is_same_v<T, std::int64_t>) return "int64";
  if constexpr (std::is_same_v<T, std::uint64_t>) return "uint64";
  if constexpr (std::is_same_v<T, float>) return "float";
  if constexpr (std::is_same_v<T, double>) return "double";
  return "?";
}

std::string dispatched(ScalarType t) {
  return smpl::visit_scalar_type(t, [](auto tag) { return type_name<decltype(tag)>(); });
}

TEST(ScalarTypes, EveryEnumeratorGetsItsType) {
  EXPECT_EQ(dispatched(ScalarType::kInt8), "int8");
  EXPECT_EQ(dispatched(ScalarType::kUint8), "uint8");
  EXPECT_EQ(dispatched(ScalarType::kInt16), "int16");
  EXPECT_EQ(dispatched(ScalarType::kUint16), "uint16");
  EXPECT_EQ(dispatched(ScalarType::kInt32), "int32");
  EXPECT_EQ(dispatched(ScalarType::kUint32), "uint32");
  EXPECT_EQ(dispatched(ScalarType::kFloat32), "float");
  EXPECT_EQ(dispatched(ScalarType::kFloat64), "double");
  EXPECT_EQ(dispatched(ScalarType::kInt64), "int64");
  EXPECT_EQ(dispatched(ScalarType::kUint64), "uint64");
}

TEST(ScalarTypes, SizesAndAValueOutsideTheEnum) {
  EXPECT_EQ(smpl::scalar_size(ScalarType::kUint8), 1u);
  EXPECT_EQ(smpl::scalar_size(ScalarType::kInt16), 2u);
  EXPECT_EQ(smpl::scalar_size(ScalarType::kFloat32), 4u);
  EXPECT_EQ(smpl::scalar_size(ScalarType::kFloat64), 8u);
  EXPECT_EQ(smpl::scalar_size(ScalarType::kUint64), 8u);
  // Nothing is called for a value that names no enumerator; the result is value-initialised.
  int calls = 0;
  smpl::visit_scalar_type(static_cast<ScalarType>(42), [&](auto) { ++calls; });
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(smpl::scalar_size(static_cast<ScalarType>(42)), 0u);
}

TEST(ScalarTypes, LoadReadsUnalignedLittleEndianValues) {
  const std::array<std::uint8_t, 9> bytes = {0xff, 0x01, 0x02, 0x03, 0x04, 0, 0, 0x80, 0x3f};
  EXPECT_EQ(smpl::load_scalar<std::int8_t>(bytes.data()), -1);
  EXPECT_EQ(smpl::load_scalar<std::uint16_t>(bytes.data() + 1), 0x0201);  // odd address
  EXPECT_EQ(smpl::load_scalar<std::uint32_t>(bytes.data() + 1), 0x04030201u);
  EXPECT_EQ(smpl::load_scalar<float>(bytes.data() + 5), 1.0f);  // 0x3f800000
}

}  // namespace
