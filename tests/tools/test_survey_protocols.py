#!/usr/bin/env python3
"""Tests of tools/survey_protocols.py on made-up survey files whose answer is known.

    python3 tests/tools/test_survey_protocols.py   (ctest: tools.survey_protocols)
"""

import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCRIPT = os.path.join(ROOT, "tools", "survey_protocols.py")
sys.path.insert(0, os.path.join(ROOT, "tools"))
import survey_protocols  # noqa: E402


def arm_mm(stature_m, weight_kg):
    """The made-up population's upper arm length (exactly linear in the fit's features)."""
    return 1000.0 * (0.02 + 0.18 * stature_m + 0.004 * weight_kg ** (1.0 / 3.0))


def hip_mm(stature_m, weight_kg):
    return 1000.0 * (0.10 + 0.30 * stature_m + 0.17 * weight_kg ** (1.0 / 3.0))


def write_surveys(folder, arm_offset_mm, heavy_offset_mm):
    """ANSUR-like and NHANES-like files of one sex: NHANES's arm `arm_offset_mm` longer than the
    ANSUR relation, and one person with BMI over 35 whose arm is `heavy_offset_mm` longer."""
    ansur = os.path.join(folder, "ansur.csv")
    nhanes = os.path.join(folder, "nhanes.csv")
    with open(ansur, "w", encoding="latin-1") as f:
        f.write("stature,weightkg,shoulderelbowlength,buttockcircumference\n")
        for i in range(40):
            h = 1.55 + 0.01 * (i % 10)
            w = 50.0 + 2.5 * (i // 4) + (i % 3)
            f.write(f"{h * 1000:.6f},{w * 10:.6f},{arm_mm(h, w):.9f},{hip_mm(h, w):.9f}\n")
    with open(nhanes, "w", encoding="latin-1") as f:
        f.write("# a description line\nBMXWT,BMXHT,BMXARML,BMXHIP\n")
        for i in range(20):
            h = 1.58 + 0.01 * (i % 7)
            w = 55.0 + 1.5 * i
            f.write(f"{w:.6f},{h * 100:.6f},{(arm_mm(h, w) + arm_offset_mm) / 10:.9f},"
                    f"{hip_mm(h, w) / 10:.9f}\n")
        h, w = 1.60, 120.0  # BMI 46.9
        f.write(f"{w:.6f},{h * 100:.6f},{(arm_mm(h, w) + heavy_offset_mm) / 10:.9f},"
                f"{hip_mm(h, w) / 10:.9f}\n")
    return ansur, nhanes


class Compare(unittest.TestCase):
    def test_an_offset_of_protocol_is_found_and_the_control_is_zero(self):
        with tempfile.TemporaryDirectory() as d:
            ansur, nhanes = write_surveys(d, 30.0, 500.0)
            rows = survey_protocols.compare(ansur, nhanes, 35.0)
            (arm_label, arm_n, arm_mean, _, arm_sd), (hip_label, hip_n, hip_mean, _, _) = rows
            self.assertIn("upper arm", arm_label)
            self.assertIn("hip", hip_label)
            self.assertEqual(arm_n, 20)  # the person over BMI 35 is left out
            self.assertAlmostEqual(arm_mean, 30.0, places=5)
            self.assertAlmostEqual(hip_mean, 0.0, places=5)
            self.assertLess(arm_sd, 1e-5)  # the ANSUR values are exactly linear
            with_heavy = survey_protocols.compare(ansur, nhanes, 100.0)[0]
            self.assertEqual(with_heavy[1], 21)
            self.assertAlmostEqual(with_heavy[2], 30.0 + 470.0 / 21, places=5)

    def test_a_bad_value_is_named(self):
        with tempfile.TemporaryDirectory() as d:
            ansur, nhanes = write_surveys(d, 0.0, 0.0)
            with open(nhanes, "a", encoding="latin-1") as f:
                f.write("60,-1,30,90\n")
            r = subprocess.run([sys.executable, SCRIPT, "--ansur-dir", d, "--nhanes-dir", d],
                               capture_output=True, text=True)
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("not found", r.stderr)  # the files do not have the survey names
            with self.assertRaises(SystemExit) as e:
                survey_protocols.compare(ansur, nhanes, 35.0)
            self.assertIn("BMXHT", str(e.exception))
            self.assertIn("not a positive number", str(e.exception))


if __name__ == "__main__":
    unittest.main()
