// The committed .npz files load in common SMPL tooling: numpy (allow_pickle=False) sees SMPL's
// keys with SMPL's shapes and dtypes (the blend shapes at float32, as smplx works).
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <string>

namespace {

TEST(OpenModelNpz, LoadsWithNumpyInTheSmplLayout) {
  const std::string script = std::string(CALIPER_TEST_DATA_DIR) + "/modelgen_npz_layout.py";
  {
    std::ofstream py(script);
    py << R"PY(
import sys
import numpy as np
ok = True
for g in ['female', 'male', 'neutral']:
    path = sys.argv[1] + '/caliper-' + g + '.npz'
    d = np.load(path, allow_pickle=False)
    V = d['v_template'].shape[0]
    B = d['shapedirs'].shape[2]
    F = d['f'].shape[0]
    checks = [
        ('v_template', d['v_template'].shape == (V, 3) and d['v_template'].dtype == np.float64),
        ('f', d['f'].shape == (F, 3) and d['f'].dtype in (np.uint32, np.int32) and d['f'].max() < V),
        # the blend shapes are float32 values, stored as such (docs/file-formats.md)
        ('shapedirs', d['shapedirs'].shape == (V, 3, B) and d['shapedirs'].dtype == np.float32 and B >= 10),
        ('posedirs', 'posedirs' not in d or (d['posedirs'].shape == (V, 3, 207)
                                             and d['posedirs'].dtype == np.float32)),
        ('J_regressor', d['J_regressor'].shape == (24, V) and d['J_regressor'].dtype == np.float64
                        and np.allclose(d['J_regressor'].sum(1), 1)),
        ('weights', d['weights'].shape == (V, 24) and d['weights'].dtype == np.float64
                    and np.allclose(d['weights'].sum(1), 1)),
        ('kintree_table', d['kintree_table'].shape == (2, 24)
                          and list(d['kintree_table'][0][1:]) == [0,0,0,1,2,3,4,5,6,7,8,9,9,9,12,13,14,16,17,18,19,20,21]),
        ('J', d['J'].shape == (24, 3)),
        ('vert_sym_idxs', d['vert_sym_idxs'].shape == (V,)),
    ]
    # an SMPL-style forward pass in numpy (shape only) works on the arrays as they are
    betas = np.linspace(-1, 1, B)
    v = d['v_template'] + d['shapedirs'].dot(betas)
    J = d['J_regressor'].dot(v)
    checks.append(('forward', np.isfinite(J).all() and v.shape == (V, 3)))
    for name, good in checks:
        if not good:
            print(g, name, 'FAILED')
            ok = False
sys.exit(0 if ok else 1)
)PY";
  }
  const std::string cmd =
      std::string(CALIPER_SYSTEM_PYTHON) + " " + script + " " + CALIPER_MODELS_DIR;
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
}

}  // namespace
