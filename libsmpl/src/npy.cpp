// numpy .npy arrays: header parsing and writing, dtype conversion, memory order
// (NEP 1, "A simple file format for NumPy arrays"; numpy/lib/format.py behaviour for headers).
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <string_view>

#include "model_error.hpp"
#include "smpl/atomic_file.hpp"
#include "smpl/enum_names.hpp"
#include "smpl/npz.hpp"
#include "smpl/scalar_types.hpp"
#include "smpl/text.hpp"

namespace smpl {
namespace {

using detail::fail;

constexpr std::size_t kMaxDims = 32;  // numpy's NPY_MAXDIMS.

// ---------------------------------------------------------------------------------------------
// A Python literal subset for .npy headers: dict, tuple, list, str, int, True, False, None.
struct Literal {
  enum class Kind { kNone, kBool, kInt, kStr, kTuple, kList, kDict } kind = Kind::kNone;
  std::int64_t integer = 0;
  std::string text;
  std::vector<Literal> items;  // tuple/list elements; dict: key, value, key, value, ...
};

class LiteralParser {
 public:
  LiteralParser(const std::string& s, const std::string& context) : s_(s), context_(context) {}

  Literal parse() {
    Literal v = value(0);
    skip_space();
    if (pos_ != s_.size()) bad("unexpected text after the header dictionary");
    return v;
  }

 private:
  [[noreturn]] void bad(const std::string& what) const {
    fail(context_, "bad .npy header (" + what + " at character " + std::to_string(pos_) + "): '" +
                       s_.substr(0, 200) + "'");
  }
  void skip_space() {
    while (pos_ < s_.size() &&
           (s_[pos_] == ' ' || s_[pos_] == '\t' || s_[pos_] == '\n' || s_[pos_] == '\r')) {
      ++pos_;
    }
  }
  bool take(char c) {
    skip_space();
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  Literal sequence(char close, Literal::Kind kind, int depth) {
    Literal v;
    v.kind = kind;
    bool saw_comma = false;
    while (!take(close)) {
      if (!v.items.empty() && !saw_comma) bad("expected ','");
      v.items.push_back(value(depth + 1));
      if (kind == Literal::Kind::kDict) {
        if (v.items.back().kind != Literal::Kind::kStr) bad("dictionary keys must be strings");
        if (!take(':')) bad("expected ':'");
        v.items.push_back(value(depth + 1));
      }
      saw_comma = take(',');
    }
    // Python: (5) is an int, (5,) a tuple; the header writer always writes (5,).
    if (kind == Literal::Kind::kTuple && v.items.size() == 1 && !saw_comma) return v.items[0];
    return v;
  }
  Literal value(int depth) {
    if (depth > 8) bad("nested too deeply");
    skip_space();
    if (pos_ >= s_.size()) bad("unexpected end");
    const char c = s_[pos_];
    if (c == '{') {
      ++pos_;
      return sequence('}', Literal::Kind::kDict, depth);
    }
    if (c == '(') {
      ++pos_;
      return sequence(')', Literal::Kind::kTuple, depth);
    }
    if (c == '[') {
      ++pos_;
      return sequence(']', Literal::Kind::kList, depth);
    }
    if (c == '\'' || c == '"') {
      ++pos_;
      Literal v;
      v.kind = Literal::Kind::kStr;
      while (pos_ < s_.size() && s_[pos_] != c) {
        if (s_[pos_] == '\\') bad("escapes are not supported in header strings");
        v.text += s_[pos_++];
      }
      if (pos_ >= s_.size()) bad("unterminated string");
      ++pos_;
      return v;
    }
    if ((c >= '0' && c <= '9') || c == '-') {
      Literal v;
      v.kind = Literal::Kind::kInt;
      bool negative = false;
      if (c == '-') {
        negative = true;
        ++pos_;
      }
      const std::size_t start = pos_;
      std::uint64_t n = 0;
      while (pos_ < s_.size() && s_[pos_] >= '0' && s_[pos_] <= '9') {
        if (n > (static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()) - 9) / 10) {
          bad("integer too large");
        }
        n = n * 10 + static_cast<std::uint64_t>(s_[pos_++] - '0');
      }
      if (pos_ == start) bad("expected a digit");
      if (pos_ < s_.size() && s_[pos_] == 'L') ++pos_;  // Python 2 long suffix
      v.integer = negative ? -static_cast<std::int64_t>(n) : static_cast<std::int64_t>(n);
      return v;
    }
    for (const char* word : {"True", "False", "None"}) {
      const std::string w(word);
      if (s_.compare(pos_, w.size(), w) == 0) {
        pos_ += w.size();
        Literal v;
        v.kind = w == "None" ? Literal::Kind::kNone : Literal::Kind::kBool;
        v.integer = w == "True" ? 1 : 0;
        return v;
      }
    }
    bad(std::string("unexpected character '") + c + "'");
  }

