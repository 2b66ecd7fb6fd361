// .npy / .npz reading and writing (smpl/npz.hpp): round trips for every dtype, numpy reading what
// we write (and our .npy bytes equal np.save's), memory order, zip64, malformed archives.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "io_test_util.hpp"
#include "smpl/npz.hpp"

namespace {

using smpl::ModelError;
using smpl::NpyArray;
using smpl::NpzArchive;

std::string data_dir() {
  std::string d = std::string(CALIPER_TEST_DATA_DIR) + "/smpl_npz";
  caliper::test::run_command("mkdir -p '" + d + "'");
  return d;
}

// Expects `f` to throw ModelError whose message contains every one of `parts`.
template <typename F>
void expect_error(const F& f, std::initializer_list<std::string> parts) {
  try {
    f();
    ADD_FAILURE() << "no ModelError";
  } catch (const ModelError& e) {
    for (const std::string& p : parts) {
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos)
          << "'" << p << "' not in: " << e.what();
    }
  }
}

NpzArchive every_dtype() {
  NpzArchive z;
  z["f8"] = smpl::make_npy(std::vector<double>{1.5, -2.25, 1e300, -0.0, 3.0, 4.0}, {2, 3});
  z["f4"] = smpl::make_npy(std::vector<float>{1.5f, -2.25f, 3.0f}, {3});
  z["i8"] = smpl::make_npy(
      std::vector<std::int64_t>{std::numeric_limits<std::int64_t>::min(), -1, 7}, {3, 1});
  z["i4"] = smpl::make_npy(std::vector<std::int32_t>{-5, 6}, {2});
  z["i2"] = smpl::make_npy(std::vector<std::int16_t>{-300, 300}, {2});
  z["i1"] = smpl::make_npy(std::vector<std::int8_t>{-3, 4}, {2});
  z["u8"] = smpl::make_npy(std::vector<std::uint64_t>{5, 6}, {2});
  z["u4"] = smpl::make_npy(std::vector<std::uint32_t>{4294967295u, 2}, {2});
  z["u2"] = smpl::make_npy(std::vector<std::uint16_t>{65535, 2}, {2});
  z["u1"] = smpl::make_npy(std::vector<std::uint8_t>{255, 0}, {2});
  z["b1"] = smpl::make_npy(std::vector<bool>{true, false, true}, {3});
  z["scalar"] = smpl::make_npy(std::vector<double>{42.0}, {});
  z["empty"] = smpl::make_npy(std::vector<double>{}, {0, 3});
  z["text"] = smpl::make_npy_strings({"pelvis", "", "h\xc3\xa9llo"});
  z["text0"] = smpl::make_npy_strings({"caliper"}, true);
  return z;
}

TEST(Npz, RoundTripsEveryDtypeStoredAndDeflated) {
  const NpzArchive z = every_dtype();
  for (bool compress : {false, true}) {
    const std::vector<std::uint8_t> bytes = smpl::npz_bytes(z, compress);
    const NpzArchive back = smpl::parse_npz(bytes.data(), bytes.size(), "mem");
    ASSERT_EQ(back.size(), z.size());
    for (const auto& [key, a] : z) {
      SCOPED_TRACE(key);
      const NpyArray& b = back.at(key);
      EXPECT_EQ(b.dtype, a.dtype);
      EXPECT_EQ(b.shape, a.shape);
      EXPECT_EQ(b.fortran_order, a.fortran_order);
      EXPECT_EQ(b.data, a.data);
    }
  }
}

