// The restricted unpickler (smpl/pickle.hpp) on opcode streams written by hand: what it builds,
// what it refuses (by name), and that malformed streams give a ModelError, never a crash.
#include <gtest/gtest.h>

#include <cstring>

#include "smpl/pickle.hpp"

namespace {

using smpl::ModelError;
using smpl::PickleDict;
using smpl::PickleValue;

PickleDict parse(const std::string& s, const std::string& context = "t.pkl") {
  return smpl::parse_pickle(reinterpret_cast<const std::uint8_t*>(s.data()), s.size(), context);
}

std::string error_of(const std::string& s) {
  try {
    parse(s);
  } catch (const ModelError& e) {
    return e.what();
  }
  return "(no error)";
}

// Opcode helpers (protocol 2, as Python 2's cPickle writes them, without memo).
std::string u32(std::uint32_t v) {
  std::string s(4, '\0');
  for (int i = 0; i < 4; ++i) s[static_cast<std::size_t>(i)] = static_cast<char>(v >> (8 * i));
  return s;
}
std::string str(const std::string& s) {  // SHORT_BINSTRING / BINSTRING
  if (s.size() < 256) return "U" + std::string(1, static_cast<char>(s.size())) + s;
  return "T" + u32(static_cast<std::uint32_t>(s.size())) + s;
}
std::string int1(int v) {
  return "K" + std::string(1, static_cast<char>(v));
}
std::string dtype(const std::string& body, const std::string& order) {
  return "cnumpy\ndtype\n(" + str(body) + int1(0) + int1(1) + "tR(" + int1(3) + str(order) +
         "NNNJ" + u32(0xFFFFFFFF) + "J" + u32(0xFFFFFFFF) + int1(0) + "tb";
}
std::string ndarray(const std::string& body, const std::string& order,
                    const std::vector<int>& shape, const std::string& raw, bool fortran = false,
                    const std::string& module = "numpy.core.multiarray") {
  std::string s = "c" + module + "\n_reconstruct\ncnumpy\nndarray\n" + int1(0) + "\x85" + str("b") +
                  "\x87R(" + int1(1) + "(";
  for (int d : shape) s += int1(d);
  s += "t" + dtype(body, order) + (fortran ? "\x88" : "\x89") + str(raw) + "tb";
  return s;
}
std::string doubles(std::initializer_list<double> v) {
  std::string s;
  for (double d : v) s.append(reinterpret_cast<const char*>(&d), sizeof(d));
  return s;
}
std::string dict(const std::string& items) {
  return "\x80\x02}(" + items + "u.";
}

TEST(Pickle, ScalarsStringsAndContainers) {
  double half = 0.5;
  std::string be(8, '\0');
  std::uint64_t bits;
  std::memcpy(&bits, &half, 8);
  for (int i = 0; i < 8; ++i)
    be[static_cast<std::size_t>(i)] = static_cast<char>(bits >> (56 - 8 * i));
  const PickleDict d =
      parse(dict(str("i") + int1(5) + str("j") + "J" + u32(0xFFFFFFFF) + str("g") + "G" + be +
                 str("s") + str("lbs") + str("n") + "N" + str("t") + "\x88" + str("l") +
                 "](K\x01K\x02"
                 "e" +
                 str("x") +
                 "\x8c\x03"
                 "abc" +
                 str("y") + std::string("C\x02\x00\x01", 4)));
  EXPECT_EQ(d.at("i").number, 5.0);
  EXPECT_EQ(d.at("j").number, -1.0);
  EXPECT_EQ(d.at("g").number, 0.5);
  EXPECT_EQ(d.at("s").kind, PickleValue::Kind::kText);
  EXPECT_EQ(d.at("s").text, "lbs");
  EXPECT_EQ(d.at("n").kind, PickleValue::Kind::kOther);
  EXPECT_EQ(d.at("t").number, 1.0);
  EXPECT_EQ(d.at("l").kind, PickleValue::Kind::kOther);
  EXPECT_EQ(d.at("l").type_name, "list");
  EXPECT_EQ(d.at("x").text, "abc");
  EXPECT_EQ(d.at("y").text, std::string("\x00\x01", 2));
}

TEST(Pickle, ArraysWithEveryByteOrderAndMemoryOrder) {
  const std::string c = doubles({1, 2, 3, 4, 5, 6});
  std::string big = c;
  for (std::size_t i = 0; i < big.size(); i += 8)
    std::reverse(big.begin() + i, big.begin() + i + 8);
  const PickleDict d = parse(dict(str("c") + ndarray("f8", "<", {2, 3}, c) + str("big") +
                                  ndarray("f8", ">", {2, 3}, big) + str("fortran") +
                                  ndarray("f8", "<", {3, 2}, c, true) + str("u4") +
                                  ndarray("u4", "<", {2}, u32(0xFFFFFFFF) + u32(7)) + str("np2") +
                                  ndarray("f8", "<", {2, 3}, c, false, "numpy._core.multiarray")));
  EXPECT_EQ(d.at("c").array.to_double(), (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(d.at("big").array.to_double(), (std::vector<double>{1, 2, 3, 4, 5, 6}));
  // Fortran data 1..6 for shape (3, 2): column 0 is 1 2 3, column 1 is 4 5 6.
  EXPECT_EQ(d.at("fortran").array.to_double(), (std::vector<double>{1, 4, 2, 5, 3, 6}));
  EXPECT_EQ(d.at("u4").array.to_int64(), (std::vector<std::int64_t>{4294967295LL, 7}));
  EXPECT_EQ(d.at("np2").array.to_double(), (std::vector<double>{1, 2, 3, 4, 5, 6}));
}

TEST(Pickle, MemoSharesObjects) {
  // The same array under two keys through BINPUT / BINGET, and MEMOIZE (protocol 4).
  const std::string a = ndarray("i4", "<", {1}, u32(9));
  const PickleDict d = parse(dict(str("a") + a + "q\x07" + str("b") + "h\x07"));
  EXPECT_EQ(d.at("b").array.to_int64(), std::vector<std::int64_t>{9});
  const PickleDict d4 =
      parse(std::string("\x80\x04\x95\x05\x00\x00\x00\x00\x00\x00\x00}\x94(\x8c\x01k\x94", 18) +
            int1(3) + "\x8c\x01m\x94h\x01u.");
  EXPECT_EQ(d4.at("k").number, 3.0);
  EXPECT_EQ(d4.at("m").text, "k");
}

TEST(Pickle, ChumpyAndSparseMatrices) {
  const std::string ch = "cchumpy.ch\nCh\n)\x81}(" + str("x") +
                         ndarray("f8", "<", {2}, doubles({7, 8})) + str("_dirty_vars") +
                         "c__builtin__\nset\n](" + str("x") + "e\x85R" + str("_itr") + "Nub";
  // csc 2 x 3: column 0 has (1, 0) = 5; column 2 has (0, 2) = 6.
  const std::string csc = "cscipy.sparse.csc\ncsc_matrix\n)\x81}(" + str("format") + str("csc") +
                          str("_shape") + int1(2) + int1(3) + "\x86" + str("indptr") +
                          ndarray("i4", "<", {4}, u32(0) + u32(1) + u32(1) + u32(2)) +
                          str("indices") + ndarray("i4", "<", {2}, u32(1) + u32(0)) + str("data") +
                          ndarray("f8", "<", {2}, doubles({5, 6})) + str("maxprint") + int1(50) +
                          "ub";
  const PickleDict d = parse(dict(str("shapedirs") + ch + str("J_regressor") + csc));
  EXPECT_EQ(d.at("shapedirs").kind, PickleValue::Kind::kArray);
  EXPECT_EQ(d.at("shapedirs").type_name, "chumpy.ch.Ch");
  EXPECT_EQ(d.at("shapedirs").array.to_double(), (std::vector<double>{7, 8}));
  const smpl::SparseNpy& s = d.at("J_regressor").sparse;
  EXPECT_EQ(d.at("J_regressor").kind, PickleValue::Kind::kSparse);
  EXPECT_EQ(s.format, "csc");
  EXPECT_EQ(s.rows, 2u);
  EXPECT_EQ(s.cols, 3u);
  EXPECT_EQ(s.indices.to_int64(), (std::vector<std::int64_t>{1, 0}));
  EXPECT_EQ(s.data.to_double(), (std::vector<double>{5, 6}));
  // The other module spellings.
  for (const char* module : {"scipy.sparse._csc", "scipy.sparse._csr", "scipy.sparse.csr"}) {
    std::string m = module;
    const std::string cls = m.find("csr") != std::string::npos ? "csr_matrix" : "csc_matrix";
    std::string p = csc;
    p.replace(1, std::string("scipy.sparse.csc\ncsc_matrix").size(), m + "\n" + cls);
    EXPECT_EQ(parse(dict(str("J") + p)).at("J").sparse.format, cls.substr(0, 3)) << module;
  }
}

TEST(Pickle, RefusesEveryOtherClassByName) {
  EXPECT_NE(error_of(dict(str("a") + "cos\nsystem\n" + str("ls") + "\x85R")).find("'os.system'"),
            std::string::npos);
  // builtins.eval through STACK_GLOBAL (protocol 4).
  EXPECT_NE(error_of("\x80\x04}(\x8c\x01"
                     "a\x8c\x08"
                     "builtins\x8c\x04"
                     "eval\x93\x8c\x01x\x85Ru.")
                .find("'builtins.eval'"),
            std::string::npos);
  EXPECT_NE(error_of(dict(str("a") + "csubprocess\nPopen\n")).find("'subprocess.Popen'"),
            std::string::npos);
  EXPECT_NE(error_of(dict(str("a") + "cnumpy\nload\n")).find("'numpy.load'"), std::string::npos);
  EXPECT_NE(error_of(dict(str("a") + "cnumpy.core.multiarray\nscalar_evil\n"))
                .find("'numpy.core.multiarray.scalar_evil'"),
            std::string::npos);
  // A whitelisted class may still not be called in other ways.
  EXPECT_NE(
      error_of(dict(str("a") + "cnumpy\nndarray\n)R")).find("refused to call 'numpy.ndarray'"),
      std::string::npos);
  EXPECT_NE(error_of(dict(str("a") + "cnumpy\ndtype\n)\x81")).find("refused to instantiate"),
            std::string::npos);
}

TEST(Pickle, RefusesOtherProtocolsAndOpcodes) {
  EXPECT_NE(error_of("\x80\x06}.").find("protocol 6"), std::string::npos);
  EXPECT_NE(error_of("\x80\x01}.").find("protocol 1"), std::string::npos);
  EXPECT_NE(error_of("\x80\x02(I1\n.").find("unsupported pickle opcode 0x49"), std::string::npos);
  EXPECT_NE(error_of("\x80\x02(cos\nsystem\ni.").find("'os.system'"), std::string::npos);
  EXPECT_NE(error_of("\x80\x02}(U\x01"
                     "a(ou.")
                .find("refused"),
            std::string::npos);
  EXPECT_NE(error_of("\x80\x05\x97.").find("out-of-band"), std::string::npos);
  EXPECT_NE(error_of("\x80\x02Q.").find("persistent"), std::string::npos);
  EXPECT_NE(error_of("\x80\x02].").find("expected a dict"), std::string::npos);
  EXPECT_NE(error_of("\x80\x02.").find("stack underflow"), std::string::npos);
  EXPECT_NE(error_of("\x80\x02h\x05.").find("memo entry 5"), std::string::npos);
  EXPECT_NE(error_of("\x80\x02}K\x01K\x02u.").find("MARK expected"), std::string::npos);
  EXPECT_NE(error_of("\x80\x02}(K\x01K\x02u.").find("key is a int"), std::string::npos);
  EXPECT_NE(error_of("").find("empty"), std::string::npos);
}

TEST(Pickle, BadArrayStatesGiveClearErrors) {
  // Object array: the state's data is a list of Python objects.
  std::string obj = ndarray("O8", "|", {1}, "");
  obj.replace(obj.rfind(str("")), str("").size(),
              "](K\x01"
              "e");
  EXPECT_NE(error_of(dict(str("a") + obj)).find("object arrays are refused"), std::string::npos);
  // Too few / too many data bytes.
  EXPECT_NE(error_of(dict(str("a") + ndarray("f8", "<", {3}, doubles({1, 2})))).find("truncated"),
            std::string::npos);
  EXPECT_NE(
      error_of(dict(str("a") + ndarray("f8", "<", {1}, doubles({1, 2})))).find("does not match"),
      std::string::npos);
  EXPECT_NE(error_of(dict(str("a") + ndarray("c16", "<", {1}, doubles({1, 2}))))
                .find("unsupported dtype '<c16'"),
            std::string::npos);
  // An array whose BUILD never came.
  EXPECT_NE(error_of(dict(str("a") + "cnumpy.core.multiarray\n_reconstruct\ncnumpy\nndarray\n" +
                          int1(0) + "\x85" + str("b") + "\x87R"))
                .find("without data"),
            std::string::npos);
  // A chumpy object without 'x'.
  EXPECT_NE(error_of(dict(str("a") + "cchumpy.ch\nCh\n)\x81}b")).find("without 'x'"),
            std::string::npos);
}

TEST(Pickle, CyclesAndDeepNestingAreHarmless) {
  // l = []; l.append(l); d = {'a': l, 'c': Ch with state {'x': itself}}.
  const PickleDict d = parse(dict(str("a") + "]q\x01h\x01"
                                             "a"));
  EXPECT_EQ(d.at("a").kind, PickleValue::Kind::kOther);
  EXPECT_NE(error_of(dict(str("c") + "cchumpy.ch\nCh\n)\x81q\x02}(" + str("x") + "h\x02ub"))
                .find("nested too deeply"),
            std::string::npos);
  std::string deep = "\x80\x02}(" + str("a");
  for (int i = 0; i < 100000; ++i) deep += "]";
  for (int i = 0; i < 99999; ++i) deep += "a";
  deep += "u.";
  EXPECT_EQ(parse(deep).at("a").type_name, "list");
}

TEST(Pickle, EveryTruncationIsAnError) {
  const std::string full =
      dict(str("v") + ndarray("f8", "<", {2}, doubles({1, 2})) + str("s") + str("lbs") + str("c") +
           "cchumpy.ch\nCh\n)\x81}(" + str("x") + ndarray("i4", "<", {1}, u32(3)) + "ub");
  ASSERT_EQ(parse(full).size(), 3u);
  for (std::size_t cut = 0; cut < full.size(); ++cut) {
    const std::string context = "cut" + std::to_string(cut) + ".pkl";
    try {
      parse(full.substr(0, cut), context);
      ADD_FAILURE() << "cut at " << cut << " parsed";
    } catch (const ModelError& e) {
      EXPECT_NE(std::string(e.what()).find(context), std::string::npos) << e.what();
    }
  }
}

}  // namespace
