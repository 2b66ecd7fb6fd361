// load_model() on SMPL-format files the tests build themselves (tests/smpl/fixtures/
// make_io_fixtures.py): every format must give exactly the arrays the generator wrote, and
// malformed files must give a ModelError naming the file and the problem, never a crash.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <random>

#include "io_test_util.hpp"
#include "smpl/io.hpp"
#include "smpl/npz.hpp"

namespace {

using caliper::test::io_fixture_dir;

std::string fixture(const std::string& name) {
  return io_fixture_dir() + "/" + name;
}

// The bits of a double (C++17 has no std::bit_cast).
std::uint64_t double_bits(double x) {
  static_assert(sizeof(double) == sizeof(std::uint64_t), "a double is 64 bits");
  std::uint64_t bits = 0;
  std::memcpy(&bits, &x, sizeof bits);
  return bits;
}

// Bitwise comparison of a double matrix with a reference array (C order).
template <typename M>
::testing::AssertionResult same_doubles(const M& m, const smpl::NpyArray& ref, const char* what) {
  const std::vector<double> r = ref.to_double();
  if (static_cast<std::size_t>(m.size()) != r.size()) {
    return ::testing::AssertionFailure()
           << what << ": " << m.size() << " values, reference has " << r.size();
  }
  std::size_t n = 0;
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index j = 0; j < m.cols(); ++j, ++n) {
      const double a = m(i, j);
      if (double_bits(a) != double_bits(r[n])) {
        return ::testing::AssertionFailure()
               << what << "(" << i << ", " << j << ") = " << a << ", reference " << r[n];
      }
    }
  }
  return ::testing::AssertionSuccess();
}

template <typename V>
::testing::AssertionResult same_ints(const V& values, const smpl::NpyArray& ref, const char* what) {
  const std::vector<std::int64_t> r = ref.to_int64();
  if (static_cast<std::size_t>(values.size()) != r.size()) {
    return ::testing::AssertionFailure()
           << what << ": " << values.size() << " values, reference has " << r.size();
  }
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (static_cast<std::int64_t>(values.data()[i]) != r[i]) {
      return ::testing::AssertionFailure()
             << what << "[" << i << "] = " << values.data()[i] << ", reference " << r[i];
    }
  }
  return ::testing::AssertionSuccess();
}

// Every array of `m` against the reference directory the generator wrote.
void expect_matches_reference(const smpl::BodyModel& m, const std::string& ref_dir,
                              bool posedirs = true) {
  using smpl::read_npy;
  EXPECT_TRUE(same_doubles(m.v_template, read_npy(ref_dir + "/v_template.npy"), "v_template"));
  EXPECT_TRUE(same_ints(m.faces, read_npy(ref_dir + "/f.npy"), "f"));
  // shapedirs / posedirs: row 3 v + c of the 3V x B matrix is (v, c, :) of the V x 3 x B array.
  EXPECT_TRUE(same_doubles(m.shapedirs, read_npy(ref_dir + "/shapedirs.npy"), "shapedirs"));
  if (posedirs) {
    EXPECT_TRUE(same_doubles(m.posedirs, read_npy(ref_dir + "/posedirs.npy"), "posedirs"));
  }
  EXPECT_TRUE(same_doubles(Eigen::MatrixXd(m.j_regressor), read_npy(ref_dir + "/J_regressor.npy"),
                           "J_regressor"));
  EXPECT_TRUE(
      same_doubles(Eigen::MatrixXd(m.weights), read_npy(ref_dir + "/weights.npy"), "weights"));
  EXPECT_TRUE(same_ints(m.parents, read_npy(ref_dir + "/parents.npy"), "parents"));
  EXPECT_TRUE(same_ints(m.mirror, read_npy(ref_dir + "/vert_sym_idxs.npy"), "vert_sym_idxs"));
}

// ---------------------------------------------------------------------------------------------
// Every format gives the generator's arrays.
class LoadFormat : public ::testing::TestWithParam<const char*> {};

