#!/usr/bin/env python3
"""Do the avatars' arms have the girth of real people's? R2 avatars against NHANES's BMXARMC.

The open models are fitted on NHANES's mid-upper-arm circumference (docs/models.md, "The arm's
girth"). This script makes every NHANES development subject's R2 avatar from their height and
weight (the product's path: `caliper.create(..., regressor='R2')`, from the model's shape curve),
measures its mid-upper-arm girth as the generator does (apps/modelgen/src/makehuman_measures.cpp,
`upper_arm_circumference`: the left arm's slice x = the midpoint of the acromion and radiale
landmarks, the convex hull of the section's points around the midpoint of the SMPL shoulder and
elbow joints), and prints, by BMI bin, the mean of NHANES and of the avatars, the avatars' bias
and MAE, and the MAE of a linear fit of the girth on height and weight cross-validated on the
same people (10 folds by row number), the baseline `caliper evaluate nhanes` uses for the hip
and the waist. The libcaliper measurements do not include the arm's girth, so this is a
separate check (figures in docs/evaluation.md, section 4).

Usage: PYTHONPATH=build/python tools/nhanes_arm_girth.py [--nhanes-dir ../shared/data/nhanes]
       [--sex female|male] [--every N]
"""
import argparse
import csv
import os

import numpy as np
from scipy.spatial import ConvexHull

import caliper

BINS = [(0, 20), (20, 25), (25, 30), (30, 35), (35, 40), (40, 50), (50, 1000)]
SECTION_RADIUS = 0.10  # m around the humerus's midpoint: the arm's section, not the torso's


def read_nhanes(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    col = lambda name: np.array([float(r[name]) for r in rows])
    return col("BMXHT") / 100.0, col("BMXWT"), col("BMXARMC") / 100.0


def arm_girth(model, vertices):
    v = np.asarray(vertices)
    faces = np.asarray(model.faces)
    joints = np.asarray(model.j_regressor) @ v
    shoulder = v[model.landmarks["left_shoulder"][0]]
    radiale = v[model.landmarks["left_radiale"][0]]
    humerus = 0.5 * (joints[16] + joints[18])  # SMPL's left shoulder and elbow joints
    x0 = 0.5 * (shoulder[0] + radiale[0])
    points = []
    for a, b in ((0, 1), (1, 2), (2, 0)):
        p, q = v[faces[:, a]], v[faces[:, b]]
        dp, dq = p[:, 0] - x0, q[:, 0] - x0
        crossing = dp * dq < 0
        t = dp[crossing] / (dp[crossing] - dq[crossing])
        points.append(p[crossing] + (q[crossing] - p[crossing]) * t[:, None])
    section = np.concatenate(points)[:, 1:3]
    section = section[np.linalg.norm(section - humerus[1:3], axis=1) < SECTION_RADIUS]
    return ConvexHull(section).area  # of a 2-D hull: its perimeter


def baseline_errors(height, weight, girth):
    x = np.c_[np.ones_like(height), height, weight]
    pred = np.zeros_like(girth)
    fold = np.arange(len(girth)) % 10
    for k in range(10):
        coef = np.linalg.lstsq(x[fold != k], girth[fold != k], rcond=None)[0]
        pred[fold == k] = x[fold == k] @ coef
    return np.abs(pred - girth)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--nhanes-dir", default=os.path.join(here, "..", "..", "shared", "data", "nhanes"))
    parser.add_argument("--sex", choices=["female", "male"], action="append")
    parser.add_argument("--every", type=int, default=1, help="every N-th subject (default: all)")
    args = parser.parse_args()
    for sex in args.sex or ["female", "male"]:
        model = caliper.open_model(sex)
        regressors = caliper.train_regressors(model)
        path = os.path.join(args.nhanes_dir, f"NHANES_2017_2020_{sex.upper()}_dev.csv")
        height, weight, armc = read_nhanes(path)
        keep = np.arange(len(height)) % args.every == 0
        height, weight, armc = height[keep], weight[keep], armc[keep]
        avatar = np.array([
            arm_girth(model, caliper.create(model, regressors, height=h, weight=w,
                                            regressor="R2", force=True).vertices)
            for h, w in zip(height, weight)])
        base = baseline_errors(height, weight, armc)
        bmi = weight / height**2
        print(f"{sex}: {len(height)} NHANES subjects, {path}; mm")
        print("| BMI | people | NHANES mean | avatar mean | bias | MAE | baseline MAE | ratio |")
        print("|---|---|---|---|---|---|---|---|")
        for lo, hi in BINS + [(0, 1000)]:
            s = (bmi >= lo) & (bmi < hi)
            if not s.any():
                continue
            if (lo, hi) == (0, 1000):
                name = "all"
            else:
                name = f"<{hi}" if lo == 0 else (f">{lo}" if hi == 1000 else f"{lo}-{hi}")
            err = avatar[s] - armc[s]
            mae = np.abs(err).mean() * 1000
            print(f"| {name} | {s.sum()} | {armc[s].mean() * 1000:.0f} | {avatar[s].mean() * 1000:.0f} "
                  f"| {err.mean() * 1000:+.1f} | {mae:.1f} | {base[s].mean() * 1000:.1f} "
                  f"| {mae / (base[s].mean() * 1000):.2f} |")


if __name__ == "__main__":
    main()
