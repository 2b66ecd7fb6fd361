// OBJ/PLY avatars read back beside their writers (smpl::read_mesh_avatar): the up axis and the
// `caliper-metadata` comment, which smpl::mesh_metadata_json makes with nlohmann-json.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "caliper_test/files.hpp"
#include "caliper_test/random_model.hpp"
#include "smpl/export.hpp"
#include "smpl/mesh_read.hpp"
#include "smpl/text.hpp"

namespace {

namespace fs = std::filesystem;

// OBJ prints coordinates with %.9g: nine significant digits of values about 1 m.
constexpr double kObjTolM = 1e-8;
// PLY stores float32: 24-bit mantissas, about 6e-8 m at 1 m (measured 5.96e-8 here).
constexpr double kPlyTolM = 2e-7;

fs::path mesh_avatar_out_dir() {
  return caliper::test::output_dir(CALIPER_TEST_DATA_DIR, "mesh_avatar");
}

const std::map<std::string, std::string> kExtras = {
    {"model", "caliper-female"},
    {"note", "say \"hi\"\\ \ttab\nnew line"},
    {"sex", "female"},
};

TEST(MeshMetadata, OneCompactJsonLineInKeyOrder) {
  EXPECT_EQ(smpl::mesh_metadata_json({}), "");
  EXPECT_EQ(smpl::mesh_metadata_json({{"sex", "female"}, {"model", "m"}}),
            "{\"model\":\"m\",\"sex\":\"female\"}");
  const std::string j = smpl::mesh_metadata_json(kExtras);
  EXPECT_EQ(j.find('\n'), std::string::npos) << "a comment is one line";
  EXPECT_NE(j.find(R"("say \"hi\"\\ \ttab\nnew line")"), std::string::npos) << j;
  EXPECT_EQ(smpl::parse_mesh_metadata_json(j, "x"), kExtras);
  // Bytes that are not UTF-8 are replaced, never written as invalid JSON.
  const std::string latin1 = smpl::mesh_metadata_json({{"city", "M\xE9tis"}});
  EXPECT_EQ(smpl::parse_mesh_metadata_json(latin1, "x").at("city"), "M\xEF\xBF\xBDtis");
  EXPECT_THROW(smpl::parse_mesh_metadata_json("[1, 2]", "x"), smpl::ModelError);
  EXPECT_THROW(smpl::parse_mesh_metadata_json("{\"a\": ", "x"), smpl::ModelError);
  // Values of other types are skipped.
  const auto mixed = smpl::parse_mesh_metadata_json(R"({"a":"b","n":3,"o":{}})", "x");
  EXPECT_EQ(mixed, (std::map<std::string, std::string>{{"a", "b"}}));
}

TEST(MeshAvatar, ObjAndPlyRoundTripWithUpAxisAndMetadata) {
  const smpl::BodyModel model = caliper::test::make_random_model(4);
  const Eigen::VectorXd betas = caliper::test::random_betas(4, 1.0, 7);
  for (const char* name : {"a.obj", "a.ply", "A.OBJ"}) {
    for (const smpl::UpAxis up : {smpl::UpAxis::Y, smpl::UpAxis::Z}) {
      smpl::ExportOptions o;
      o.up = up;
      o.extras = kExtras;
      const std::string path = (mesh_avatar_out_dir() / name).string();
      smpl::write_mesh_avatar(path, model, betas, o);
      const std::string text = caliper::test::slurp(path);
      EXPECT_NE(text.find("caliper-metadata " + smpl::mesh_metadata_json(kExtras) + "\n"),
                std::string::npos)
          << name;
      const smpl::MeshAvatar a = smpl::read_mesh_avatar(path);
      o.up = smpl::UpAxis::Y;
      const smpl::Vertices expected = smpl::export_rest_body(model, betas, o, path).vertices;
      ASSERT_EQ(a.vertices.rows(), expected.rows()) << name;
      const double tol = smpl::ends_with_ci(path, ".ply") ? kPlyTolM : kObjTolM;
      EXPECT_LE((a.vertices - expected).cwiseAbs().maxCoeff(), tol) << name;
      EXPECT_EQ(a.faces, model.faces) << name;
      EXPECT_EQ(a.extras, kExtras) << name;
    }
  }
}

TEST(MeshAvatar, BadFilesAreModelErrors) {
  EXPECT_THROW(smpl::read_mesh_avatar((mesh_avatar_out_dir() / "a.stl").string()),
               smpl::ModelError);
  EXPECT_THROW(smpl::read_mesh_avatar((mesh_avatar_out_dir() / "missing.obj").string()),
               smpl::ModelError);
  const std::string bad = (mesh_avatar_out_dir() / "bad_meta.obj").string();
  std::ofstream(bad) << "# caliper-metadata {\"model\": \nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  try {
    smpl::read_mesh_avatar(bad);
    FAIL();
  } catch (const smpl::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("bad_meta.obj: its caliper-metadata comment"),
              std::string::npos)
        << e.what();
  }
  // A mesh without the comments: +Y up, no metadata.
  const std::string plain = (mesh_avatar_out_dir() / "plain.obj").string();
  std::ofstream(plain) << "# made elsewhere\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const smpl::MeshAvatar a = smpl::read_mesh_avatar(plain);
  EXPECT_EQ(a.vertices.rows(), 3);
  EXPECT_DOUBLE_EQ(a.vertices(2, 1), 1.0);
  EXPECT_TRUE(a.extras.empty());
}

}  // namespace
