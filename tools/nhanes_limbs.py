#!/usr/bin/env python3
"""Do the avatars' limbs have real people's proportions? R2 avatars against NHANES's limbs.

The open models are fitted on NHANES's mid-upper-arm circumference and upper leg length
(docs/models.md, "The arm's girth", "The upper leg"). This script makes every NHANES development
subject's R2 avatar from their height and weight (the product's path: `caliper.create(...,
regressor='R2')`, from the model's shape curve), measures on it what the generator fits
(apps/modelgen/src/makehuman_measures.cpp):
- `upper_arm_circumference`: the left arm's slice x = the midpoint of the acromion and radiale
  landmarks, the convex hull of the section's points around the midpoint of the SMPL shoulder
  and elbow joints; against NHANES's BMXARMC;
- `upper_leg_length`: the trochanterion's height over the lateral femoral epicondyle's (the
  model's `left_trochanterion` and `left_knee_lateral` landmarks, where the generator fitted
  them); against NHANES's BMXLEG mapped onto ANSUR II's trochanterion-to-epicondyle height
  (minus the mean difference at equal stature and cube root of weight under BMI 35, as the
  generator maps it; --ansur-dir);
and prints, by BMI bin, the mean of NHANES and of the avatars, the avatars' bias and MAE, and the
MAE of a linear fit of the measurement on height and weight cross-validated on the same people
(10 folds by row number), the baseline `caliper evaluate nhanes` uses for the hip and the waist.
The libcaliper measurements include neither, so this is a separate check (figures in
docs/evaluation.md, section 4).

Usage: PYTHONPATH=build/python tools/nhanes_limbs.py [--nhanes-dir ../shared/data/nhanes]
       [--ansur-dir ../shared/data/ansur2] [--model-dir DIR] [--sex female|male] [--every N]
"""
import argparse
import csv
import os

import numpy as np
from scipy.spatial import ConvexHull

import caliper

BINS = [(0, 20), (20, 25), (25, 30), (30, 35), (35, 40), (40, 50), (50, 1000)]
SECTION_RADIUS = 0.10  # m around the humerus's midpoint: the arm's section, not the torso's


def read_csv(path, names):
    with open(path, newline="", encoding="latin-1") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    return [np.array([float(r[name]) for r in rows]) for name in names]


def read_nhanes(path):
    height, weight, armc, leg = read_csv(path, ["BMXHT", "BMXWT", "BMXARMC", "BMXLEG"])
    return height / 100.0, weight, armc / 100.0, leg / 100.0


def leg_offset(ansur_path, height, weight, leg):
    """NHANES's BMXLEG minus ANSUR II's trochanterion-to-epicondyle height predicted at the NHANES
    person's stature and cube root of weight, averaged under BMI 35 (metres)."""
    stature, kg10, troch, epi = read_csv(
        ansur_path, ["stature", "weightkg", "trochanterionheight", "lateralfemoralepicondyleheight"])
    x = np.c_[np.ones_like(stature), stature / 1000.0, np.cbrt(kg10 / 10.0)]
    coef = np.linalg.lstsq(x, (troch - epi) / 1000.0, rcond=None)[0]
    under = weight / height**2 < 35.0
    pred = np.c_[np.ones_like(height), height, np.cbrt(weight)] @ coef
    return float(np.mean(leg[under] - pred[under]))


def leg_points(model):
    """The upper leg's ends where the generator fitted them: the model's `left_trochanterion`
    landmark (the mean of its vertex ids, a point on an edge) and `left_knee_lateral` vertex."""
    landmarks = model.landmarks
    missing = [n for n in ("left_trochanterion", "left_knee_lateral") if n not in landmarks]
    if missing:
        raise SystemExit(f"nhanes_limbs: the model has no {' or '.join(missing)} landmark (open "
                         "models made before the upper leg was fitted, 2026-12-07, and SMPL files "
                         "lack them); regenerate the models with caliper-modelgen or leave out "
                         "--model-dir to judge the committed ones")
    return list(landmarks["left_trochanterion"]), landmarks["left_knee_lateral"][0]


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
    parser.add_argument("--ansur-dir", default=os.path.join(here, "..", "..", "shared", "data", "ansur2"))
    parser.add_argument("--model-dir", help="folder of caliper-<sex>.npz (default: the committed models)")
    parser.add_argument("--sex", choices=["female", "male"], action="append")
    parser.add_argument("--every", type=int, default=1, help="every N-th subject (default: all)")
    args = parser.parse_args()
    for sex in args.sex or ["female", "male"]:
        model = (caliper.load_model(os.path.join(args.model_dir, f"caliper-{sex}.npz"))
                 if args.model_dir else caliper.open_model(sex))
        trochanterion, knee = leg_points(model)  # before the slow part: refuse a model early
        regressors = caliper.train_regressors(model)
        path = os.path.join(args.nhanes_dir, f"NHANES_2017_2020_{sex.upper()}_dev.csv")
        height, weight, armc, leg = read_nhanes(path)
        offset = leg_offset(os.path.join(args.ansur_dir, f"ANSUR_II_{sex.upper()}_Public.csv"),
                            height, weight, leg)
        keep = np.arange(len(height)) % args.every == 0
        height, weight, armc, leg = height[keep], weight[keep], armc[keep], leg[keep] - offset
        arm, thigh = [], []
        for h, w in zip(height, weight):
            v = np.asarray(caliper.create(model, regressors, height=h, weight=w,
                                          regressor="R2", force=True).vertices)
            arm.append(arm_girth(model, v))
            thigh.append(v[trochanterion, 1].mean() - v[knee, 1])
        print(f"{sex}: {len(height)} NHANES subjects, {path}; mm")
        print(f"upper leg: BMXLEG minus {offset * 1000:.1f} mm (ANSUR II's trochanterion-to-"
              "epicondyle height at equal stature and weight under BMI 35)")
        for name, survey, avatar in (("mid-upper-arm circumference", armc, np.array(arm)),
                                     ("upper leg length", leg, np.array(thigh))):
            print_table(name, height, weight, survey, avatar)


def print_table(name, height, weight, survey, avatar):
    base = baseline_errors(height, weight, survey)
    bmi = weight / height**2
    print(f"\n{name}")
    print("| BMI | people | NHANES mean | avatar mean | bias | MAE | baseline MAE | ratio |")
    print("|---|---|---|---|---|---|---|---|")
    for lo, hi in BINS + [(0, 1000)]:
        s = (bmi >= lo) & (bmi < hi)
        if not s.any():
            continue
        if (lo, hi) == (0, 1000):
            label = "all"
        else:
            label = f"<{hi}" if lo == 0 else (f">{lo}" if hi == 1000 else f"{lo}-{hi}")
        err = avatar[s] - survey[s]
        mae = np.abs(err).mean() * 1000
        print(f"| {label} | {s.sum()} | {survey[s].mean() * 1000:.0f} | {avatar[s].mean() * 1000:.0f} "
              f"| {err.mean() * 1000:+.1f} | {mae:.1f} | {base[s].mean() * 1000:.1f} "
              f"| {mae / (base[s].mean() * 1000):.2f} |")


if __name__ == "__main__":
    main()