  const std::string& s_;
  const std::string& context_;
  std::size_t pos_ = 0;
};

// ---------------------------------------------------------------------------------------------
// dtype descriptors.
}  // namespace

std::string npy_object_array_advice() {
  return "is a Python object array (dtype '|O'), i.e. pickled data, which is never loaded. A "
         "scipy sparse matrix saved with np.savez becomes such an array; convert it to a dense "
         "array first, e.g. np.savez(out, J_regressor=np.asarray(J_regressor.todense()), ...)";
}

namespace {

std::string object_array_message() {
  return npy_object_array_advice();
}

struct DtypeInfo {
  std::string normalized;  // "<f8", "|b1", "|S5", "<U3", ...
  std::size_t item_size = 0;
  std::size_t swap_unit = 0;  // bytes per swapped unit when big-endian (0: no swap)
};

DtypeInfo parse_descr(const std::string& descr, const std::string& context) {
  if (descr.empty()) fail(context, "empty dtype descriptor");
  char order = descr[0];
  std::string body = descr.substr(1);
  if (order != '<' && order != '>' && order != '|' && order != '=') {
    order = '=';
    body = descr;
  }
  if (body.empty()) fail(context, "bad dtype descriptor '" + descr + "'");
  const char kind = body[0];
  if (kind == 'O') fail(context, object_array_message());
  std::size_t n = 0;
  if (body.size() < 2 || body.size() > 12) fail(context, "unsupported dtype '" + descr + "'");
  for (std::size_t i = 1; i < body.size(); ++i) {
    if (body[i] < '0' || body[i] > '9') fail(context, "unsupported dtype '" + descr + "'");
    n = n * 10 + static_cast<std::size_t>(body[i] - '0');
  }
  DtypeInfo info;
  const bool big = order == '>';
  auto numeric = [&](std::initializer_list<std::size_t> sizes) {
    if (std::find(sizes.begin(), sizes.end(), n) == sizes.end()) {
      fail(context, "unsupported dtype '" + descr +
                        "' (supported: b1, i1, u1, i2, u2, i4, u4, "
                        "i8, u8, f4, f8, S<n>, U<n>)");
    }
    info.item_size = n;
    info.normalized = std::string(n == 1 ? "|" : "<") + kind + std::to_string(n);
    info.swap_unit = (big && n > 1) ? n : 0;
  };
  switch (kind) {
    case 'b':
      numeric({1});
      break;
    case 'i':
    case 'u':
      numeric({1, 2, 4, 8});
      break;
    case 'f':
      numeric({4, 8});
      break;
    case 'S':
      if (n == 0) fail(context, "unsupported dtype '" + descr + "'");
      info.item_size = n;
      info.normalized = "|S" + std::to_string(n);
      break;
    case 'U':
      if (n == 0 || n > (1u << 24)) fail(context, "unsupported dtype '" + descr + "'");
      info.item_size = 4 * n;
      info.normalized = "<U" + std::to_string(n);
      info.swap_unit = big ? 4 : 0;
      break;
    default:
      fail(context, "unsupported dtype '" + descr +
                        "' (supported: b1, i1, u1, i2, u2, i4, u4, "
                        "i8, u8, f4, f8, S<n>, U<n>)");
  }
  return info;
}

// The numeric dtypes (as parse_descr normalises them) in ScalarType's order.
constexpr std::array<const char*, 10> kNumericDtypes = {"|i1", "|u1", "<i2", "<u2", "<i4",
                                                        "<u4", "<f4", "<f8", "<i8", "<u8"};
static_assert(kNumericDtypes.size() == static_cast<std::size_t>(ScalarType::kUint64) + 1);

// Calls f(value) for every element of a numeric array in storage order.
template <typename F>
void for_each_numeric(const NpyArray& a, const F& f) {
  const std::string& d = a.dtype;
  const std::uint8_t* p = a.data.data();
  const std::size_t n = a.size();
  if (const auto type = enum_from_name<ScalarType>(d, kNumericDtypes)) {
    visit_scalar_type(*type, [&](auto tag) {
      using T = decltype(tag);
      for (std::size_t i = 0; i < n; ++i) f(load_scalar<T>(p + i * sizeof(T)));
    });
  } else if (d == "|b1") {
    for (std::size_t i = 0; i < n; ++i) f(static_cast<std::uint8_t>(p[i] != 0));
  } else {
    throw ModelError("array of dtype '" + d + "' is not numeric");
  }
}

void check_numeric(const NpyArray& a) {
  if (a.kind() == 'O') throw ModelError(object_array_message());
  if (!a.is_numeric()) throw ModelError("array of dtype '" + a.dtype + "' is not numeric");
}

std::vector<std::uint32_t> decode_utf8(const std::string& s) {
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t len = c < 0x80         ? 1
                      : (c >> 5) == 6  ? 2
                      : (c >> 4) == 14 ? 3
                      : (c >> 3) == 30 ? 4
                                       : 0;
    if (len == 0 || i + len > s.size()) {
      throw ModelError("text '" + s + "' is not valid UTF-8");
    }
    std::uint32_t cp = len == 1 ? c : len == 2 ? (c & 0x1Fu) : len == 3 ? (c & 0x0Fu) : (c & 0x07u);
    for (std::size_t k = 1; k < len; ++k) {
      const auto cc = static_cast<unsigned char>(s[i + k]);
      if ((cc >> 6) != 2) throw ModelError("text '" + s + "' is not valid UTF-8");
      cp = (cp << 6) | (cc & 0x3Fu);
    }
    out.push_back(cp);
    i += len;
  }
  return out;
}

std::string python_tuple(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) s += ", ";
    s += std::to_string(shape[i]);
  }
  if (shape.size() == 1) s += ",";
  return s + ")";
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// NpyArray members.
std::size_t NpyArray::size() const {
  std::size_t n = 1;
  for (std::size_t d : shape) n *= d;
  return n;
}

