// The project's own model format (save_model / load_model): exact round trip, deterministic
// bytes, and a file that numpy opens without pickle and that has SMPL's keys, shapes and dtypes.
#include <gtest/gtest.h>

#include "caliper_test/random_model.hpp"
#include "io_test_util.hpp"
#include "smpl/io.hpp"

namespace {

std::string save_model_out_dir() {
  std::string d = std::string(CALIPER_TEST_DATA_DIR) + "/smpl_save";
  caliper::test::run_command("mkdir -p '" + d + "'");
  return d;
}

smpl::BodyModel model_with_everything() {
  caliper::test::RandomModelOptions o;  // a small mesh keeps the test fast
  o.num_betas = 12;
  o.seed = 5;
  o.rings = 20;
  o.segments = 16;
  smpl::BodyModel m = caliper::test::make_random_model(o);
  m.meta.name = "caliper-test-model";
  m.meta.gender = "female";
  m.meta.source = "test_save_model";
  m.meta.extra["licence"] = "CC0 \xe2\x80\x94 test data";
  m.meta.extra["version"] = "1";
  // Texture coordinates per corner, with a seam: corner c of face f gets coordinate 3 f + c.
  m.uvs.resize(3 * m.faces.rows(), 2);
  m.uv_faces.resize(m.faces.rows(), 3);
  for (Eigen::Index f = 0; f < m.faces.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      m.uv_faces(f, c) = static_cast<int>(3 * f + c);
      m.uvs.row(3 * f + c) << 0.001 * static_cast<double>(f % 997), 0.25 * c;
    }
  }
  return m;
}

void expect_same_model(const smpl::BodyModel& a, const smpl::BodyModel& b) {
  // Exact equality: the format stores doubles (float32 only where that is lossless) and ints.
  EXPECT_TRUE(a.v_template == b.v_template);
  EXPECT_TRUE(a.faces == b.faces);
  EXPECT_TRUE(a.shapedirs == b.shapedirs);
  EXPECT_TRUE(a.posedirs == b.posedirs);
  EXPECT_TRUE(Eigen::MatrixXd(a.j_regressor) == Eigen::MatrixXd(b.j_regressor));
  EXPECT_TRUE(Eigen::MatrixXd(a.weights) == Eigen::MatrixXd(b.weights));
  EXPECT_EQ(a.parents, b.parents);
  EXPECT_EQ(a.joint_names, b.joint_names);
  EXPECT_EQ(a.landmarks, b.landmarks);
  EXPECT_EQ(a.mirror, b.mirror);
  EXPECT_TRUE(a.uvs == b.uvs);
  EXPECT_TRUE(a.uv_faces == b.uv_faces);
  EXPECT_EQ(a.meta.name, b.meta.name);
  EXPECT_EQ(a.meta.gender, b.meta.gender);
  EXPECT_EQ(a.meta.source, b.meta.source);
  EXPECT_EQ(a.meta.extra, b.meta.extra);
}

TEST(SaveModel, RoundTripIsExact) {
  const smpl::BodyModel m = model_with_everything();
  ASSERT_FALSE(m.landmarks.empty());
  ASSERT_FALSE(m.mirror.empty());
  for (bool compress : {false, true}) {
    const std::string path = save_model_out_dir() + (compress ? "/rt_deflated.npz" : "/rt.npz");
    smpl::SaveOptions o;
    o.compress = compress;
    smpl::save_model(m, path, o);
    expect_same_model(m, smpl::load_model(path));
  }
}

TEST(SaveModel, ModelsWithoutOptionalPartsRoundTrip) {
  smpl::BodyModel m = caliper::test::make_random_model(3, 16, false, 9);  // MANO-like, no posedirs
  m.landmarks.clear();
  m.mirror.clear();
  m.joint_names.clear();
  m.meta = {};
  const std::string path = save_model_out_dir() + "/bare.npz";
  smpl::save_model(m, path);
  const smpl::BodyModel back = smpl::load_model(path);
  EXPECT_FALSE(back.has_pose_blend_shapes());
  EXPECT_TRUE(back.landmarks.empty());
  EXPECT_TRUE(back.mirror.empty());
  EXPECT_TRUE(back.joint_names.empty());  // 16 joints: no default names
  EXPECT_TRUE(back.v_template == m.v_template);
}

TEST(SaveModel, BytesAreDeterministic) {
  const smpl::BodyModel m = model_with_everything();
  const std::string a = save_model_out_dir() + "/det_a.npz";
  const std::string b = save_model_out_dir() + "/det_b.npz";
  smpl::save_model(m, a);
  smpl::save_model(smpl::load_model(a), b);
  EXPECT_EQ(smpl::read_file_bytes(a), smpl::read_file_bytes(b));
}

TEST(SaveModel, BlendShapesOfFloat32ValuesAreStoredAsFloat32) {
  // The open models' blend shapes are float32 values: stored as <f4, read back to the same doubles.
  smpl::BodyModel m = model_with_everything();
  m.shapedirs = m.shapedirs.cast<float>().cast<double>();
  m.posedirs = m.posedirs.cast<float>().cast<double>();
  const std::string path = save_model_out_dir() + "/single.npz";
  smpl::save_model(m, path);
  smpl::NpzArchive z = smpl::read_npz(path);
  EXPECT_EQ(z.at("shapedirs").dtype, "<f4");
  EXPECT_EQ(z.at("posedirs").dtype, "<f4");
  EXPECT_EQ(z.at("v_template").dtype, "<f8");
  expect_same_model(m, smpl::load_model(path));
  // One value that float32 cannot hold keeps that array at float64, and nothing is lost.
  m.posedirs(1, 2) = 0.1;
  smpl::save_model(m, path);
  z = smpl::read_npz(path);
  EXPECT_EQ(z.at("shapedirs").dtype, "<f4");
  EXPECT_EQ(z.at("posedirs").dtype, "<f8");
  expect_same_model(m, smpl::load_model(path));
}