TEST(Npz, TypedAccessors) {
  const NpzArchive z = every_dtype();
  EXPECT_EQ(z.at("u4").to_int64(), (std::vector<std::int64_t>{4294967295LL, 2}));
  EXPECT_EQ(z.at("b1").to_double(), (std::vector<double>{1, 0, 1}));
  EXPECT_EQ(z.at("i1").to_double(), (std::vector<double>{-3, 4}));
  EXPECT_EQ(z.at("text").to_strings(), (std::vector<std::string>{"pelvis", "", "h\xc3\xa9llo"}));
  EXPECT_EQ(z.at("text").dtype, "<U6");
  EXPECT_EQ(z.at("text0").to_strings(), (std::vector<std::string>{"caliper"}));
  EXPECT_EQ(z.at("scalar").size(), 1u);
  EXPECT_THROW(z.at("text").to_double(), ModelError);
  EXPECT_THROW(z.at("f8").to_int64(), ModelError);  // 1.5 is not an integer
}

TEST(Npz, OutputIsDeterministic) {
  const NpzArchive z = every_dtype();
  EXPECT_EQ(smpl::npz_bytes(z), smpl::npz_bytes(z));
  EXPECT_EQ(smpl::npz_bytes(z, true), smpl::npz_bytes(z, true));
}

// The container fields the committed models carry (docs/file-formats.md, libsmpl/src/zip.cpp's
// header), field by field, stored and deflated: minizip writes them, so this catches a minizip
// (or a call) that writes anything else, also for stored members, which the models' cmp in CI
// does not cover.
TEST(Npz, WritesTheModelsContainerFields) {
  NpzArchive z;
  z["a"] = smpl::make_npy(std::vector<double>{1.0, 2.0, 3.0}, {3});
  z["bb"] = smpl::make_npy(std::vector<std::int32_t>{7}, {1});
  auto le = [](const std::vector<std::uint8_t>& b, std::size_t pos, int n) {
    std::uint64_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = (v << 8) | b.at(pos + i);
    return v;
  };
  for (bool compress : {false, true}) {
    SCOPED_TRACE(compress ? "deflated" : "stored");
    const std::vector<std::uint8_t> b = smpl::npz_bytes(z, compress);
    const std::uint64_t method = compress ? 8 : 0;
    // End of central directory: the last 22 bytes (no comment, no zip64 records).
    ASSERT_GE(b.size(), 22u);
    const std::size_t eocd = b.size() - 22;
    EXPECT_EQ(le(b, eocd, 4), 0x06054b50u);
    EXPECT_EQ(le(b, eocd + 4, 4), 0u);  // disk numbers
    EXPECT_EQ(le(b, eocd + 8, 2), 2u);
    EXPECT_EQ(le(b, eocd + 10, 2), 2u);
    EXPECT_EQ(le(b, eocd + 20, 2), 0u);  // comment length
    const std::size_t cd_offset = le(b, eocd + 16, 4);
    EXPECT_EQ(cd_offset + le(b, eocd + 12, 4), eocd);
    std::size_t local = 0, central = cd_offset;
    for (const std::string name : {"a.npy", "bb.npy"}) {
      SCOPED_TRACE(name);
      const std::vector<std::uint8_t> npy = smpl::npy_bytes(z.at(name.substr(0, name.size() - 4)));
      // Local header: version 2.0, no flags, method, DOS time 0 and date 1980-01-01, no extra.
      EXPECT_EQ(le(b, local, 4), 0x04034b50u);
      EXPECT_EQ(le(b, local + 4, 2), 20u);
      EXPECT_EQ(le(b, local + 6, 2), 0u);
      EXPECT_EQ(le(b, local + 8, 2), method);
      EXPECT_EQ(le(b, local + 10, 2), 0u);
      EXPECT_EQ(le(b, local + 12, 2), 0x0021u);
      EXPECT_EQ(le(b, local + 22, 4), npy.size());
      EXPECT_EQ(le(b, local + 26, 2), name.size());
      EXPECT_EQ(le(b, local + 28, 2), 0u);
      EXPECT_EQ(std::string(b.begin() + local + 30, b.begin() + local + 30 + name.size()), name);
      const std::uint64_t payload = le(b, local + 18, 4);
      if (!compress) {
        EXPECT_EQ(payload, npy.size());
      }
      // Central entry: made by 2.0 MS-DOS, the local header's fields, no extra, comment or
      // attributes, the local header's offset.
      EXPECT_EQ(le(b, central, 4), 0x02014b50u);
      EXPECT_EQ(le(b, central + 4, 2), 20u);
      for (int f = 0; f < 26; ++f) EXPECT_EQ(b.at(central + 6 + f), b.at(local + 4 + f)) << f;
      EXPECT_EQ(le(b, central + 32, 2), 0u);  // comment length
      EXPECT_EQ(le(b, central + 34, 8), 0u);  // disk, internal and external attributes
      EXPECT_EQ(le(b, central + 42, 4), local);
      local += 30 + name.size() + payload;
      central += 46 + name.size();
    }
    EXPECT_EQ(local, cd_offset);  // no data descriptors
    EXPECT_EQ(central, eocd);
  }
}

