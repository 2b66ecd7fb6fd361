#!/usr/bin/env python3
"""Do ANSUR II and NHANES measure the same thing the same way? A check at equal height and weight.

The open models are fitted on both surveys (docs/models.md, "Shape space from real people"), so a
measurement fitted on both must mean the same in both. This script compares pairs of
measurements that the two surveys define on the same landmarks:

- upper arm length: ANSUR II `shoulderelbowlength` (acromion to the bottom of the elbow, elbow
  bent 90 degrees) and NHANES `BMXARML` (acromion to the olecranon, elbow bent 90 degrees);
- hip circumference: ANSUR II `buttockcircumference` and NHANES `BMXHIP` (both at the maximum
  protrusion of the buttocks), as a control.

For each sex it fits the ANSUR II value as a linear function of stature and the cube root of
weight (least squares, with an intercept), predicts it for every NHANES person of that sex with a
BMI below --max-bmi (ANSUR II has few people above 35, so the fit is not extrapolated far), and
prints the mean of NHANES minus prediction with its standard error, and the ANSUR II fit's
residual SD for scale. A difference of several residual SDs for a length that no population
difference at equal height and weight explains is a difference of measuring protocol.

Usage: tools/survey_protocols.py [--ansur-dir ../shared/data/ansur2]
                                 [--nhanes-dir ../shared/data/nhanes] [--max-bmi 35]

Plain Python (no numpy): the fits have three unknowns.
"""

import argparse
import csv
import math
import os
import sys

# (label, ANSUR II column (mm), NHANES column (cm))
PAIRS = [
    ("upper arm length (elbow bent 90 degrees)", "shoulderelbowlength", "BMXARML"),
    ("hip circumference (control)", "buttockcircumference", "BMXHIP"),
]


def read_rows(path, comment_lines=False):
    """The rows of a CSV file as dicts; `#` lines before the header skipped if asked."""
    with open(path, newline="", encoding="latin-1") as f:
        lines = [line for line in f if not (comment_lines and line.startswith("#"))]
    return list(csv.DictReader(lines))


def solve3(a, b):
    """Solves the 3x3 system a x = b (Gaussian elimination with partial pivoting)."""
    m = [row[:] + [v] for row, v in zip(a, b)]
    for i in range(3):
        p = max(range(i, 3), key=lambda r: abs(m[r][i]))
        m[i], m[p] = m[p], m[i]
        if m[i][i] == 0.0:
            raise ValueError("singular fit: the predictors are not independent")
        for r in range(i + 1, 3):
            f = m[r][i] / m[i][i]
            for c in range(i, 4):
                m[r][c] -= f * m[i][c]
    x = [0.0] * 3
    for i in reversed(range(3)):
        x[i] = (m[i][3] - sum(m[i][c] * x[c] for c in range(i + 1, 3))) / m[i][i]
    return x


def fit(features, values):
    """Least-squares coefficients of values ~ features (rows of [1, stature, cbrt(weight)])."""
    ata = [[sum(f[i] * f[j] for f in features) for j in range(3)] for i in range(3)]
    atb = [sum(f[i] * v for f, v in zip(features, values)) for i in range(3)]
    return solve3(ata, atb)


def predict(c, f):
    return sum(a * b for a, b in zip(c, f))


def number(row, column, path):
    try:
        v = float(row[column])
    except (KeyError, ValueError):
        sys.exit(f"{path}: column {column} is missing or not a number in some row")
    if not math.isfinite(v) or v <= 0.0:
        sys.exit(f"{path}: column {column} holds {row[column]!r}, not a positive number")
    return v


def compare(ansur_path, nhanes_path, max_bmi):
    """Rows (label, n_nhanes, mean difference mm, standard error mm, ANSUR residual SD mm)."""
    ansur = read_rows(ansur_path)
    nhanes = read_rows(nhanes_path, comment_lines=True)
    # ANSUR II: stature mm, weightkg in 0.1 kg; NHANES: BMXHT cm, BMXWT kg.
    a_feat = [[1.0, number(r, "stature", ansur_path) / 1000.0,
               (number(r, "weightkg", ansur_path) / 10.0) ** (1.0 / 3.0)] for r in ansur]
    people = []
    for r in nhanes:
        h = number(r, "BMXHT", nhanes_path) / 100.0
        w = number(r, "BMXWT", nhanes_path)
        if w / (h * h) < max_bmi:
            people.append((r, [1.0, h, w ** (1.0 / 3.0)]))
    if len(people) < 2:
        sys.exit(f"{nhanes_path}: fewer than 2 people with a BMI under {max_bmi}")
    out = []
    for label, a_col, n_col in PAIRS:
        y = [number(r, a_col, ansur_path) / 1000.0 for r in ansur]
        c = fit(a_feat, y)
        res = [v - predict(c, f) for f, v in zip(a_feat, y)]
        res_sd = math.sqrt(sum(e * e for e in res) / (len(res) - 3))
        d = [number(r, n_col, nhanes_path) / 100.0 - predict(c, f) for r, f in people]
        mean = sum(d) / len(d)
        sd = math.sqrt(sum((e - mean) ** 2 for e in d) / (len(d) - 1))
        out.append((label, len(d), 1000.0 * mean, 1000.0 * sd / math.sqrt(len(d)),
                    1000.0 * res_sd))
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--ansur-dir", default="../shared/data/ansur2")
    p.add_argument("--nhanes-dir", default="../shared/data/nhanes")
    p.add_argument("--max-bmi", type=float, default=35.0)
    args = p.parse_args()
    print(f"NHANES people with BMI under {args.max_bmi:g}; ANSUR II value predicted from stature "
          "and the cube root of weight; mm\n")
    print("| sex | measurement | NHANES people | NHANES - ANSUR II prediction | standard error "
          "| ANSUR II residual SD | in residual SDs |")
    print("|---|---|---|---|---|---|---|")
    for sex, ansur_file, nhanes_file in (
            ("female", "ANSUR_II_FEMALE_Public.csv", "NHANES_2017_2020_FEMALE_dev.csv"),
            ("male", "ANSUR_II_MALE_Public.csv", "NHANES_2017_2020_MALE_dev.csv")):
        paths = (os.path.join(args.ansur_dir, ansur_file), os.path.join(args.nhanes_dir, nhanes_file))
        for path in paths:
            if not os.path.isfile(path):
                sys.exit(f"{path}: not found (check --ansur-dir / --nhanes-dir)")
        for label, n, mean, se, res_sd in compare(*paths, args.max_bmi):
            print(f"| {sex} | {label} | {n} | {mean:+.1f} | {se:.1f} | {res_sd:.1f} "
                  f"| {mean / res_sd:+.1f} |")


if __name__ == "__main__":
    main()