TEST(SaveModel, InvalidModelsAreNotWritten) {
  smpl::BodyModel m = model_with_everything();
  m.v_template(3, 1) = std::numeric_limits<double>::quiet_NaN();
  try {
    smpl::save_model(m, save_model_out_dir() + "/nan.npz");
    FAIL();
  } catch (const smpl::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos) << e.what();
  }
  EXPECT_THROW(smpl::save_model(model_with_everything(), "/nonexistent-dir/x.npz"),
               smpl::ModelError);
  // Texture-coordinate faces must match the faces and index the coordinates.
  smpl::BodyModel uv = model_with_everything();
  uv.uv_faces(2, 1) = static_cast<int>(uv.uvs.rows());
  try {
    smpl::save_model(uv, save_model_out_dir() + "/bad_ft.npz");
    FAIL();
  } catch (const smpl::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find("'ft'"), std::string::npos) << e.what();
  }
  uv = model_with_everything();
  uv.uv_faces.conservativeResize(uv.faces.rows() - 1, 3);
  EXPECT_THROW(smpl::save_model(uv, save_model_out_dir() + "/short_ft.npz"), smpl::ModelError);
}

// A landmark table whose offsets point past the vertex list (in the middle) is refused.
TEST(SaveModel, CorruptLandmarkTableIsAClearError) {
  smpl::NpzArchive z = smpl::model_arrays(model_with_everything());
  std::vector<std::int64_t> off = z.at("landmark_offsets").to_int64();
  ASSERT_GE(off.size(), 3u);
  off[1] = off.back() + 1000;
  z["landmark_offsets"] = smpl::make_npy(off, {off.size()});
  const std::string path = save_model_out_dir() + "/bad_landmarks.npz";
  smpl::write_npz(path, z);
  try {
    smpl::load_model(path);
    FAIL();
  } catch (const smpl::ModelError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'landmark_offsets' must not decrease"), std::string::npos)
        << e.what();
  }
}

// numpy opens the file with allow_pickle=False; keys, shapes and dtypes are SMPL's; the loading
// code of common SMPL tooling (dense arrays, kintree_table[0] parents) works on it; every member's
// bytes equal np.save's.
TEST(SaveModel, OpensInNumpyLikeAnSmplNpz) {
  const smpl::BodyModel m = model_with_everything();
  const std::string path = save_model_out_dir() + "/numpy_check.npz";
  smpl::save_model(m, path);
  const std::string program = R"PY(
import io, sys, zipfile
import numpy as np
path, V, F, K, B, P = sys.argv[1], *map(int, sys.argv[2:])
z = np.load(path, allow_pickle=False)
assert z['v_template'].shape == (V, 3) and z['v_template'].dtype == np.float64
assert z['f'].shape == (F, 3) and z['f'].dtype == np.uint32
assert z['shapedirs'].shape == (V, 3, B) and z['shapedirs'].dtype == np.float64
assert z['posedirs'].shape == (V, 3, P)
assert z['J_regressor'].shape == (K, V) and np.allclose(z['J_regressor'].sum(1), 1)
assert z['weights'].shape == (V, K) and np.allclose(z['weights'].sum(1), 1)
assert z['kintree_table'].shape == (2, K) and z['kintree_table'][0, 0] == 4294967295
assert np.all(z['kintree_table'][0, 1:] < np.arange(1, K))
assert np.allclose(z['J'], z['J_regressor'] @ z['v_template'])
assert z['vert_sym_idxs'].shape == (V,)
assert list(z['joint_names'][:2]) == ['pelvis', 'left_hip']
names, off, ids = z['landmark_names'], z['landmark_offsets'], z['landmark_vertices']
assert off[0] == 0 and off[-1] == len(ids) and len(off) == len(names) + 1
assert 'head_top' in list(names)
assert str(z['meta_name']) == 'caliper-test-model' and str(z['meta_gender']) == 'female'
assert dict(zip(z['meta_extra_keys'], z['meta_extra_values']))['licence'] == 'CC0 \u2014 test data'
# The forward pass of common SMPL code on the file (shape blend shapes and joints).
betas = np.linspace(-1, 1, B)
v = z['v_template'] + z['shapedirs'].reshape(-1, B).dot(betas).reshape(V, 3)
assert np.isfinite(z['J_regressor'].dot(v)).all()
with zipfile.ZipFile(path) as zf:
    for info in zf.infolist():
        buf = io.BytesIO()
        np.save(buf, z[info.filename[:-4]])
        assert zf.read(info) == buf.getvalue(), info.filename
print('numpy opens the model like an SMPL npz')
)PY";
  const std::string args = "'" + path + "' " + std::to_string(m.num_vertices()) + " " +
                           std::to_string(m.num_faces()) + " " + std::to_string(m.num_joints()) +
                           " " + std::to_string(m.num_betas()) + " " +
                           std::to_string(m.num_pose_features());
  EXPECT_EQ(caliper::test::run_python(program, args), 0);
}

}  // namespace
