/// \file npz.hpp
/// numpy `.npy` arrays and `.npz` archives (NEP 1, "A simple file format for NumPy arrays";
/// PKWARE APPNOTE 6.3 for the zip container), read and written without Python.
///
/// Reading: `.npy` versions 1.0, 2.0 and 3.0; zip members stored or deflated, zip64 extra fields,
/// CRC-32 checked; dtypes b1, i1, u1, i2, u2, i4, u4, i8, u8, f4, f8 and the fixed-width string
/// types S<n> (bytes) and U<n> (UTF-32); C and Fortran order; big-endian arrays are converted to
/// little-endian. Object arrays (`|O`, i.e. pickled members) are never unpickled: an `.npz`
/// member holding one is returned as a placeholder (dtype "|O", its shape, no data) whose
/// accessors throw ModelError with npy_object_array_advice(), so that files with unused object
/// members (SMPL-X's joint2num, part2num) still load.
/// Writing: `.npy` version 1.0 headers byte-identical to numpy's; zip members stored (or deflated
/// on request) with a fixed timestamp, so the same arrays always give the same bytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "smpl/body_model.hpp"

namespace smpl {

/// One numpy array: dtype descriptor, shape, memory order and raw little-endian bytes.
struct NpyArray {
  /// numpy dtype descriptor, always little-endian or byte-order free: "<f8", "<f4", "<i8", "<i4",
  /// "<i2", "|i1", "<u8", "<u4", "<u2", "|u1", "|b1", "|S<n>" (bytes) or "<U<n>" (UTF-32 text).
  std::string dtype = "<f8";
  std::vector<std::size_t> shape;  ///< empty for a 0-d (scalar) array.
  bool fortran_order = false;      ///< true: `data` is in column-major (Fortran) order.
  std::vector<std::uint8_t> data;  ///< element bytes, size() * item_size() of them.

  /// Number of elements (product of `shape`; 1 for a 0-d array).
  std::size_t size() const;
  /// Bytes per element (8 for "<f8", n for "|S<n>", 4 n for "<U<n>").
  std::size_t item_size() const;
  /// numpy kind character: 'f' float, 'i' signed, 'u' unsigned, 'b' bool, 'S' bytes, 'U' text,
  /// 'O' object-array placeholder (no data).
  char kind() const;
  /// True for the numeric and bool kinds (f, i, u, b).
  bool is_numeric() const;
  /// "(6890, 3)"-style text of the shape, for messages.
  std::string shape_string() const;

  /// All elements as doubles in C (row-major) order. Throws ModelError for non-numeric dtypes.
  std::vector<double> to_double() const;
  /// All elements as int64 in C order. Floats must hold integral values; u8 values above
  /// 2^63 - 1 wrap (numpy's astype(int64)). Throws ModelError otherwise.
  std::vector<std::int64_t> to_int64() const;
  /// Elements of an S or U array as UTF-8 strings in C order (trailing NULs removed).
  std::vector<std::string> to_strings() const;
  /// The same array with its data in C order (a copy; fortran_order is false).
  NpyArray c_order() const;
};

/// An `.npz` archive's arrays by key (member name without ".npy"), sorted by key.
using NpzArchive = std::map<std::string, NpyArray>;

/// The message for object arrays: they are pickled data, never loaded, and how to convert them.
std::string npy_object_array_advice();

/// numpy's descriptor for the C++ scalar type T (double -> "<f8", std::int32_t -> "<i4", ...).
template <typename T>
std::string npy_dtype() {
  if constexpr (std::is_same_v<T, bool>) {
    return "|b1";
  } else if constexpr (std::is_floating_point_v<T>) {
    static_assert(sizeof(T) == 4 || sizeof(T) == 8, "float or double");
    return sizeof(T) == 4 ? "<f4" : "<f8";
  } else {
    static_assert(std::is_integral_v<T>, "arithmetic types only");
    const char kind = std::is_signed_v<T> ? 'i' : 'u';
    return std::string(sizeof(T) == 1 ? "|" : "<") + kind + std::to_string(sizeof(T));
  }
}

/// A C-order array of `shape` from `values` (values.size() must equal the product of shape).
/// Throws ModelError when the sizes disagree. Assumes a little-endian machine (x86-64, ARM64).
template <typename T>
NpyArray make_npy(const std::vector<T>& values, std::vector<std::size_t> shape) {
  NpyArray a;
  a.dtype = npy_dtype<T>();
  a.shape = std::move(shape);
  if (a.size() != values.size()) {
    throw ModelError("make_npy: " + std::to_string(values.size()) +
                     " values do not fill an array of shape " + a.shape_string());
  }
  a.data.resize(values.size() * sizeof(T));
  for (std::size_t i = 0; i < values.size(); ++i) {
    const T v = values[i];
    std::memcpy(a.data.data() + i * sizeof(T), &v, sizeof(T));
  }
  return a;
}

/// A 2-D C-order array (rows x cols) from any Eigen matrix, whatever its storage order.
template <typename Derived>
NpyArray make_npy(const Eigen::DenseBase<Derived>& m) {
  using T = typename Derived::Scalar;
  std::vector<T> values(static_cast<std::size_t>(m.rows() * m.cols()));
  std::size_t n = 0;
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) values[n++] = m(r, c);
  }
  return make_npy(values, {static_cast<std::size_t>(m.rows()), static_cast<std::size_t>(m.cols())});
}

