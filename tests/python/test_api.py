"""The Python API: model arrays without copies, create with units, batch evaluation, export,
errors with the C++ message."""
import math
import os

import numpy as np
import pytest

import caliper

# Same C++ code on both sides of each comparison: equal to the last bit unless stated.
EXACT = 0.0
# float32 output is the float64 result rounded once: relative error at most 2^-24.
FLOAT32_REL = 2.0 ** -24


def test_model_arrays_are_views_of_the_model(model):
    v = model.v_template
    assert v.shape == (model.num_vertices, 3) and v.dtype == np.float64
    assert not v.flags.writeable
    # Two reads share the model's memory: no copy per access.
    assert np.shares_memory(v, model.v_template)
    assert model.shapedirs.shape == (model.num_vertices, 3, model.num_betas)
    assert np.shares_memory(model.shapedirs, model.shapedirs)
    assert model.posedirs.shape == (model.num_vertices, 3, model.num_pose_features)
    assert model.faces.shape == (model.num_faces, 3) and model.faces.dtype == np.int32
    assert model.j_regressor.shape == (model.num_joints, model.num_vertices)
    assert model.weights.shape == (model.num_vertices, model.num_joints)
    np.testing.assert_allclose(model.weights.sum(axis=1), 1.0, atol=1e-12)  # rows sum to 1
    assert model.parents[0] == -1 and len(model.joint_names) == model.num_joints
    with pytest.raises(ValueError):
        v[0, 0] = 1.0  # read-only


def test_view_keeps_the_model_alive():
    v = caliper.open_model("male").v_template  # the model object is dropped at once
    assert np.isfinite(v).all() and v.shape[1] == 3


def test_create_with_units_equals_si_numbers(model, regressors):
    a = caliper.create(model, regressors, height="168cm", weight="62kg")
    b = caliper.create(model, regressors, {"height": 1.68, "weight": 62.0})
    assert a.regressor == "R2"
    np.testing.assert_array_equal(a.betas, b.betas)
    assert a.input == {"height": 1.68, "weight": 62.0}
    assert abs(a.achieved["height"] - 1.68) < 0.02  # R2 is a least-squares fit, not exact
    c = caliper.create(model, regressors, height="5ft6in", weight="136.69lb")
    assert math.isclose(c.input["height"], 66 * 0.0254, rel_tol=1e-15)


def test_every_regressor(model, regressors):
    six = dict(height="170cm", weight="65kg", arm_span="170cm", inseam="78cm",
               hip_width="34cm", arm_length="56cm")
    for name in ("R2", "R4", "R5", "R6"):
        needed = caliper.regressor_inputs(name)
        kw = {k: v for k, v in six.items()
              if {"arm_span": "arm_span_fingertips", "inseam": "inseam_height"}.get(k, k) in needed}
        a = caliper.create(model, regressors, regressor=name, **kw)
        assert a.regressor == name and a.covariance is None
        assert a.betas.shape == (model.num_betas,)
    na = caliper.create(model, regressors, **six)  # all six: noise-aware by default
    assert na.regressor == "noise-aware"
    k = na.covariance.shape[0]
    assert na.covariance.shape == (k, k) and na.betas_sd.shape == (k,)
    noisy = caliper.create(model, regressors, regressor="noise-aware", height="170cm",
                           noise={"height": "5cm"})
    assert noisy.betas_sd[0] > 0
    assert isinstance(na.plausibility.plausible, bool)


def test_exact_inputs_reproduces_every_input(model, regressors):
    a = caliper.create(model, regressors, height="168cm", weight="62kg", exact_inputs=True)
    # refine_to_inputs stops when every residual is below 1e-9 m (docs/regressors.md).
    assert abs(a.achieved["height"] - 1.68) < 1e-6
    assert abs(a.achieved["weight"] - 62.0) < 1e-4


def test_shape_curve_starts_plain_regressors_and_can_be_switched_off(model, regressors):
    # The open models carry the general population's shape curve: R2 from it sets every beta
    # (the paper's R2 leaves those beyond its 10 at 0) and gives the height back as well.
    curve = caliper.create(model, regressors, height="160cm", weight="110kg")
    paper = caliper.create(model, regressors, height="160cm", weight="110kg", shape_curve=False)
    assert np.abs(curve.betas[10:]).max() > 1e-3
    assert np.abs(paper.betas[10:]).max() == 0
    for a in (curve, paper):
        assert abs(a.achieved["height"] - 1.60) < 1e-3


