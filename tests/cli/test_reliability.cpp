// Issue 10, sections 3 and 4 on the command line: nothing a user made is lost (atomic writes,
// failed writes are errors), batch file names never collide, odd but honest input gets a clear
// answer (open meshes, upside-down meshes, feet and inches, absurd numbers, broken models).
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "caliper/json.hpp"
#include "caliper/plausibility.hpp"
#include "caliper_test/write_fault.hpp"
#include "cli_fixture.hpp"
#include "cli_run.hpp"
#include "cli_support.hpp"
#include "commands.hpp"
#include "report.hpp"
#include "smpl/export.hpp"
#include "smpl/io.hpp"

namespace caliper::cli {
namespace {

namespace fs = std::filesystem;
using test::file_bytes;
using test::FileSizeLimit;
using test::temporary_files_in;

using test::CliRun;

using test::contains;

class Reliability : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(CALIPER_TEST_DATA_DIR) / "cli-reliability" / info->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    model_ = path("model.npz");
    smpl::save_model(test::cli_test_model("female"), model_);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  CliRun run(const std::vector<std::string>& args) const {
    std::ostringstream out, err;
    Io io{out, err, false};
    CliRun r;
    r.code = main_guarded(args, io);
    r.out = out.str();
    r.err = err.str();
    return r;
  }
  fs::path dir_;
  std::string model_;
};

// ---------------------------------------------------------------------------------------------
// Writes

TEST_F(Reliability, CreateKeepsAGoodGlbWhenTheWriteFails) {
  ASSERT_EQ(run({"create", "--model", model_, "--height", "170cm", "--weight", "65kg", "--force",
                 "--out", path("a.glb")})
                .code,
            kExitOk);
  const std::string good = file_bytes(path("a.glb"));
  ASSERT_GT(good.size(), 4096u);
  CliRun r;
  {
    const FileSizeLimit limit(4096);  // the disk fills up after 4 KiB
    r = run({"create", "--model", model_, "--height", "180cm", "--weight", "80kg", "--force",
             "--out", path("a.glb")});
  }
  EXPECT_EQ(r.code, kExitRuntime) << r.err;
  EXPECT_TRUE(contains(r.err, "a.glb")) << r.err;
  EXPECT_TRUE(contains(r.err, "unchanged")) << r.err;
  EXPECT_EQ(file_bytes(path("a.glb")), good) << "the previous avatar must be intact";
  EXPECT_TRUE(temporary_files_in(dir_).empty());
}

TEST_F(Reliability, BatchKeepsThePreviousResultsWhenTheWriteFails) {
  std::ofstream people(path("people.csv"));
  people << "id,height_cm,weight_kg\n";
  for (int i = 0; i < 60; ++i)
    people << "p" << i << "," << 160 + i % 30 << "," << 55 + i % 25 << "\n";
  people.close();
  ASSERT_EQ(run({"batch", path("people.csv"), "--model", model_, "--force", "-j", "1", "--out",
                 path("results.csv")})
                .code,
            kExitOk);
  const std::string good = file_bytes(path("results.csv"));
  ASSERT_GT(good.size(), 8192u);
  CliRun r;
  {
    const FileSizeLimit limit(8192);
    r = run({"batch", path("people.csv"), "--model", model_, "--force", "-j", "1", "--out",
             path("results.csv"), "--regressor", "R2"});
  }
  EXPECT_EQ(r.code, kExitRuntime) << r.err;
  EXPECT_TRUE(contains(r.err, "results.csv")) << r.err;
  EXPECT_EQ(file_bytes(path("results.csv")), good) << "never a results file cut mid-row";
  EXPECT_TRUE(temporary_files_in(dir_).empty());
}

// Every kind of file the command line writes, through its own code path: a failed write is
// exit 1 naming the file, the previous file stays byte for byte, no temporary is left.
TEST_F(Reliability, EveryWriterKeepsThePreviousFileWhenTheWriteFails) {
  const std::vector<std::string> create = {"create", "--model",  model_, "--height",
                                           "170cm",  "--weight", "65kg", "--force"};
  const auto with = [](std::vector<std::string> args, const std::vector<std::string>& more) {
    args.insert(args.end(), more.begin(), more.end());
    return args;
  };
  const struct {
    std::string file;
    std::vector<std::string> args;
  } writers[] = {
      {"a.glb", with(create, {"--out", path("a.glb")})},
      {"a.obj", with(create, {"--out", path("a.obj")})},
      {"a.ply", with(create, {"--out", path("a.ply")})},
      {"a.png", with(create, {"--png", path("a.png")})},
      {"regressors.json", {"train", "--model", model_, "--save", path("regressors.json")}},
  };
  const std::string previous = "the user's previous file\n";
  for (const auto& w : writers) {
    std::ofstream(path(w.file), std::ios::binary) << previous;
    CliRun r;
    {
      const FileSizeLimit limit(previous.size() + 1);  // every new file is larger than this
      r = run(w.args);
    }
    EXPECT_EQ(r.code, kExitRuntime) << w.file << ": " << r.err;
    EXPECT_TRUE(contains(r.err, w.file)) << r.err;
    EXPECT_TRUE(contains(r.err, "unchanged")) << r.err;
    EXPECT_EQ(file_bytes(path(w.file)), previous) << w.file;
    EXPECT_TRUE(temporary_files_in(dir_).empty()) << w.file;
    // Without the limit the same command replaces the file (the failure above was the write).
    ASSERT_EQ(run(w.args).code, kExitOk) << w.file;
    EXPECT_GT(file_bytes(path(w.file)).size(), previous.size() + 1) << w.file;
  }
}

TEST_F(Reliability, BatchToAFullDiskIsAnError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  std::ofstream(path("people.csv")) << "height_cm,weight_kg\n170,65\n";
  const CliRun r =
      run({"batch", path("people.csv"), "--model", model_, "--force", "--out", "/dev/full"});
  EXPECT_EQ(r.code, kExitRuntime) << r.err;
  EXPECT_TRUE(contains(r.err, "/dev/full")) << r.err;
  EXPECT_TRUE(contains(r.err, "No space left")) << r.err;
}

TEST_F(Reliability, BatchFileNamesNeverCollide) {
  std::ofstream(path("people.csv")) << "id,height_cm,weight_kg\n"
                                       "a b,170,62\n"
                                       "a_b,171,63\n"
                                       "a/b,172,64\n"
                                       ",173,65\n"
                                       "a b,174,66\n"
                                       "A_B,175,67\n"
                                       ",176,68\n";
  const CliRun r =
      run({"batch", path("people.csv"), "--model", model_, "--force", "-j", "2", "--out",
           path("results.csv"), "--out-dir", path("avatars"), "--format", "obj"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  const CsvTable t = read_csv(path("results.csv"));
  ASSERT_EQ(t.rows.size(), 7u);
  const int file = t.column("file");
  ASSERT_GE(file, 0);
  std::set<std::string> names;
  for (const auto& row : t.rows) {
    const std::string& name = row[static_cast<size_t>(file)];
    names.insert(name);
    EXPECT_TRUE(fs::exists(dir_ / "avatars" / name)) << name;
  }
  EXPECT_EQ(names.size(), 7u) << "two people share an avatar file";
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir_ / "avatars")) files += e.is_regular_file();
  EXPECT_EQ(files, 7u);
  // Each file holds its own person: the heights differ by 1 cm from row to row.
  std::set<std::string> contents;
  for (const auto& name : names) contents.insert(file_bytes(dir_ / "avatars" / name));
  EXPECT_EQ(contents.size(), 7u);
}

TEST_F(Reliability, BatchMalformedRowIsAPerRowError) {
  std::ofstream(path("people.csv")) << "id,height_cm,weight_kg\n"
                                       "a,170,62\n"
                                       "b,171\n"
                                       "c,172,64,99\n"
                                       "d,173,65\n";
  const CliRun r = run(
      {"batch", path("people.csv"), "--model", model_, "--force", "--out", path("results.csv")});
  EXPECT_EQ(r.code, kExitRuntime) << r.err;
  EXPECT_TRUE(contains(r.err, "2 ok, 0 refused, 2 errors")) << r.err;
  const CsvTable t = read_csv(path("results.csv"));
  ASSERT_EQ(t.rows.size(), 4u);
  const auto status = static_cast<size_t>(t.column("status"));
  EXPECT_EQ(t.rows[0][status], "ok");
  EXPECT_EQ(t.rows[1][status], "error");
  EXPECT_TRUE(contains(t.rows[1].back(), ":3: 2 cells, but the header has 3")) << t.rows[1].back();
  EXPECT_EQ(t.rows[2][status], "error");
  EXPECT_EQ(t.rows[3][status], "ok");
}

TEST_F(Reliability, BatchRowWithAStrayQuoteIsAPerRowError) {
  // A quote opened and never closed used to swallow the rest of the file and end the batch.
  std::ofstream(path("people.csv")) << "id,height_cm,weight_kg\n"
                                       "a,170,62\n"
                                       "b,\"171,63\n"
                                       "\"c,d\",172,64\n"
                                       "e,173,65\n"
                                       "f,174,\"66\n";  // the last line, no line break
  const CliRun r = run(
      {"batch", path("people.csv"), "--model", model_, "--force", "--out", path("results.csv")});
  EXPECT_EQ(r.code, kExitRuntime) << r.err;
  EXPECT_TRUE(contains(r.err, "3 ok, 0 refused, 2 errors")) << r.err;
  const CsvTable t = read_csv(path("results.csv"));
  ASSERT_EQ(t.rows.size(), 5u);
  const auto status = static_cast<size_t>(t.column("status"));
  const auto id = static_cast<size_t>(t.column("id"));
  const std::vector<std::string> ids = {"a", "b", "c,d", "e", "f"};
  const std::vector<std::string> statuses = {"ok", "error", "ok", "ok", "error"};
  for (size_t i = 0; i < ids.size(); ++i) {
    EXPECT_EQ(t.rows[i][id], ids[i]);
    EXPECT_EQ(t.rows[i][status], statuses[i]) << ids[i];
  }
  EXPECT_TRUE(contains(t.rows[1].back(), ":3: a quoted cell is not closed on this line"))
      << t.rows[1].back();
  EXPECT_TRUE(contains(t.rows[4].back(), ":6: a quoted cell is not closed")) << t.rows[4].back();
  // Without per-row errors (other tables) a quoted cell may still span lines (RFC 4180).
  const CsvTable multi = parse_csv("a,b\n\"x\ny\",1\n", "t.csv");
  ASSERT_EQ(multi.rows.size(), 1u);
  EXPECT_EQ(multi.rows[0][0], "x\ny");
  EXPECT_THROW(parse_csv("a,b\n\"x,1\n", "t.csv"), CsvError);
}

TEST_F(Reliability, BatchChecksItsOutputsBeforeWorking) {
  std::ofstream(path("people.csv")) << "height_cm,weight_kg\n170,62\n";
  std::ofstream(path("a-file")) << "x";
  CliRun r =
      run({"batch", path("people.csv"), "--model", model_, "--force", "--out-dir", path("a-file")});
  EXPECT_EQ(r.code, kExitRuntime);
  EXPECT_TRUE(contains(r.err, "--out-dir")) << r.err;
  EXPECT_FALSE(contains(r.err, "people in")) << "no work before the check: " << r.err;
  r = run({"batch", path("people.csv"), "--model", model_, "--force", "--out",
           path("no-such-folder/results.csv")});
  EXPECT_EQ(r.code, kExitRuntime);
  EXPECT_TRUE(contains(r.err, "does not exist")) << r.err;
  EXPECT_FALSE(contains(r.err, "people in")) << r.err;
}

TEST_F(Reliability, BatchSaysWhenAnAvatarIsImplausible) {
  std::ofstream(path("people.csv")) << "id,height_cm,weight_kg\nok,170,62\nodd,240,40\n";
  for (const bool mesh : {false, true}) {
    std::vector<std::string> args = {"batch", path("people.csv"), "--model", model_, "--force",
                                     "--out", path("results.csv")};
    if (mesh) args.push_back("--circumferences");
    const CliRun r = run(args);
    const CsvTable t = read_csv(path("results.csv"));
    ASSERT_EQ(t.rows.size(), 2u);
    const auto plausible = static_cast<size_t>(t.column("plausible"));
    ASSERT_EQ(t.rows[1][plausible], "no") << "the test needs an implausible avatar";
    EXPECT_TRUE(contains(t.rows[1].back(),
                         "unusual body shape (outside the usual range): Mahalanobis distance"))
        << t.rows[1].back();
    EXPECT_FALSE(contains(t.rows[0].back(), "unusual body shape")) << t.rows[0].back();
  }
}

// ---------------------------------------------------------------------------------------------
// Odd input

TEST_F(Reliability, MeasureLeavesOutVolumeAndWeightOfAnOpenMesh) {
  smpl::BodyModel m = test::cli_test_model("female");
  const smpl::Faces closed = m.faces;
  m.faces = closed.topRows(closed.rows() - 40);  // a hole, as a hand cut at the wrist
  smpl::save_model(m, path("open.npz"));
  CliRun r = run({"measure", "--model", path("open.npz"), "--betas", "0"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_FALSE(contains(r.out, "\nVolume ")) << r.out;  // no table row
  EXPECT_FALSE(contains(r.out, "\nWeight ")) << r.out;
  EXPECT_TRUE(contains(r.out, "\nOverall height ")) << r.out;
  EXPECT_TRUE(contains(r.out, "note: volume and weight left out: the mesh is not closed")) << r.out;
  r = run({"measure", "--model", path("open.npz"), "--betas", "0", "--json"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  const Json j = parse_json(r.out);
  EXPECT_FALSE(j.at("measurements").contains("volume"));
  EXPECT_FALSE(j.at("measurements").contains("weight"));
  EXPECT_EQ(j.at("notes").size(), 1u);
  // The closed model still has both.
  r = run({"measure", "--model", model_, "--betas", "0", "--json"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_GT(parse_json(r.out).at("measurements").at("weight").as_number(), 0.0);
}

TEST_F(Reliability, MeasureWarnsAboutAnUpsideDownOrFlatMesh) {
  const smpl::BodyModel m = test::cli_test_model("female");
  smpl::Vertices flipped = m.v_template;
  flipped.col(1) *= -1.0;  // upside down (a mirror, but the head is now at the bottom)
  smpl::write_obj(path("flipped.obj"), flipped, m.faces);
  CliRun r = run({"measure", path("flipped.obj"), "--model", model_, "--no-circumferences"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_TRUE(contains(r.err, "upside down")) << r.err;
  EXPECT_TRUE(contains(r.err, "implausible measurement")) << r.err;
  smpl::Vertices flat = m.v_template;
  flat.col(1).setZero();  // height 0
  smpl::write_obj(path("flat.obj"), flat, m.faces);
  r = run({"measure", path("flat.obj"), "--model", model_, "--no-circumferences", "--json"});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  EXPECT_TRUE(contains(r.err, "implausible measurement: height")) << r.err;
  EXPECT_GE(parse_json(r.out).at("warnings").size(), 1u);
  // A normal avatar has no orientation warning.
  r = run({"measure", "--model", model_, "--betas", "0", "--no-circumferences"});
  EXPECT_FALSE(contains(r.err, "upside down")) << r.err;
}

TEST(OddInput, FeetAndInchesOnlyCombineAsFeetThenInches) {
  constexpr double kFeetInchesTol = 1e-12;  // one multiplication and one addition
  EXPECT_NEAR(parse_length("5FT6IN", "--height"), 66 * 0.0254, kFeetInchesTol);
  EXPECT_NEAR(parse_length("5Ft 6In", "--height"), 66 * 0.0254, kFeetInchesTol);
  EXPECT_NEAR(parse_length("5ft6in", "--height"), 66 * 0.0254, kFeetInchesTol);
  EXPECT_NEAR(parse_mass("62KG", "--weight"), 62.0, kFeetInchesTol);
  for (const char* bad : {"5ft60cm", "6ft-6in", "5ft12in", "-5ft6in", "5in6ft", "5ft6in2in"}) {
    try {
      parse_length(bad, "--height");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const UsageError& e) {
      EXPECT_TRUE(contains(e.what(), bad)) << e.what();
    }
  }
}

TEST(OddInput, AbsurdNumbersPrintShort) {
  EXPECT_EQ(format_number(5e31, 2), "5.000e+31");
  EXPECT_EQ(format_number(53.872, 2), "53.87");
  EXPECT_LE(format_value("height", 1e306).size(), 16u) << format_value("height", 1e306);
  EXPECT_EQ(format_value("height", 1.685), "168.5 cm");
  Plausibility p;
  p.mahalanobis = 5e31;
  p.dof = 10;
  p.plausible = false;
  EXPECT_TRUE(contains(format_plausibility(p), "Mahalanobis distance 5.000e+31"))
      << format_plausibility(p);
}

TEST_F(Reliability, AnAbsurdTypedWeightIsRefusedShortly) {
  const CliRun r = run({"create", "--model", model_, "--height", "170cm", "--weight", "1e308kg"});
  EXPECT_EQ(r.code, kExitImplausible) << r.err;
  EXPECT_LT(r.err.size(), 400u) << r.err;
}

TEST_F(Reliability, AModelWithoutShapeIsAModelError) {
  smpl::BodyModel m = test::cli_test_model("female");
  m.shapedirs.setZero();
  smpl::save_model(m, path("flat-shape.npz"));
  const CliRun r = run({"create", "--model", path("flat-shape.npz"), "--height", "170cm",
                        "--weight", "65kg", "--force"});
  EXPECT_EQ(r.code, kExitRuntime) << r.err;
  EXPECT_TRUE(contains(r.err, "shapedirs")) << r.err;
  EXPECT_FALSE(contains(r.err, "implausible")) << r.err;
}

}  // namespace
}  // namespace caliper::cli