std::size_t NpyArray::item_size() const {
  if (kind() == 'O') return 0;  // placeholder: no data
  return parse_descr(dtype, "dtype").item_size;
}

char NpyArray::kind() const {
  return dtype.size() >= 2 ? dtype[1] : '?';
}

bool NpyArray::is_numeric() const {
  const char k = kind();
  return k == 'f' || k == 'i' || k == 'u' || k == 'b';
}

std::string NpyArray::shape_string() const {
  return python_tuple(shape);
}

NpyArray NpyArray::c_order() const {
  NpyArray out = *this;
  out.fortran_order = false;
  if (!fortran_order || shape.size() < 2 || kind() == 'O') return out;
  const std::size_t item = item_size();
  const std::size_t n = size();
  const std::size_t nd = shape.size();
  // Fortran strides (in elements) of each axis.
  std::vector<std::size_t> stride(nd, 1);
  for (std::size_t k = 1; k < nd; ++k) stride[k] = stride[k - 1] * shape[k - 1];
  std::vector<std::size_t> index(nd, 0);
  std::size_t src = 0;
  auto copy = [&](auto tag) {
    using T = decltype(tag);
    const std::uint8_t* in = data.data();
    std::uint8_t* o = out.data.data();
    for (std::size_t i = 0; i < n; ++i) {
      if constexpr (std::is_same_v<T, void*>) {
        std::memcpy(o + i * item, in + src * item, item);
      } else {
        std::memcpy(o + i * sizeof(T), in + src * sizeof(T), sizeof(T));
      }
      // Advance the C-order multi-index (last axis fastest) and the Fortran source offset.
      for (std::size_t k = nd; k-- > 0;) {
        if (++index[k] < shape[k]) {
          src += stride[k];
          break;
        }
        src -= stride[k] * (shape[k] - 1);
        index[k] = 0;
      }
    }
  };
  // Items of 1, 2, 4 or 8 bytes move as one unsigned integer of that size (a copy of a fixed
  // size), other items (strings) as `item` bytes.
  for (const ScalarType word :
       {ScalarType::kUint8, ScalarType::kUint16, ScalarType::kUint32, ScalarType::kUint64}) {
    if (scalar_size(word) == item) {
      visit_scalar_type(word, copy);
      return out;
    }
  }
  copy(static_cast<void*>(nullptr));
  return out;
}