TEST_P(LoadFormat, GivesTheGeneratorsArraysBitForBit) {
  const std::string path = fixture(GetParam());
  const smpl::BodyModel m = smpl::load_model(path);
  expect_matches_reference(m, path + ".ref");
  EXPECT_EQ(m.meta.source, path);
}

INSTANTIATE_TEST_SUITE_P(SmallModels, LoadFormat,
                         ::testing::Values("small_c.npz", "small_fortran.npz", "small_deflate.npz",
                                           "small_py2.pkl", "small_py2_numpy2.pkl", "small_p3.pkl",
                                           "small_p4.pkl", "small_p5.pkl", "smplx_like.npz"));

TEST(LoadModel, SmplShapedModelsGetSmplJointNamesOthersNone) {
  EXPECT_EQ(smpl::load_model(fixture("small_py2.pkl")).joint_names, smpl::smpl_joint_names());
  const smpl::BodyModel x = smpl::load_model(fixture("smplx_like.npz"));
  EXPECT_EQ(x.num_joints(), 55);
  EXPECT_EQ(x.num_pose_features(), 9 * 54);
  EXPECT_TRUE(x.joint_names.empty());
}

TEST(LoadModel, DropsExactZeroSkinningWeights) {
  const smpl::BodyModel m = smpl::load_model(fixture("small_c.npz"));
  // The generator gives every vertex exactly 4 non-zero weights.
  EXPECT_EQ(m.weights.nonZeros(), 4 * m.num_vertices());
}

TEST(LoadModel, FullSizeModelsWithSmplSizes) {
  for (const char* name : {"full300.npz", "full300_p4.pkl"}) {
    SCOPED_TRACE(name);
    const smpl::BodyModel m = smpl::load_model(fixture(name));
    EXPECT_EQ(m.num_vertices(), 6890);
    EXPECT_EQ(m.num_faces(), 13776);
    EXPECT_EQ(m.num_joints(), 24);
    EXPECT_EQ(m.num_betas(), 300);
    EXPECT_EQ(m.num_pose_features(), 207);
    expect_matches_reference(m, fixture("full300.npz.ref"));
  }
  const smpl::BodyModel m10 = smpl::load_model(fixture("full10_py2.pkl"));
  EXPECT_EQ(m10.num_betas(), 10);
  EXPECT_EQ(m10.num_vertices(), 6890);
  expect_matches_reference(m10, fixture("full10_py2.pkl.ref"));
}

TEST(LoadModel, NumBetasSelectsTheFirstComponents) {
  smpl::LoadOptions o;
  o.num_betas = 10;
  o.load_pose_blend_shapes = false;
  const smpl::BodyModel m = smpl::load_model(fixture("full300.npz"), o);
  ASSERT_EQ(m.num_betas(), 10);
  EXPECT_FALSE(m.has_pose_blend_shapes());
  // Same values as the first 10 of the file's 300: compare with the generator's 10-beta copy.
  expect_matches_reference(m, fixture("full10_py2.pkl.ref"), /*posedirs=*/false);
  o.num_betas = 0;
  EXPECT_EQ(smpl::load_model(fixture("small_c.npz"), o).num_betas(), 0);
}

TEST(LoadModel, MoreBetasThanTheFileHasIsAClearError) {
  smpl::LoadOptions o;
  o.num_betas = 11;
  try {
    smpl::load_model(fixture("small_p4.pkl"), o);
    FAIL() << "no error";
  } catch (const smpl::ModelError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("small_p4.pkl"), std::string::npos) << msg;
    EXPECT_NE(msg.find("10 components"), std::string::npos) << msg;
    EXPECT_NE(msg.find("num_betas"), std::string::npos) << msg;
  }
}

// ---------------------------------------------------------------------------------------------
// Bad files: the error names the file and the problem.
struct BadCase {
  const char* file;
  const char* expected;
};

// Test names show the file and the expected message, not the struct's bytes.
void PrintTo(const BadCase& c, std::ostream* os) {
  *os << c.file << ": " << c.expected;
}

