// libFuzzer target: the .npz (zip + .npy) and .npy readers on arbitrary bytes, and the typed
// accessors on whatever they return. Anything but a result or a smpl::ModelError is a bug.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "smpl/npz.hpp"

namespace {

void touch(const smpl::NpyArray& a) {
  if (a.is_numeric()) {
    (void)a.to_double();
    (void)a.c_order();
    try {
      (void)a.to_int64();
    } catch (const smpl::ModelError&) {
    }
  } else {
    (void)a.to_strings();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    if (size >= 6 && std::memcmp(data, "\x93NUMPY", 6) == 0) {
      touch(smpl::parse_npy(data, size, "fuzz.npy"));
    } else {
      for (const auto& [key, array] : smpl::parse_npz(data, size, "fuzz.npz")) touch(array);
    }
  } catch (const smpl::ModelError&) {
  }
  return 0;
}