std::vector<double> NpyArray::to_double() const {
  check_numeric(*this);
  const NpyArray& a = fortran_order && shape.size() >= 2 ? c_order() : *this;
  std::vector<double> out;
  out.reserve(a.size());
  for_each_numeric(a, [&](auto v) { out.push_back(static_cast<double>(v)); });
  return out;
}

std::vector<std::int64_t> NpyArray::to_int64() const {
  check_numeric(*this);
  const NpyArray c = fortran_order && shape.size() >= 2 ? c_order() : NpyArray{};
  const NpyArray& a = fortran_order && shape.size() >= 2 ? c : *this;
  std::vector<std::int64_t> out;
  out.reserve(a.size());
  for_each_numeric(a, [&](auto v) {
    using T = decltype(v);
    if constexpr (std::is_floating_point_v<T>) {
      if (!(std::floor(v) == v) || !(std::fabs(v) < 9.2e18)) {
        throw ModelError("array of dtype '" + dtype + "' holds the non-integer value " +
                         std::to_string(v) + " where integers are expected");
      }
    }
    out.push_back(static_cast<std::int64_t>(v));
  });
  return out;
}

std::vector<std::string> NpyArray::to_strings() const {
  const char k = kind();
  if (k == 'O') throw ModelError(object_array_message());
  if (k != 'S' && k != 'U') throw ModelError("array of dtype '" + dtype + "' is not text");
  const NpyArray c = fortran_order && shape.size() >= 2 ? c_order() : NpyArray{};
  const NpyArray& a = fortran_order && shape.size() >= 2 ? c : *this;
  const std::size_t item = item_size();
  std::vector<std::string> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::uint8_t* p = a.data.data() + i * item;
    std::string s;
    if (k == 'S') {
      s.assign(reinterpret_cast<const char*>(p), item);
      while (!s.empty() && s.back() == '\0') s.pop_back();
    } else {
      std::size_t len = item / 4;
      while (len > 0 && load_scalar<std::uint32_t>(p + 4 * (len - 1)) == 0) --len;
      for (std::size_t j = 0; j < len; ++j) {
        const auto cp = load_scalar<std::uint32_t>(p + 4 * j);
        if (cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) {
          throw ModelError("text array holds the invalid code point " + std::to_string(cp));
        }
        append_utf8(s, cp);
      }
    }
    out.push_back(std::move(s));
  }
  return out;
}

NpyArray make_npy_strings(const std::vector<std::string>& values, bool scalar) {
  if (scalar && values.size() != 1) throw ModelError("make_npy_strings: a scalar needs 1 string");
  std::vector<std::vector<std::uint32_t>> cps;
  std::size_t width = 1;  // numpy gives '' the dtype <U1
  for (const std::string& v : values) {
    cps.push_back(decode_utf8(v));
    width = std::max(width, cps.back().size());
  }
  NpyArray a;
  a.dtype = "<U" + std::to_string(width);
  if (!scalar) a.shape = {values.size()};
  a.data.assign(values.size() * width * 4, 0);
  for (std::size_t i = 0; i < cps.size(); ++i) {
    for (std::size_t j = 0; j < cps[i].size(); ++j) {
      std::memcpy(a.data.data() + (i * width + j) * 4, &cps[i][j], 4);
    }
  }
  return a;
}

// ---------------------------------------------------------------------------------------------
// .npy bytes.
std::vector<std::uint8_t> npy_bytes(const NpyArray& a) {
  const DtypeInfo info = parse_descr(a.dtype, "npy_bytes");
  if (info.normalized != a.dtype) throw ModelError("npy_bytes: non-normalised dtype " + a.dtype);
  if (a.data.size() != a.size() * info.item_size) {
    throw ModelError("npy_bytes: array of shape " + a.shape_string() + " and dtype " + a.dtype +
                     " has " + std::to_string(a.data.size()) + " data bytes, expected " +
                     std::to_string(a.size() * info.item_size));
  }
  // Same text as numpy 1.24's format._write_array_header (keys sorted, growth padding).
  std::string header = "{'descr': '" + a.dtype +
                       "', 'fortran_order': " + (a.fortran_order ? "True" : "False") +
                       ", 'shape': " + python_tuple(a.shape) + ", }";
  if (!a.shape.empty()) {
    const std::size_t growth = a.fortran_order ? a.shape.back() : a.shape.front();
    const std::size_t digits = std::to_string(growth).size();
    header.append(21 - std::min<std::size_t>(21, digits), ' ');
  }
  const std::size_t hlen = header.size() + 1;
  const std::size_t pad = 64 - ((8 + 2 + hlen) % 64);
  const std::size_t total = hlen + pad;
  if (total > 65535) throw ModelError("npy_bytes: header too long for .npy version 1.0");
  std::string prefix("\x93NUMPY\x01\x00", 8);
  prefix += static_cast<char>(total & 0xFF);
  prefix += static_cast<char>(total >> 8);
  prefix += header;
  prefix.append(pad, ' ');
  prefix += '\n';
  std::vector<std::uint8_t> out;
  out.reserve(prefix.size() + a.data.size());
  for (char c : prefix) out.push_back(static_cast<std::uint8_t>(c));
  out.insert(out.end(), a.data.begin(), a.data.end());
  return out;
}