TEST(Npy, FortranOrderIsConvertedToCOrder) {
  // A 2 x 3 x 2 array a[i][j][k] = 100 i + 10 j + k stored in Fortran order (i fastest).
  std::vector<double> fortran;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 2; ++i) fortran.push_back(100 * i + 10 * j + k);
  NpyArray a = smpl::make_npy(fortran, {2, 3, 2});
  a.fortran_order = true;
  std::vector<double> expected;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 2; ++k) expected.push_back(100 * i + 10 * j + k);
  EXPECT_EQ(a.to_double(), expected);
  EXPECT_EQ(a.c_order().to_double(), expected);
  EXPECT_FALSE(a.c_order().fortran_order);
}

// numpy reads what we write (stored and deflated), with allow_pickle=False, and our .npy bytes
// are exactly np.save's for the same array.
TEST(Npz, NumpyReadsOurFilesAndWritesTheSameNpyBytes) {
  const std::string dir = data_dir();
  const NpzArchive z = every_dtype();
  smpl::write_npz(dir + "/ours.npz", z);
  smpl::write_npz(dir + "/ours_deflated.npz", z, true);
  for (const auto& [key, a] : z) smpl::write_npy(dir + "/ours_" + key + ".npy", a);
  const std::string program = R"PY(
import io, sys, zipfile
import numpy as np
d = sys.argv[1]
expected = {
    'f8': np.array([[1.5, -2.25, 1e300], [-0.0, 3.0, 4.0]]),
    'f4': np.array([1.5, -2.25, 3.0], dtype=np.float32),
    'i8': np.array([[np.iinfo(np.int64).min], [-1], [7]], dtype=np.int64),
    'i4': np.array([-5, 6], dtype=np.int32), 'i2': np.array([-300, 300], dtype=np.int16),
    'i1': np.array([-3, 4], dtype=np.int8), 'u8': np.array([5, 6], dtype=np.uint64),
    'u4': np.array([4294967295, 2], dtype=np.uint32), 'u2': np.array([65535, 2], dtype=np.uint16),
    'u1': np.array([255, 0], dtype=np.uint8), 'b1': np.array([True, False, True]),
    'scalar': np.array(42.0), 'empty': np.zeros((0, 3)),
    'text': np.array(['pelvis', '', 'h\u00e9llo']), 'text0': np.array('caliper'),
}
for name in ('ours.npz', 'ours_deflated.npz'):
    z = np.load(d + '/' + name, allow_pickle=False)
    assert sorted(z.files) == sorted(expected), z.files
    for k, v in expected.items():
        a = z[k]
        assert a.dtype == v.dtype and a.shape == v.shape, (name, k, a.dtype, a.shape)
        assert a.tobytes() == v.tobytes(), (name, k)
    assert zipfile.ZipFile(d + '/' + name).testzip() is None
for k, v in expected.items():
    buf = io.BytesIO()
    np.save(buf, v)
    ours = open(d + '/ours_' + k + '.npy', 'rb').read()
    assert ours == buf.getvalue(), (k, ours[:128], buf.getvalue()[:128])
print('numpy agrees')
)PY";
  EXPECT_EQ(caliper::test::run_python(program, "'" + dir + "'"), 0);
}

