// write_file_atomic: complete new file or the old one untouched, never a temporary left behind.
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "caliper_test/random_model.hpp"
#include "caliper_test/write_fault.hpp"
#include "smpl/atomic_file.hpp"
#include "smpl/export.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"

namespace {

namespace fs = std::filesystem;
using caliper::test::file_bytes;
using caliper::test::FileSizeLimit;
using caliper::test::temporary_files_in;

class AtomicFile : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ =
        fs::temp_directory_path() / ("caliper-atomic-" + std::to_string(::getpid())) / info->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_.parent_path()); }
  fs::path dir_;
};

TEST_F(AtomicFile, WritesANewFileAndLeavesNoTemporary) {
  const fs::path p = dir_ / "a.txt";
  smpl::write_file_atomic(p.string(), "hello\n");
  EXPECT_EQ(file_bytes(p), "hello\n");
  EXPECT_TRUE(temporary_files_in(dir_).empty());
}

TEST_F(AtomicFile, ReplacesAFileAndKeepsItsPermissions) {
  const fs::path p = dir_ / "a.txt";
  smpl::write_file_atomic(p.string(), "old");
  ASSERT_EQ(::chmod(p.c_str(), 0640), 0);
  smpl::write_file_atomic(p.string(), "new contents");
  EXPECT_EQ(file_bytes(p), "new contents");
  struct stat st {};
  ASSERT_EQ(::stat(p.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);
}

TEST_F(AtomicFile, AFailedWriteKeepsThePreviousFileAndRemovesTheTemporary) {
  const fs::path p = dir_ / "model.bin";
  const std::string good(1000, 'g');
  smpl::write_file_atomic(p.string(), good);
  const std::string big(100000, 'b');
  {
    const FileSizeLimit limit(4096);  // as a full disk: write() fails with EFBIG
    try {
      smpl::write_file_atomic(p.string(), big);
      FAIL() << "no error for a failed write";
    } catch (const smpl::WriteError& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("unchanged"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(file_bytes(p), good);
  EXPECT_TRUE(temporary_files_in(dir_).empty());
}

TEST_F(AtomicFile, ExportersKeepThePreviousFileOnAFailedWrite) {
  smpl::Vertices v(3, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  smpl::Faces f(1, 3);
  f << 0, 1, 2;
  const fs::path obj = dir_ / "m.obj";
  smpl::write_obj(obj.string(), v, f);
  const std::string before = file_bytes(obj);
  smpl::Vertices big = smpl::Vertices::Random(20000, 3);
  smpl::Faces big_f = smpl::Faces::Zero(1, 3);
  {
    const FileSizeLimit limit(4096);
    EXPECT_THROW(smpl::write_obj(obj.string(), big, big_f), smpl::WriteError);
    EXPECT_THROW(smpl::write_ply((dir_ / "m.ply").string(), big, big_f), smpl::WriteError);
  }
  EXPECT_EQ(file_bytes(obj), before);
  EXPECT_FALSE(fs::exists(dir_ / "m.ply"));
  EXPECT_TRUE(temporary_files_in(dir_).empty());
}

TEST_F(AtomicFile, ModelsAndAvatarsKeepThePreviousFileOnAFailedWrite) {
  caliper::test::RandomModelOptions o;
  o.num_betas = 4;
  o.rings = 12;
  o.segments = 12;
  const smpl::BodyModel model = caliper::test::make_random_model(o);
  const std::string previous = "the user's previous file\n";
  const fs::path npz = dir_ / "model.npz", glb = dir_ / "avatar.glb";
  std::ofstream(npz, std::ios::binary) << previous;
  std::ofstream(glb, std::ios::binary) << previous;
  {
    const FileSizeLimit limit(previous.size() + 1);
    EXPECT_THROW(smpl::save_model(model, npz.string()), smpl::WriteError);
    EXPECT_THROW(smpl::write_gltf(glb.string(), model, Eigen::VectorXd::Zero(4)), smpl::WriteError);
  }
  EXPECT_EQ(file_bytes(npz), previous);
  EXPECT_EQ(file_bytes(glb), previous);
  EXPECT_TRUE(temporary_files_in(dir_).empty());
  smpl::save_model(model, npz.string());  // the same writes succeed without the limit
  EXPECT_GT(file_bytes(npz).size(), previous.size() + 1);
}

TEST_F(AtomicFile, AFullDeviceIsAnError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  try {
    smpl::write_file_atomic("/dev/full", "x");
    FAIL() << "no error writing to /dev/full";
  } catch (const smpl::WriteError& e) {
    EXPECT_NE(std::string(e.what()).find("No space left"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_character_file("/dev/full"));  // written in place, never replaced
}

TEST_F(AtomicFile, AMissingFolderOrAFolderInTheWayIsAnError) {
  EXPECT_THROW(smpl::write_file_atomic((dir_ / "no-such-dir" / "a.txt").string(), "x"),
               smpl::WriteError);
  fs::create_directories(dir_ / "sub" / "inner");
  EXPECT_THROW(smpl::write_file_atomic((dir_ / "sub").string(), "x"), smpl::WriteError);
  EXPECT_TRUE(fs::is_directory(dir_ / "sub" / "inner"));
  EXPECT_TRUE(temporary_files_in(dir_).empty());
}

TEST_F(AtomicFile, ASymbolicLinkIsFollowedAndKept) {
  const fs::path target = dir_ / "target.txt";
  const fs::path link = dir_ / "link.txt";
  smpl::write_file_atomic(target.string(), "old");
  fs::create_symlink(target, link);
  smpl::write_file_atomic(link.string(), "new");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(file_bytes(target), "new");
}

}  // namespace
