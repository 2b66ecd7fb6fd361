#!/usr/bin/python3
"""Independent check of the open models' arms against ANSUR II, with numpy only.

Poses a committed model's mean body with both arms hanging (shoulder joints rotated 90 degrees
down, plain linear blend skinning written here from scratch, not the project's C++) and prints
  - the hanging shoulder-to-wrist length (acromion landmark at rest to the posed wrist
    landmark), the figure caliper-modelgen --validate reports for the mean body, and
  - the hanging wrist height above the soles, which the generator never sees. ANSUR II measures
    it on standing people with the arms hanging (wristheight); with --ansur DIR the survey
    means are printed beside it.

usage: tests/modelgen/hanging_arm_check.py assets/models/caliper-female.npz [--ansur DIR]
"""
import csv
import math
import sys

import numpy as np


def rot_z(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def main(argv):
    if len(argv) < 2:
        sys.exit(__doc__)
    d = np.load(argv[1], allow_pickle=False)
    names = list(d["landmark_names"])
    offsets, ids = d["landmark_offsets"], d["landmark_vertices"]
    parents = d["kintree_table"][0].astype(np.int64)
    v, weights = d["v_template"], d["weights"]
    joints = d["J_regressor"] @ v

    def landmark(name, verts):
        i = names.index(name)
        return verts[ids[offsets[i]:offsets[i + 1]]].mean(axis=0)

    local = [np.eye(3)] * len(parents)
    local[16] = rot_z(-math.pi / 2)  # left shoulder: arm along +x swings down
    local[17] = rot_z(math.pi / 2)   # right shoulder
    world = []
    for j, p in enumerate(parents):
        t = np.eye(4)
        t[:3, :3] = local[j]
        t[:3, 3] = joints[j] - (joints[p] if j > 0 else 0.0)
        world.append(t if j == 0 else world[p] @ t)
    a = np.stack(world)
    for j in range(len(parents)):
        a[j, :3, 3] -= a[j, :3, :3] @ joints[j]
    m = np.einsum("vj,jab->vab", weights, a)
    posed = np.einsum("vab,vb->va", m[:, :3, :3], v) + m[:, :3, 3]

    floor = v[:, 1].min()
    arm = np.mean([np.linalg.norm(landmark(s + "_wrist", posed) - landmark(s + "_shoulder", v))
                   for s in ("left", "right")])
    wrist = np.mean([landmark(s + "_wrist", posed)[1] for s in ("left", "right")]) - floor
    print(f"{argv[1]}: mean body, arms hanging")
    print(f"  shoulder-to-wrist (acromion to wrist): {1000 * arm:.1f} mm")
    print(f"  wrist height above the soles:          {1000 * wrist:.1f} mm")
    if "--ansur" in argv:
        folder = argv[argv.index("--ansur") + 1]
        for sex in ("FEMALE", "MALE"):
            with open(f"{folder}/ANSUR_II_{sex}_Public.csv", encoding="latin-1") as f:
                rows = list(csv.DictReader(f))
            arm_s = np.mean([float(r["acromionradialelength"]) + float(r["radialestylionlength"])
                             for r in rows])
            wrist_s = np.mean([float(r["wristheight"]) for r in rows])
            print(f"  ANSUR II {sex.lower()}: shoulder-to-wrist {arm_s:.1f} mm, "
                  f"wrist height {wrist_s:.1f} mm ({len(rows)} people)")


if __name__ == "__main__":
    main(sys.argv)
