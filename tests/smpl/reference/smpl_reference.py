#!/usr/bin/python3
"""Independent numpy reference of the SMPL forward pass, written from the published equations
(Loper et al., "SMPL: A Skinned Multi-Person Linear Model", SIGGRAPH Asia 2015, eqs. 1-4, and the
step list in shared/reference/smpl-format.md), deliberately NOT from the C++ code: it uses the
normalised-axis form of Rodrigues' formula, dense matrices, explicit 4x4 homogeneous transforms
and numpy's einsum, so an error in the C++ cannot be copied here.

Usage: smpl_reference.py INPUT.npz OUTPUT.npz
INPUT keys: v_template (V,3), shapedirs (V,3,B), posedirs (V,3,P) or absent, J_regressor (K,V)
dense, weights (V,K) dense, parents (K,) int, betas (N,Bmax) with nbetas (N,) = how many of each
row are given (the rest are "missing" and treated as zero, as the C++ API pads), poses (N,3K),
trans (N,3).
OUTPUT keys: vertices (N,V,3), joints (N,K,3), transforms (N,K,4,4) world joint transforms.
"""
import sys

import numpy as np


def rodrigues(axis_angle):
    """R = cos t I + sin t [k]x + (1 - cos t) k k^T with k the unit axis; identity at t = 0."""
    theta = float(np.linalg.norm(axis_angle))
    if theta == 0.0:
        return np.eye(3)
    k = axis_angle / theta
    kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.cos(theta) * np.eye(3) + np.sin(theta) * kx + (1.0 - np.cos(theta)) * np.outer(k, k)


def forward(m, betas, pose, trans):
    K = m["parents"].shape[0]
    B = betas.shape[0]
    # 1. Shape blend shapes: B_S(beta) = sum_n beta_n S_n.
    v_shaped = m["v_template"] + np.einsum("vcb,b->vc", m["shapedirs"][:, :, :B], betas)
    # 2. Joints regressed from the shaped rest mesh.
    J = m["J_regressor"] @ v_shaped
    # 3. Local rotations.
    R = np.stack([rodrigues(pose[3 * k:3 * k + 3]) for k in range(K)])
    # 4-5. Pose blend shapes from (R_k - I), k >= 1, flattened row-major.
    v_posed = v_shaped
    if "posedirs" in m:
        feature = (R[1:] - np.eye(3)).reshape(-1)
        v_posed = v_shaped + np.einsum("vcp,p->vc", m["posedirs"], feature)
    # 6. Kinematic chain with 4x4 homogeneous matrices.
    G = np.zeros((K, 4, 4))
    for k in range(K):
        local = np.eye(4)
        local[:3, :3] = R[k]
        p = int(m["parents"][k])
        local[:3, 3] = J[k] if p < 0 else J[k] - J[p]
        G[k] = local if p < 0 else G[p] @ local
    # 7. Skinning matrices: world transform times the inverse rest (bind) transform.
    A = np.zeros((K, 4, 4))
    for k in range(K):
        bind_inverse = np.eye(4)
        bind_inverse[:3, 3] = -J[k]
        A[k] = G[k] @ bind_inverse
    # 8. Linear blend skinning in homogeneous coordinates, then the translation.
    T = np.einsum("vk,kij->vij", m["weights"], A)
    homog = np.concatenate([v_posed, np.ones((v_posed.shape[0], 1))], axis=1)
    verts = np.einsum("vij,vj->vi", T, homog)[:, :3] + trans
    joints = G[:, :3, 3] + trans
    Gt = G.copy()
    Gt[:, :3, 3] += trans
    return verts, joints, Gt


def main():
    data = np.load(sys.argv[1], allow_pickle=False)
    m = {key: data[key] for key in ("v_template", "shapedirs", "J_regressor", "weights", "parents")}
    if "posedirs" in data.files:
        m["posedirs"] = data["posedirs"]
    out_v, out_j, out_g = [], [], []
    for i in range(data["poses"].shape[0]):
        n = int(data["nbetas"][i])
        v, j, g = forward(m, data["betas"][i, :n], data["poses"][i], data["trans"][i])
        out_v.append(v)
        out_j.append(j)
        out_g.append(g)
    np.savez(sys.argv[2], vertices=np.stack(out_v), joints=np.stack(out_j), transforms=np.stack(out_g))


if __name__ == "__main__":
    main()