// Fortran order, big-endian and mixed dtypes written by numpy, stored and deflated.
TEST(Npz, ReadsWhatNumpyWrites) {
  const std::string dir = data_dir();
  const std::string program = R"PY(
import sys
import numpy as np
d = sys.argv[1]
a = np.arange(24, dtype=np.float64).reshape(2, 3, 4) * 0.5
kw = dict(c=a, f=np.asfortranarray(a), f4f=np.asfortranarray(a.astype(np.float32)),
          be=a.astype('>f8'), bei=np.arange(6, dtype='>i4').reshape(2, 3),
          u4=np.array([4294967295, 1], dtype=np.uint32), b=np.array(True),
          s=np.array([b'ab', b'c']), u=np.array(['x', 'yz']))
np.savez(d + '/np_stored.npz', **kw)
np.savez_compressed(d + '/np_deflated.npz', **kw)
)PY";
  ASSERT_EQ(caliper::test::run_python(program, "'" + dir + "'"), 0);
  std::vector<double> expected(24);
  for (int i = 0; i < 24; ++i) expected[static_cast<std::size_t>(i)] = 0.5 * i;
  for (const char* name : {"np_stored.npz", "np_deflated.npz"}) {
    SCOPED_TRACE(name);
    const NpzArchive z = smpl::read_npz(dir + "/" + name);
    EXPECT_EQ(z.at("c").to_double(), expected);
    EXPECT_TRUE(z.at("f").fortran_order);
    EXPECT_EQ(z.at("f").to_double(), expected);
    EXPECT_EQ(z.at("f4f").dtype, "<f4");
    EXPECT_EQ(z.at("f4f").to_double(), expected);
    EXPECT_EQ(z.at("be").dtype, "<f8");  // converted from big-endian
    EXPECT_EQ(z.at("be").to_double(), expected);
    EXPECT_EQ(z.at("bei").to_int64(), (std::vector<std::int64_t>{0, 1, 2, 3, 4, 5}));
    EXPECT_EQ(z.at("u4").to_int64(), (std::vector<std::int64_t>{4294967295LL, 1}));
    EXPECT_EQ(z.at("b").shape.size(), 0u);
    EXPECT_EQ(z.at("b").to_double(), std::vector<double>{1.0});
    EXPECT_EQ(z.at("s").to_strings(), (std::vector<std::string>{"ab", "c"}));
    EXPECT_EQ(z.at("u").to_strings(), (std::vector<std::string>{"x", "yz"}));
  }
}

// ---------------------------------------------------------------------------------------------
// Malformed .npy headers.
std::vector<std::uint8_t> npy_with_header(const std::string& header, std::size_t data_bytes) {
  std::vector<std::uint8_t> b = {0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0};
  b.push_back(static_cast<std::uint8_t>(header.size() & 0xFF));
  b.push_back(static_cast<std::uint8_t>(header.size() >> 8));
  b.insert(b.end(), header.begin(), header.end());
  b.insert(b.end(), data_bytes, 0);
  return b;
}