def test_population_is_the_noise_aware_prior(model, regressors):
    # As `caliper create --population`: the open models carry ANSUR II's soldiers (a smaller
    # waist than the general population's for the same height and weight) and NHANES's adults,
    # which are the models' own N(0, I) (the same avatar as without a population).
    own = caliper.create(model, regressors, height="165cm", weight="64kg", regressor="noise-aware")
    adults = caliper.create(model, regressors, height="165cm", weight="64kg", population="nhanes")
    soldier = caliper.create(model, regressors, height="165cm", weight="64kg", population="ansur2")
    assert adults.regressor == soldier.regressor == "noise-aware"
    assert np.abs(adults.betas - own.betas).max() < 1e-9
    assert soldier.achieved["waist_circumference"] < own.achieved["waist_circumference"] - 0.01
    with pytest.raises(caliper.InvalidInputError, match="takes the noise-aware regressor"):
        caliper.create(model, regressors, height="165cm", weight="64kg", regressor="R2",
                       population="ansur2")
    with pytest.raises(caliper.InvalidInputError, match="carries no population 'martians'"):
        caliper.create(model, regressors, height="165cm", weight="64kg", population="martians")


def test_batch_evaluation_equals_single_calls(model):
    rng = np.random.default_rng(7)
    n, k = 16, model.num_joints
    betas = rng.normal(size=(n, 10))
    poses = rng.normal(scale=0.3, size=(n, 3 * k))
    trans = rng.normal(size=(n, 3))
    verts, joints = caliper.evaluate(model, betas, poses, trans, joints=True)
    assert verts.shape == (n, model.num_vertices, 3) and joints.shape == (n, k, 3)
    for i in range(n):
        vi, ji = caliper.evaluate(model, betas[i], poses[i], trans[i], joints=True)
        np.testing.assert_array_equal(verts[i], vi)
        np.testing.assert_array_equal(joints[i], ji)
    # (N, K, 3) poses are the same numbers as (N, 3K).
    np.testing.assert_array_equal(caliper.evaluate(model, betas, poses.reshape(n, k, 3), trans),
                                  verts)
    # float32 in and out.
    v32 = caliper.evaluate(model, betas.astype(np.float32), poses.astype(np.float32),
                           trans.astype(np.float32), dtype=np.float32)
    assert v32.dtype == np.float32
    ref = caliper.evaluate(model, betas.astype(np.float32).astype(np.float64),
                           poses.astype(np.float32).astype(np.float64),
                           trans.astype(np.float32).astype(np.float64))
    np.testing.assert_allclose(v32, ref, rtol=FLOAT32_REL, atol=1e-7)


def test_rest_pose_evaluation_is_the_avatar(model, regressors):
    a = caliper.create(model, regressors, height="168cm", weight="62kg")
    v = caliper.evaluate(model, a.betas)
    # Rest pose: the skinning transforms are pure translations that cancel; 1e-12 m covers the
    # rounding of adding and subtracting the joint positions.
    np.testing.assert_allclose(v, a.vertices, rtol=0, atol=1e-12)


def test_measure_betas_and_vertices_agree(model, regressors):
    a = caliper.create(model, regressors, height="168cm", weight="62kg")
    by_betas = caliper.measure(model, betas=a.betas)
    by_vertices = caliper.measure(model, a.vertices)
    assert by_betas == by_vertices == a.achieved
    assert {"height", "weight", "volume", "hip_width"} <= set(by_betas)


def test_exports(model, regressors, work):
    a = caliper.create(model, regressors, height="168cm", weight="62kg")
    for ext in (".glb", ".gltf", ".obj", ".ply"):
        path = os.path.join(work, "avatar" + ext)
        a.save(path)
        assert os.path.getsize(path) > 1000
    with open(os.path.join(work, "avatar.glb"), "rb") as f:
        assert f.read() == a.glb_bytes()
    back = caliper.read_gltf(os.path.join(work, "avatar.glb"))
    # A textured model's file is split at its texture seams: its vertices are the model's,
    # then copies of those on a seam.
    assert back["vertices"].shape[0] >= model.num_vertices and back["vertices"].shape[1] == 3
    assert len(np.unique(back["vertices"], axis=0)) == model.num_vertices
    assert back["extras"]["regressor"] == "R2"
    assert back["joint_names"] == model.joint_names
    caliper.write_gltf(os.path.join(work, "b.gltf"), model, a.betas, pose_correctives=True)
    assert caliper.glb_bytes(model, a.betas)[:4] == b"glTF"
    caliper.write_obj(os.path.join(work, "m.obj"), a.vertices, model.faces)
    caliper.write_ply(os.path.join(work, "m.ply"), a.vertices, model.faces)
    model.save(os.path.join(work, "model.npz"))
    again = caliper.load_model(os.path.join(work, "model.npz"))
    np.testing.assert_array_equal(again.v_template, model.v_template)
    np.testing.assert_array_equal(again.shapedirs, model.shapedirs)


