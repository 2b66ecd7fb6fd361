// Issue 10: pickle errors a user can act on. A truncated file names the key being read and the
// bytes missing; names read from the file are escaped before they are printed; a Git LFS pointer
// is recognised as such.
#include <gtest/gtest.h>

#include <string>

#include "smpl/io.hpp"
#include "smpl/pickle.hpp"

namespace {

using smpl::ModelError;

std::string error_of(const std::string& s, const std::string& context = "t.pkl") {
  try {
    smpl::parse_pickle(reinterpret_cast<const std::uint8_t*>(s.data()), s.size(), context);
  } catch (const ModelError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string model_error_of(const std::string& s) {
  try {
    smpl::load_model_from_memory(reinterpret_cast<const std::uint8_t*>(s.data()), s.size(),
                                 "m.pkl");
  } catch (const ModelError& e) {
    return e.what();
  }
  return "(no error)";
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

bool printable_ascii(const std::string& s) {
  for (const char c : s)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) return false;
  return true;
}

// Protocol-2 opcodes as Python 2's cPickle writes them (see test_pickle.cpp).
std::string str(const std::string& s) {  // SHORT_BINSTRING
  return "U" + std::string(1, static_cast<char>(s.size())) + s;
}
std::string int1(int v) {
  return "K" + std::string(1, static_cast<char>(v));
}
std::string ndarray_f8(int n, const std::string& raw) {
  const std::string dtype = "cnumpy\ndtype\n(" + str("f8") + int1(0) + int1(1) + "tR(" + int1(3) +
                            str("<") + "NNNJ\xff\xff\xff\xffJ\xff\xff\xff\xff" + int1(0) + "tb";
  return "cnumpy.core.multiarray\n_reconstruct\ncnumpy\nndarray\n" + int1(0) + "\x85" + str("b") +
         "\x87R(" + int1(1) + "(" + int1(n) + "t" + dtype + "\x89" + str(raw) + "tb";
}
std::string doubles(int n) {
  std::string s;
  for (int i = 0; i < n; ++i) {
    const double d = i;
    s.append(reinterpret_cast<const char*>(&d), sizeof d);
  }
  return s;
}

TEST(PickleErrors, TruncatedNamesTheKeyAndTheMissingBytes) {
  const std::string raw = doubles(4);  // 32 bytes
  const std::string full = "\x80\x02}(" + str("v_template") + ndarray_f8(2, doubles(2)) +
                           str("shapedirs") + ndarray_f8(4, raw) + "u.";
  ASSERT_EQ(error_of(full), "(no error)");
  // Cut 10 bytes into shapedirs' 32 data bytes: 22 are missing.
  const size_t data = full.rfind(raw);
  const std::string e = error_of(full.substr(0, data + 10), "SMPL_MALE.pkl");
  EXPECT_TRUE(contains(e, "SMPL_MALE.pkl: truncated pickle")) << e;
  EXPECT_TRUE(contains(e, "'shapedirs'")) << e;
  EXPECT_TRUE(contains(e, "22 bytes short")) << e;
  EXPECT_TRUE(contains(e, "ends at byte " + std::to_string(data + 10))) << e;
  // Cut inside the first array: the key is v_template.
  const std::string e2 = error_of(full.substr(0, full.find(doubles(2)) + 3));
  EXPECT_TRUE(contains(e2, "'v_template'")) << e2;
  EXPECT_TRUE(contains(e2, "13 bytes short")) << e2;
  // Cut before any key.
  EXPECT_TRUE(contains(error_of(full.substr(0, 4)), "before the first key"))
      << error_of(full.substr(0, 4));
}

TEST(PickleErrors, EscapesNamesFromTheFile) {
  // A refused class whose name carries a terminal escape and a raw byte.
  const std::string e =
      error_of("\x80\x02}(" + str("a") + "cos\x1b[2J\nsys\xfftem\n" + str("ls") + "\x85Ru.");
  EXPECT_TRUE(contains(e, "refused")) << e;
  EXPECT_TRUE(contains(e, "os\\x1b[2J.sys\\xfftem")) << e;
  EXPECT_TRUE(printable_ascii(e)) << e;
  // A key with a terminal title escape, listed by the model loader's "missing key" error.
  const std::string m =
      model_error_of("\x80\x02}(" + str("\x1b]0;owned\x07") + ndarray_f8(1, doubles(1)) + "u.");
  EXPECT_TRUE(contains(m, "missing key")) << m;
  EXPECT_TRUE(contains(m, "\\x1b]0;owned\\x07")) << m;
  EXPECT_TRUE(printable_ascii(m)) << m;
  EXPECT_EQ(smpl::printable("a\\b\n\xc3\xa9"), "a\\\\b\\x0a\\xc3\\xa9");
}

TEST(PickleErrors, RecognisesAGitLfsPointer) {
  const std::string pointer =
      "version https://git-lfs.github.com/spec/v1\n"
      "oid sha256:4d7a214614ab2935c943f9e0ff69d22eadbb8f32b1258daaa5e2ca24d17e2393\n"
      "size 39001280\n";
  EXPECT_TRUE(contains(error_of(pointer, "SMPL_FEMALE.pkl"),
                       "SMPL_FEMALE.pkl: this is a Git LFS "
                       "pointer file"))
      << error_of(pointer);
  EXPECT_TRUE(contains(error_of(pointer), "git lfs pull")) << error_of(pointer);
  EXPECT_TRUE(contains(model_error_of(pointer), "git lfs pull")) << model_error_of(pointer);
}

}  // namespace