namespace {

// A parsed .npy header.
struct NpyHeader {
  std::string descr;
  std::vector<std::size_t> shape;
  bool fortran = false;
  std::size_t data_offset = 0;  // bytes before the array data
  bool object = false;          // pickled Python objects (no data is read)
};

// The length of the .npy preamble (magic, version, header length field) and of the header text,
// from the first bytes of a .npy file.
std::size_t preamble_and_header(const std::uint8_t* bytes, std::size_t size,
                                const std::string& context, std::size_t& header_len) {
  static const std::uint8_t magic[] = {0x93, 'N', 'U', 'M', 'P', 'Y'};
  if (size < 10 || std::memcmp(bytes, magic, 6) != 0) {
    fail(context, size < 10 ? "truncated .npy data (" + std::to_string(size) + " bytes)"
                            : "not an .npy array (bad magic bytes)");
  }
  const int major = bytes[6];
  std::size_t offset = 0;
  if (major == 1) {
    header_len = bytes[8] | (static_cast<std::size_t>(bytes[9]) << 8);
    offset = 10;
  } else if (major == 2 || major == 3) {
    if (size < 12) fail(context, "truncated .npy header");
    header_len = bytes[8] | (static_cast<std::size_t>(bytes[9]) << 8) |
                 (static_cast<std::size_t>(bytes[10]) << 16) |
                 (static_cast<std::size_t>(bytes[11]) << 24);
    offset = 12;
  } else {
    fail(context, "unsupported .npy format version " + std::to_string(major));
  }
  if (header_len > (1u << 20)) fail(context, ".npy header longer than 1 MiB");
  return offset;
}

NpyHeader parse_header(const std::uint8_t* bytes, std::size_t size, const std::string& context) {
  std::size_t header_len = 0;
  const std::size_t offset = preamble_and_header(bytes, size, context, header_len);
  if (header_len > size - offset) {
    fail(context, "truncated .npy header (needs " + std::to_string(header_len) + " bytes, " +
                      std::to_string(size - offset) + " present)");
  }
  const std::string header(reinterpret_cast<const char*>(bytes + offset), header_len);
  const Literal dict = LiteralParser(header, context).parse();
  if (dict.kind != Literal::Kind::kDict) fail(context, "bad .npy header: not a dictionary");
  const Literal* descr = nullptr;
  const Literal* fortran = nullptr;
  const Literal* shape = nullptr;
  for (std::size_t i = 0; i + 1 < dict.items.size(); i += 2) {
    const std::string& key = dict.items[i].text;
    if (key == "descr") descr = &dict.items[i + 1];
    if (key == "fortran_order") fortran = &dict.items[i + 1];
    if (key == "shape") shape = &dict.items[i + 1];
  }
  if (!descr || !fortran || !shape) {
    fail(context, "bad .npy header: 'descr', 'fortran_order' and 'shape' are required");
  }
  if (descr->kind != Literal::Kind::kStr) {
    fail(context, "structured dtypes (record arrays) are not supported");
  }
  if (fortran->kind != Literal::Kind::kBool) fail(context, "bad .npy header: fortran_order");
  if (shape->kind != Literal::Kind::kTuple) fail(context, "bad .npy header: shape is no tuple");
  if (shape->items.size() > kMaxDims) fail(context, "bad .npy header: too many dimensions");
  NpyHeader h;
  for (const Literal& d : shape->items) {
    if (d.kind != Literal::Kind::kInt || d.integer < 0) fail(context, "bad .npy header: shape");
    h.shape.push_back(static_cast<std::size_t>(d.integer));
  }
  h.descr = descr->text;
  h.fortran = fortran->integer != 0;
  h.data_offset = offset + header_len;
  const std::string& t = h.descr;
  h.object = t == "|O" || t == "O" || t == "<O" || t == ">O" || t == "|O8" || t == "<O8";
  return h;
}

}  // namespace