def test_regressors_round_trip(model, regressors, work):
    path = os.path.join(work, "regressors.json")
    regressors.save(path)
    loaded = caliper.load_regressors(path, model)
    assert loaded.names == regressors.names == ["R2", "R4", "R5", "R6", "noise-aware"]
    x = {"height": 1.7, "weight": 70.0}
    np.testing.assert_array_equal(loaded.linear("R2").predict(x), regressors.linear("R2").predict(x))
    mean, cov = loaded.noise_aware.predict(x)
    assert cov.shape == (mean.size, mean.size)
    with pytest.raises(caliper.ModelMismatchError, match="model"):
        caliper.load_regressors(path, caliper.open_model("male"))


def test_bad_files_raise_with_the_cxx_message(work):
    missing = os.path.join(work, "nope.npz")
    with pytest.raises(caliper.ModelError, match="nope.npz"):
        caliper.load_model(missing)
    bad = os.path.join(work, "bad.npz")
    with open(bad, "wb") as f:
        f.write(b"PK\x03\x04 truncated")
    with pytest.raises(caliper.ModelError, match="bad.npz"):
        caliper.load_model(bad)
    with pytest.raises(caliper.Error):  # ModelError is a caliper.Error and an OSError
        caliper.load_model(bad)
    with pytest.raises(OSError):
        caliper.load_model(bad)
    with pytest.raises(caliper.Error, match="nope.json"):
        caliper.load_regressors(os.path.join(work, "nope.json"))


def test_bad_values_raise_with_the_cxx_message(model, regressors, work):
    with pytest.raises(caliper.InvalidInputError, match="height '168': no unit given"):
        caliper.create(model, regressors, height="168", weight="62kg")
    with pytest.raises(ValueError, match="unknown unit 'kg'"):  # InvalidInputError is a ValueError
        caliper.create(model, regressors, height="168kg", weight="62kg")
    with pytest.raises(caliper.InvalidInputError, match="height"):
        caliper.create(model, regressors, height=5.0, weight=62.0)  # 5 m: implausible
    with pytest.raises(caliper.InvalidInputError, match="height"):
        caliper.create(model, regressors, height=float("nan"), weight=62.0)
    with pytest.raises(caliper.InvalidInputError, match="R4 needs"):
        caliper.create(model, regressors, height="168cm", weight="62kg", regressor="R4")
    with pytest.raises(caliper.InvalidInputError, match="R7"):
        caliper.create(model, regressors, height="168cm", regressor="R7")
    with pytest.raises(caliper.InvalidInputError, match="no measurements"):
        caliper.create(model, regressors)
    with pytest.raises(caliper.InvalidInputError, match="betas: 99 values"):
        caliper.evaluate(model, np.zeros(99))
    with pytest.raises(caliper.InvalidInputError, match="poses: expected shape"):
        caliper.evaluate(model, np.zeros((2, 10)), np.zeros((2, 5)))
    with pytest.raises(caliper.InvalidInputError, match="dtype"):
        caliper.evaluate(model, np.zeros(10), dtype=np.int32)
    with pytest.raises(caliper.InvalidInputError, match="unknown avatar extension"):
        caliper.create(model, regressors, height="168cm", weight="62kg").save(
            os.path.join(work, "a.fbx"))
    with pytest.raises(caliper.InvalidInputError, match="either vertices"):
        caliper.measure(model)
    # force=True accepts an input outside the hard limits, with the message as a warning.
    a = caliper.create(model, regressors, height="168cm", weight="300kg", force=True)
    assert any("weight" in w or "BMI" in w for w in a.warnings)


def test_docstrings_everywhere():
    missing = [n for n in caliper.__all__
               if not n.startswith("_") and callable(getattr(caliper, n))
               and not (getattr(caliper, n).__doc__ or "").strip()]
    assert missing == []
    for cls in (caliper.BodyModel, caliper.Avatar, caliper.Regressors):
        for name, member in vars(cls).items():
            if name.startswith("_"):
                continue
            assert (member.__doc__ or "").strip(), f"{cls.__name__}.{name} has no docstring"