TEST(Npy, BadHeadersGiveClearErrors) {
  auto parse = [](const std::vector<std::uint8_t>& b) {
    return [b] { smpl::parse_npy(b.data(), b.size(), "x.npy"); };
  };
  expect_error(parse({'n', 'o', 'p', 'e', 0, 0, 0, 0, 0, 0, 0}), {"x.npy", "bad magic"});
  // Object arrays: a placeholder without data whose accessors explain the conversion.
  const std::vector<std::uint8_t> obj =
      npy_with_header("{'descr': '|O', 'fortran_order': False, 'shape': (2,), }", 16);
  const NpyArray placeholder = smpl::parse_npy(obj.data(), obj.size(), "x.npy");
  EXPECT_EQ(placeholder.dtype, "|O");
  EXPECT_TRUE(placeholder.data.empty());
  expect_error([&] { placeholder.to_double(); }, {"object array", "todense()"});
  expect_error([&] { placeholder.to_strings(); }, {"object array"});
  expect_error([&] { smpl::npy_bytes(placeholder); }, {"object array"});
  expect_error(
      parse(npy_with_header("{'descr': '<c16', 'fortran_order': False, 'shape': (1,), }", 16)),
      {"unsupported dtype '<c16'"});
  expect_error(parse(npy_with_header(
                   "{'descr': [('a', '<f8')], 'fortran_order': False, 'shape': (1,), }", 8)),
               {"structured"});
  expect_error(
      parse(npy_with_header("{'descr': '<f8', 'fortran_order': False, 'shape': (3,), }", 16)),
      {"truncated", "needs 24 bytes, 16 present"});
  expect_error(parse(npy_with_header("{'descr': '<f8', 'fortran_order': False, "
                                     "'shape': (4294967296, 4294967296, 4294967296), }",
                                     0)),
               {"impossibly large"});
  expect_error(parse(npy_with_header("{'descr': '<f8', 'shape': (1,), }", 8)), {"'fortran_order'"});
  expect_error(parse(npy_with_header("{'descr': '<f8', 'fortran_order': False, 'shape': (1,", 8)),
               {"bad .npy header"});
  expect_error(
      parse(npy_with_header("{'descr': '<f8', 'fortran_order': False, 'shape': (-1,), }", 8)),
      {"bad .npy header"});
  std::vector<std::uint8_t> short_header = npy_with_header("{}", 0);
  short_header[8] = 200;  // claims 200 header bytes
  expect_error(parse(short_header), {"truncated .npy header"});
}

// ---------------------------------------------------------------------------------------------
// Malformed zip archives.
TEST(Npz, BadArchivesGiveClearErrors) {
  NpzArchive z;
  z["a"] = smpl::make_npy(std::vector<double>{1, 2, 3}, {3});
  const std::vector<std::uint8_t> good = smpl::npz_bytes(z);
  auto parse = [](const std::vector<std::uint8_t>& b) {
    return [b] { smpl::parse_npz(b.data(), b.size(), "m.npz"); };
  };
  expect_error(parse({}), {"m.npz", "truncated or not a zip"});
  expect_error(parse(std::vector<std::uint8_t>(100, 'x')),
               {"m.npz", "no end-of-central-directory"});
  std::vector<std::uint8_t> crc = good;
  crc[30 + 5 + 100] ^= 1;  // a byte of the member's npy data
  expect_error(parse(crc), {"m.npz", "member 'a.npy'", "CRC-32 mismatch"});
  std::vector<std::uint8_t> method = good;
  method[8] = 12;                           // local header: bzip2
  method[good.size() - 22 - 51 + 10] = 12;  // central directory entry
  expect_error(parse(method), {"unsupported zip compression method 12"});
  std::vector<std::uint8_t> cut(good.begin(), good.end() - 30);
  expect_error(parse(cut), {"m.npz"});
  // The central directory claims more data than the file holds.
  std::vector<std::uint8_t> big = good;
  big[good.size() - 22 - 51 + 20] = 0xFF;
  big[good.size() - 22 - 51 + 24] = 0xFF;
  expect_error(parse(big), {"m.npz", "a.npy"});
}

// A deflate "bomb": the directory claims far more output than the input can produce.
TEST(Npz, ImplausibleUncompressedSizeIsRefused) {
  NpzArchive z;
  z["a"] = smpl::make_npy(std::vector<double>(1000, 0.0), {1000});
  std::vector<std::uint8_t> b = smpl::npz_bytes(z, true);
  const std::size_t cd = b.size() - 22 - 51;
  for (std::size_t off : {std::size_t{22}, cd + 24}) {
    b[off] = 0xFF;
    b[off + 1] = 0xFF;
    b[off + 2] = 0xFF;
    b[off + 3] = 0x7F;
  }
  expect_error([&] { smpl::parse_npz(b.data(), b.size(), "bomb.npz"); },
               {"bomb.npz", "more than deflate can produce"});
}