/// A 1-D "<U<n>" text array (numpy's str array; opens with np.load(allow_pickle=False)). Text is
/// UTF-8 in, UTF-32 in the file. A 0-d array when `scalar` is true (exactly one string then).
NpyArray make_npy_strings(const std::vector<std::string>& values, bool scalar = false);

/// The `.npy` file bytes of `array` (version 1.0 header, padded to 64 bytes like numpy's).
std::vector<std::uint8_t> npy_bytes(const NpyArray& array);
/// Parses `.npy` bytes. `context` (file and member) starts every error message. An object array
/// gives a placeholder (see above). Throws ModelError: bad magic, bad header, unsupported dtype,
/// size mismatch.
NpyArray parse_npy(const std::uint8_t* bytes, std::size_t size, const std::string& context);
/// An array from a dtype descriptor (any byte order: "<f8", ">i4", "|b1", "f8" = native, ...),
/// a shape, a memory order and exactly size() * item_size() raw bytes; big-endian data is
/// converted. Throws ModelError naming `context`: unsupported or object dtype, wrong byte count.
NpyArray npy_from_raw(const std::string& descr, std::vector<std::size_t> shape, bool fortran_order,
                      const std::uint8_t* bytes, std::size_t size, const std::string& context);
/// Reads a `.npy` file. Throws ModelError naming `path` and the problem.
NpyArray read_npy(const std::string& path);
/// Writes a `.npy` file. Throws ModelError when the file cannot be written.
void write_npy(const std::string& path, const NpyArray& array);

/// The bytes of an `.npz` archive holding `arrays` (members "<key>.npy" in key order, timestamp
/// 1980-01-01 00:00, no extra fields). `compress` deflates the members (zlib level 6), like
/// np.savez_compressed. Deterministic: the same arrays always give the same bytes.
std::vector<std::uint8_t> npz_bytes(const NpzArchive& arrays, bool compress = false);
/// The number of leading bytes of a `.npy` file that hold its preamble and header, from at least
/// its first 12 bytes (10 for version 1.0). Throws ModelError for bad magic, an unknown version or
/// a header longer than 1 MiB.
std::size_t npy_header_size(const std::uint8_t* bytes, std::size_t size,
                            const std::string& context);
/// The size of a whole `.npy` file (header and data) as its header declares it, from at least its
/// first npy_header_size() bytes (the data need not be present). 0 for an object array, whose
/// pickled data has no declared size. Throws ModelError for a bad header, an unsupported dtype or
/// an impossibly large shape.
std::size_t npy_declared_size(const std::uint8_t* bytes, std::size_t size,
                              const std::string& context);

/// An `.npz` archive's directory, read once; a member is inflated, CRC-checked and parsed only
/// when array() asks for it, so members nobody uses cost nothing (a zip bomb among them is never
/// inflated). The constructor refuses archives whose members overlap (several directory entries
/// pointing at the same data) or repeat a name, and members whose local header or data lie
/// outside the file. A deflated member is inflated up to the size its `.npy` header declares and
/// no further: a directory that claims more (or less) is refused before the data is inflated.
/// The `bytes` must outlive the reader.
class NpzReader {
 public:
  /// Reads the directory of `size` bytes; `context` (the file) starts every error message.
  /// Throws ModelError: not a zip, truncated, overlapping or repeated members.
  NpzReader(const std::uint8_t* bytes, std::size_t size, std::string context);
  /// The keys (member names ending in ".npy", without it), sorted.
  std::vector<std::string> keys() const;
  /// True when the archive has member `key` + ".npy".
  bool has(const std::string& key) const;
  /// Inflates, checks and parses member `key` + ".npy". Throws ModelError naming the member:
  /// missing, encrypted, unsupported compression, sizes that disagree with the `.npy` header,
  /// corrupt deflate data, CRC mismatch, bad `.npy` data. An object array gives the placeholder
  /// described above (its pickled data is neither inflated nor checked).
  NpyArray array(const std::string& key) const;

 private:
  struct Member {
    std::string name;
    std::uint16_t method = 0;
    std::uint16_t flags = 0;
    std::uint32_t crc = 0;
    std::uint64_t compressed = 0;
    std::uint64_t uncompressed = 0;
    std::uint64_t data_offset = 0;
  };
  const std::uint8_t* bytes_;
  std::string context_;
  std::map<std::string, Member> members_;  // by key
};

/// Parses all `.npy` members of `.npz` bytes (NpzReader::array() for every key). Members not
/// ending in ".npy" are ignored. Throws ModelError naming `context`, the member and the problem
/// (bad zip, truncated, overlapping members, CRC mismatch, bad npy header, unsupported dtype or
/// compression).
NpzArchive parse_npz(const std::uint8_t* bytes, std::size_t size, const std::string& context);
/// Reads an `.npz` file; errors name `path`.
NpzArchive read_npz(const std::string& path);
/// Writes an `.npz` file (see npz_bytes()). Throws ModelError when it cannot be written.
void write_npz(const std::string& path, const NpzArchive& arrays, bool compress = false);

/// Reads a whole file into memory. Throws ModelError naming `path` when it cannot be read.
std::vector<std::uint8_t> read_file_bytes(const std::string& path);
/// Writes `bytes` to `path` atomically (write_file_atomic). Throws WriteError naming `path` on
/// failure; the previous file is then unchanged.
void write_file_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes);

}  // namespace smpl