std::size_t npy_header_size(const std::uint8_t* bytes, std::size_t size,
                            const std::string& context) {
  std::size_t header_len = 0;
  return preamble_and_header(bytes, size, context, header_len) + header_len;
}

std::size_t npy_declared_size(const std::uint8_t* bytes, std::size_t size,
                              const std::string& context) {
  const NpyHeader h = parse_header(bytes, size, context);
  if (h.object) return 0;
  const DtypeInfo info = parse_descr(h.descr, context);
  std::size_t total = h.data_offset;
  if (std::find(h.shape.begin(), h.shape.end(), 0) != h.shape.end()) return total;
  std::size_t count = info.item_size;
  for (const std::size_t n : h.shape) {
    if (count > std::numeric_limits<std::size_t>::max() / n) {
      fail(context, "array shape is impossibly large");
    }
    count *= n;
  }
  if (count > std::numeric_limits<std::size_t>::max() - total) {
    fail(context, "array shape is impossibly large");
  }
  return total + count;
}

NpyArray parse_npy(const std::uint8_t* bytes, std::size_t size, const std::string& context) {
  NpyHeader h = parse_header(bytes, size, context);
  if (h.object) {
    // Pickled Python objects: not loaded; a placeholder whose accessors explain the conversion.
    NpyArray placeholder;
    placeholder.dtype = "|O";
    placeholder.shape = std::move(h.shape);
    placeholder.fortran_order = h.fortran;
    return placeholder;
  }
  return npy_from_raw(h.descr, std::move(h.shape), h.fortran, bytes + h.data_offset,
                      size - h.data_offset, context);
}

NpyArray npy_from_raw(const std::string& descr, std::vector<std::size_t> shape, bool fortran_order,
                      const std::uint8_t* bytes, std::size_t size, const std::string& context) {
  if (shape.size() > kMaxDims) fail(context, "array has too many dimensions");
  const DtypeInfo info = parse_descr(descr, context);
  NpyArray a;
  a.dtype = info.normalized;
  a.fortran_order = fortran_order;
  a.shape = std::move(shape);
  // Element count; an array with a zero-length axis is empty whatever the other axes say.
  const bool empty = std::find(a.shape.begin(), a.shape.end(), 0) != a.shape.end();
  std::size_t count = empty ? 0 : 1;
  bool overflow = false;
  for (const std::size_t n : a.shape) {
    if (empty || overflow) break;
    if (count > std::numeric_limits<std::size_t>::max() / n) overflow = true;
    count *= n;
  }
  if (overflow ||
      (count != 0 && info.item_size > std::numeric_limits<std::size_t>::max() / count)) {
    fail(context, "array shape " + a.shape_string() + " is impossibly large");
  }
  const std::size_t nbytes = count * info.item_size;
  if (size < nbytes) {
    fail(context, "truncated array data: shape " + a.shape_string() + " of " + descr + " needs " +
                      std::to_string(nbytes) + " bytes, " + std::to_string(size) + " present");
  }
  a.data.assign(bytes, bytes + nbytes);
  if (info.swap_unit > 1) {
    for (std::size_t i = 0; i + info.swap_unit <= nbytes; i += info.swap_unit) {
      std::reverse(a.data.begin() + static_cast<std::ptrdiff_t>(i),
                   a.data.begin() + static_cast<std::ptrdiff_t>(i + info.swap_unit));
    }
  }
  return a;
}

std::vector<std::uint8_t> read_file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open the file for reading (does it exist, is it readable?)");
  in.seekg(0, std::ios::end);
  const std::streamoff end = in.tellg();
  if (end < 0) fail(path, "cannot determine the file size");
  in.seekg(0, std::ios::beg);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(end));
  if (!bytes.empty() &&
      !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(end))) {
    fail(path, "read error");
  }
  return bytes;
}

void write_file_bytes(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  write_file_atomic(path,
                    std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

NpyArray read_npy(const std::string& path) {
  const std::vector<std::uint8_t> bytes = read_file_bytes(path);
  return parse_npy(bytes.data(), bytes.size(), path);
}

void write_npy(const std::string& path, const NpyArray& array) {
  write_file_bytes(path, npy_bytes(array));
}

}  // namespace smpl