// The directory's uncompressed size disagrees with what the deflate stream gives: the .npy header
// (inflated first) declares the real size, so the mismatch is found before the data is inflated.
TEST(Npz, DeflateSizeMismatchIsAnError) {
  NpzArchive z;
  z["a"] = smpl::make_npy(std::vector<double>(1000, 1.0), {1000});
  const std::vector<std::uint8_t> good = smpl::npz_bytes(z, true);
  const std::size_t cd = good.size() - 22 - 51;
  const std::uint32_t real = 128 + 8000;  // .npy header + data
  for (std::uint32_t claimed : {real - 10, real + 10}) {
    std::vector<std::uint8_t> b = good;
    for (std::size_t off : {std::size_t{22}, cd + 24}) {
      for (int i = 0; i < 4; ++i)
        b[off + static_cast<std::size_t>(i)] = (claimed >> (8 * i)) & 0xFF;
    }
    expect_error([&] { smpl::parse_npz(b.data(), b.size(), "size.npz"); },
                 {"size.npz", "a.npy", "the zip directory says " + std::to_string(claimed),
                  "the .npy header declares " + std::to_string(real)});
  }
}

// zip64: sizes and offset in the central directory's zip64 extra field, zip64 end records.
TEST(Npz, ReadsZip64Records) {
  NpzArchive z;
  z["a"] = smpl::make_npy(std::vector<double>{1, 2, 3}, {3});
  const std::vector<std::uint8_t> plain = smpl::npz_bytes(z);
  // Rebuild the archive by hand: same local header and data, then a zip64 central directory.
  const std::size_t cd = plain.size() - 22 - 51;
  std::vector<std::uint8_t> b(plain.begin(), plain.begin() + static_cast<std::ptrdiff_t>(cd));
  auto put = [&b](std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  const std::uint64_t size = cd - 30 - 5;
  const std::uint64_t cd_offset = b.size();
  std::vector<std::uint8_t> entry(plain.begin() + static_cast<std::ptrdiff_t>(cd),
                                  plain.begin() + static_cast<std::ptrdiff_t>(cd) + 46);
  for (int i = 20; i < 28; ++i) entry[static_cast<std::size_t>(i)] = 0xFF;  // sizes -> zip64
  for (int i = 42; i < 46; ++i) entry[static_cast<std::size_t>(i)] = 0xFF;  // offset -> zip64
  entry[30] = 28;                                                           // extra length
  b.insert(b.end(), entry.begin(), entry.end());
  b.insert(b.end(), {'a', '.', 'n', 'p', 'y'});
  put(0x0001, 2);
  put(24, 2);
  put(size, 8);
  put(size, 8);
  put(0, 8);
  const std::uint64_t cd_size = b.size() - cd_offset;
  const std::uint64_t end64 = b.size();
  put(0x06064b50, 4);
  put(44, 8);
  put(45, 2);
  put(45, 2);
  put(0, 4);
  put(0, 4);
  put(1, 8);
  put(1, 8);
  put(cd_size, 8);
  put(cd_offset, 8);
  put(0x07064b50, 4);
  put(0, 4);
  put(end64, 8);
  put(1, 4);
  put(0x06054b50, 4);
  put(0, 2);
  put(0, 2);
  put(0xFFFF, 2);
  put(0xFFFF, 2);
  put(0xFFFFFFFF, 4);
  put(0xFFFFFFFF, 4);
  put(0, 2);
  const NpzArchive back = smpl::parse_npz(b.data(), b.size(), "zip64.npz");
  EXPECT_EQ(back.at("a").to_double(), (std::vector<double>{1, 2, 3}));
}

}  // namespace
