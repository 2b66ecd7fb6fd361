"""From smplx to caliper: the module's arrays are the ones smplx keeps, and smplx's forward pass
written in numpy on those arrays (smplx.lbs.lbs, without smplx installed) gives caliper.evaluate's
vertices. docs/library.md states the correspondence this test checks."""
import os

import numpy as np

import caliper

# Two implementations of the same double-precision arithmetic in a different order (numpy's
# einsum/matmul vs Eigen): they agree to rounding, far below a micrometre for bodies of ~2 m.
TOL_M = 1e-9


def rodrigues(rvec):
    """smplx.lbs.batch_rodrigues for one joint (numpy)."""
    angle = np.linalg.norm(rvec)
    if angle < 1e-12:
        return np.eye(3)
    k = rvec / angle
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * kx + (1 - np.cos(angle)) * kx @ kx


def smplx_lbs(betas, pose, v_template, shapedirs, posedirs_smplx, j_regressor, parents,
              lbs_weights):
    """smplx.lbs.lbs for one body, in numpy, with smplx's own array layouts."""
    v_shaped = v_template + np.einsum("l,vcl->vc", betas, shapedirs[:, :, :betas.size])
    joints = j_regressor @ v_shaped
    rot = np.stack([rodrigues(r) for r in pose.reshape(-1, 3)])
    pose_feature = (rot[1:] - np.eye(3)).reshape(-1)
    v_posed = v_shaped + (pose_feature @ posedirs_smplx).reshape(-1, 3)
    k = len(parents)
    transforms = np.zeros((k, 4, 4))
    for j in range(k):
        local = np.eye(4)
        local[:3, :3] = rot[j]
        local[:3, 3] = joints[j] - (joints[parents[j]] if j > 0 else 0)
        transforms[j] = local if j == 0 else transforms[parents[j]] @ local
    posed_joints = transforms[:, :3, 3].copy()
    rel = transforms.copy()
    rel[:, :3, 3] -= np.einsum("kij,kj->ki", transforms[:, :3, :3], joints)
    t = np.einsum("vk,kij->vij", lbs_weights, rel)
    v = np.einsum("vij,vj->vi", t[:, :3, :3], v_posed) + t[:, :3, 3]
    return v, posed_joints


def write_smpl_npz(path, model, rng):
    """An SMPL-format .npz (the keys smplx reads) from the open model's arrays plus pose blend
    shapes of SMPL's size (the open models have none): the file both libraries would load."""
    v, k = model.num_vertices, model.num_joints
    names = sorted(model.landmarks)  # the open model's landmark table (SMPL uses a built-in one)
    offsets = np.cumsum([0] + [len(model.landmarks[n]) for n in names])
    ids = np.concatenate([model.landmarks[n] for n in names]).astype(np.int64)
    np.savez(path, v_template=model.v_template, f=model.faces.astype(np.uint32),
             landmark_names=np.array(names), landmark_offsets=offsets, landmark_vertices=ids,
             meta_gender=np.array("female"),
             shapedirs=model.shapedirs,
             posedirs=rng.normal(scale=2e-3, size=(v, 3, 9 * (k - 1))),
             J_regressor=model.j_regressor, weights=model.weights,
             kintree_table=np.stack([np.array(model.parents, dtype=np.int64),
                                     np.arange(k, dtype=np.int64)]))


def test_same_arrays_same_vertices(work):
    rng = np.random.default_rng(3)
    path = os.path.join(work, "smpl_like.npz")
    write_smpl_npz(path, caliper.open_model("female"), rng)
    model = caliper.load_model(path)                     # smplx.SMPL(model_path=path) alike
    assert model.num_pose_features == 9 * (model.num_joints - 1)
    with np.load(path) as f:                             # the file's arrays, as smplx reads them
        np.testing.assert_array_equal(model.v_template, f["v_template"])
        np.testing.assert_array_equal(model.shapedirs, f["shapedirs"])
        np.testing.assert_array_equal(model.posedirs, f["posedirs"])
        posedirs_smplx = f["posedirs"].reshape(-1, model.num_pose_features).T  # (P, 3V)
        j_regressor = f["J_regressor"]                   # (K, V): smplx's J_regressor
        lbs_weights = f["weights"]                       # (V, K): smplx's lbs_weights
        parents = f["kintree_table"][0].copy()           # smplx's parents
        parents[0] = -1
    np.testing.assert_array_equal(model.j_regressor, j_regressor)
    np.testing.assert_array_equal(model.weights, lbs_weights)
    assert model.parents == parents.tolist()
    # smplx's posedirs buffer is caliper's posedirs reshaped: the same numbers.
    np.testing.assert_array_equal(model.posedirs.reshape(-1, model.num_pose_features).T,
                                  posedirs_smplx)
    betas = rng.normal(size=(4, 10))
    poses = rng.normal(scale=0.4, size=(4, 3 * model.num_joints))
    verts, joints = caliper.evaluate(model, betas, poses, joints=True)
    for i in range(4):
        ref_v, ref_j = smplx_lbs(betas[i], poses[i], model.v_template, model.shapedirs,
                                 posedirs_smplx, j_regressor, parents, lbs_weights)
        np.testing.assert_allclose(verts[i], ref_v, rtol=0, atol=TOL_M)
        np.testing.assert_allclose(joints[i], ref_j, rtol=0, atol=TOL_M)
    # Then an avatar from measurements, and the same vertices from the smplx-style pass.
    regs = caliper.train_regressors(model)
    avatar = caliper.create(model, regs, height="168cm", weight="62kg")
    rest, _ = smplx_lbs(avatar.betas, np.zeros(3 * model.num_joints), model.v_template,
                        model.shapedirs, posedirs_smplx, j_regressor, parents, lbs_weights)
    np.testing.assert_allclose(rest, avatar.vertices, rtol=0, atol=TOL_M)
    assert abs(caliper.measure(model, rest)["height"] - avatar.achieved["height"]) < TOL_M


def test_pkl_and_npz_give_the_same_model(work):
    """SMPL ships .pkl files (smplx reads them with pickle); caliper's restricted unpickler reads
    a pickle of the same dict of numpy arrays to the same model as the .npz."""
    import pickle
    rng = np.random.default_rng(5)
    npz = os.path.join(work, "m.npz")
    write_smpl_npz(npz, caliper.open_model("male"), rng)
    with np.load(npz) as f:
        # SMPL's own keys (text arrays such as landmark_names are not in SMPL pickles).
        data = {k: f[k] for k in ("v_template", "f", "shapedirs", "posedirs", "J_regressor",
                                  "weights", "kintree_table")}
    pkl = os.path.join(work, "m.pkl")
    with open(pkl, "wb") as f:
        pickle.dump(data, f, protocol=4)  # protocol 2 from Python 3 needs _codecs (refused)
    a, b = caliper.load_model(npz), caliper.load_model(pkl)
    for name in ("v_template", "faces", "shapedirs", "posedirs", "j_regressor", "weights"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.parents == b.parents
    betas = rng.normal(size=(2, 10))
    poses = rng.normal(scale=0.3, size=(2, 3 * a.num_joints))
    np.testing.assert_array_equal(caliper.evaluate(a, betas, poses), caliper.evaluate(b, betas, poses))