class BadFile : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadFile, GivesAClearError) {
  const std::string path = fixture(GetParam().file);
  try {
    smpl::load_model(path);
    FAIL() << "no error for " << path;
  } catch (const smpl::ModelError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(GetParam().expected), std::string::npos) << msg;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Fixtures, BadFile,
    ::testing::Values(BadCase{"bad_object_array.npz", "J_regressor"},
                      BadCase{"bad_object_array.npz", "todense()"},
                      BadCase{"bad_nan.npz", "'shapedirs' contains NaN"},
                      BadCase{"bad_missing_weights.npz", "missing key 'weights'"},
                      BadCase{"bad_shape.npz", "'shapedirs' has shape (120, 2, 10)"},
                      BadCase{"bad_os_system.pkl", "'os.system'"},
                      BadCase{"bad_csc_indptr.pkl", "'J_regressor' is a corrupt sparse matrix"},
                      BadCase{"bad_builtins_eval.pkl", "'builtins.eval'"},
                      BadCase{"does_not_exist.npz", "cannot open"}));

TEST(LoadModel, UnknownFileContentIsRefused) {
  const std::string path = std::string(CALIPER_TEST_DATA_DIR) + "/smpl_io_not_a_model.obj";
  caliper::test::write_bytes(path, {'v', ' ', '1', ' ', '2', '\n'});
  try {
    smpl::load_model(path);
    FAIL();
  } catch (const smpl::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("neither an .npz"), std::string::npos) << e.what();
  }
}

// Cutting a valid file anywhere gives a ModelError naming the file (never a crash, never another
// exception type): every cut in the first 512 bytes, then 400 cuts spread over the file.
void expect_truncations_fail_cleanly(const std::string& name) {
  const std::vector<std::uint8_t> bytes = smpl::read_file_bytes(fixture(name));
  std::vector<std::size_t> cuts;
  for (std::size_t i = 0; i < std::min<std::size_t>(512, bytes.size()); ++i) cuts.push_back(i);
  for (std::size_t k = 0; k < 400; ++k) cuts.push_back(bytes.size() * k / 400);
  cuts.push_back(bytes.size() - 1);
  for (std::size_t cut : cuts) {
    const std::string context = name + " cut at " + std::to_string(cut);
    try {
      smpl::load_model_from_memory(bytes.data(), cut, context);
      ADD_FAILURE() << context << " loaded";
    } catch (const smpl::ModelError& e) {
      EXPECT_NE(std::string(e.what()).find(context), std::string::npos) << e.what();
    }
  }
}

TEST(LoadModel, TruncatedFilesFailCleanly) {
  for (const char* name :
       {"small_c.npz", "small_deflate.npz", "small_py2.pkl", "small_p3.pkl", "small_p5.pkl"}) {
    SCOPED_TRACE(name);
    expect_truncations_fail_cleanly(name);
  }
}

// Random byte corruption: loads (when it hit ignored bytes) or throws ModelError.
TEST(LoadModel, CorruptedBytesFailCleanly) {
  std::mt19937_64 rng(7);
  for (const char* name : {"small_fortran.npz", "small_deflate.npz", "small_py2.pkl",
                           "small_p4.pkl", "small_p5.pkl"}) {
    const std::vector<std::uint8_t> good = smpl::read_file_bytes(fixture(name));
    int errors = 0;
    for (int trial = 0; trial < 120; ++trial) {
      std::vector<std::uint8_t> bytes = good;
      // Corrupt 1-4 bytes, biased to the first 2 KiB where headers and opcodes are.
      const int n = 1 + static_cast<int>(rng() % 4);
      for (int k = 0; k < n; ++k) {
        const std::size_t span =
            (trial % 2 == 0) ? std::min<std::size_t>(2048, bytes.size()) : bytes.size();
        bytes[rng() % span] = static_cast<std::uint8_t>(rng());
      }
      try {
        smpl::load_model_from_memory(bytes.data(), bytes.size(), name);
      } catch (const smpl::ModelError&) {
        ++errors;
      }
    }
    EXPECT_GT(errors, 0) << name << ": no corruption was detected at all";
  }
}

}  // namespace
