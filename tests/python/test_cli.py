"""The Python module gives the `caliper` program's results for the same inputs, and
`python3 -m caliper` mirrors it."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import caliper

CLI = os.environ.get("CALIPER_CLI")
pytestmark = pytest.mark.skipif(not CLI, reason="CALIPER_CLI (the built caliper program) not set")

# The contract: betas to 1e-12, measurements to 1e-9 m (same C++ code, same inputs; the
# JSON numbers round-trip exactly, so in practice the differences are 0).
BETAS_TOL = 1e-12
MEASUREMENT_TOL = 1e-9

CASES = [
    ["--sex", "female", "--height", "168cm", "--weight", "62kg"],
    ["--sex", "male", "--height", "181cm", "--weight", "84kg", "--arm-span", "186cm",
     "--inseam", "84cm"],
    ["--sex", "female", "--height", "5ft6in", "--weight", "137lb", "--arm-span", "66in",
     "--inseam", "30in", "--hip-width", "35cm"],
    ["--sex", "neutral", "--height", "172cm", "--weight", "70kg", "--arm-span", "174cm",
     "--inseam", "80cm", "--hip-width", "34cm", "--arm-length", "57cm"],  # noise-aware
    ["--sex", "male", "--height", "175cm", "--weight", "80kg", "--regressor", "R6",
     "--arm-span", "178cm", "--inseam", "81cm", "--hip-width", "35cm", "--arm-length", "58cm"],
    ["--sex", "female", "--height", "160cm", "--weight", "55kg", "--exact-inputs"],
    ["--sex", "female", "--height", "165cm"],  # height alone: noise-aware
]


def run_json(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def option(args, name):
    return args[args.index(name) + 1] if name in args else None


def api_create(args, models, regs):
    sex = option(args, "--sex") or "neutral"
    kw = {}
    for opt, key in (("--height", "height"), ("--weight", "weight"), ("--arm-span", "arm_span"),
                     ("--inseam", "inseam"), ("--hip-width", "hip_width"),
                     ("--arm-length", "arm_length")):
        if option(args, opt):
            kw[key] = option(args, opt)
    return caliper.create(models[sex], regs[sex], regressor=option(args, "--regressor"),
                          exact_inputs="--exact-inputs" in args,
                          population=option(args, "--population"), **kw)


@pytest.fixture(scope="module")
def models():
    return {s: caliper.open_model(s) for s in caliper.SEXES}


@pytest.fixture(scope="module")
def regs(models):
    return {s: caliper.train_regressors(m) for s, m in models.items()}


def compare(report, betas, achieved, regressor):
    assert report["regressor"] == regressor
    np.testing.assert_allclose(betas, report["betas"], rtol=0, atol=BETAS_TOL)
    assert set(report["achieved"]) == set(achieved)
    for k, v in report["achieved"].items():
        # volume in m^3 and weight in kg are compared with the same absolute bound.
        assert abs(achieved[k] - v) <= MEASUREMENT_TOL, k


@pytest.mark.parametrize("args", CASES, ids=[" ".join(c[1:6]) for c in CASES])
def test_create_equals_cli(args, models, regs):
    report = run_json([CLI, "create", "--json", *args])
    a = api_create(args, models, regs)
    compare(report, a.betas, a.achieved, a.regressor)
    if a.betas_sd is not None:
        np.testing.assert_allclose(a.betas_sd, report["betas_sd"], rtol=0, atol=BETAS_TOL)


@pytest.mark.parametrize("args", CASES[:4], ids=[" ".join(c[1:6]) for c in CASES[:4]])
def test_python_m_caliper_equals_cli(args):
    report = run_json([CLI, "create", "--json", *args])
    mine = run_json([sys.executable, "-m", "caliper", "create", "--json", *args])
    compare(report, np.array(mine["betas"]), mine["achieved"], mine["regressor"])
    for key in ("input", "difference", "plausibility", "units"):
        assert mine[key].keys() == report[key].keys(), key


def test_population_equals_cli(models, regs):
    # `--population ansur2`: the noise-aware regressor with the soldiers' shapes as its prior,
    # the same avatar from the program, the module and `python3 -m caliper`.
    args = ["--sex", "female", "--height", "165cm", "--weight", "64kg", "--population", "ansur2"]
    report = run_json([CLI, "create", "--json", *args])
    a = api_create(args, models, regs)
    compare(report, a.betas, a.achieved, a.regressor)
    mine = run_json([sys.executable, "-m", "caliper", "create", "--json", *args])
    compare(report, np.array(mine["betas"]), mine["achieved"], mine["regressor"])
    assert report["population"] == mine["population"] == "ansur2"


def test_hanging_arm_equals_cli(models, regs):
    # `--arm-length-hanging`: the program and `python3 -m caliper` map the tape on the hanging arm
    # onto the model's arm length with the same map, and make the avatar of that arm length.
    args = ["--sex", "female", "--height", "168cm", "--weight", "62kg", "--arm-span", "170cm",
            "--inseam", "78cm", "--hip-width", "36cm", "--arm-length-hanging", "55cm"]
    report = run_json([CLI, "create", "--json", *args])
    mine = run_json([sys.executable, "-m", "caliper", "create", "--json", *args])
    compare(report, np.array(mine["betas"]), mine["achieved"], mine["regressor"])
    assert report["hanging_arm"].keys() == mine["hanging_arm"].keys()
    for k, v in report["hanging_arm"].items():
        assert abs(mine["hanging_arm"][k] - v) <= 1e-12, k
    arm = caliper.hanging_arm_map(models["female"])
    assert report["hanging_arm"]["measured"] == pytest.approx(0.55, abs=1e-12)
    virtual = arm["a"] * 0.55 + arm["b"]
    assert report["input"]["arm_length"] == pytest.approx(virtual, abs=1e-12)
    assert 0.40 < virtual < 0.53  # shorter than the hanging arm (the acromion is above the joint)
    a = caliper.create(models["female"], regs["female"], height="168cm", weight="62kg",
                       arm_span="170cm", inseam="78cm", hip_width="36cm", arm_length=virtual)
    compare(report, a.betas, a.achieved, a.regressor)
    r = subprocess.run([sys.executable, "-m", "caliper", "create", *args, "--arm-length", "50cm"],
                       capture_output=True, text=True, check=False)
    assert r.returncode == 2 and "not both" in r.stderr


def test_measure_equals_cli(models):
    betas = [0.5, -1.0, 0.25, 0.0, 1.5]
    report = run_json([CLI, "measure", "--sex", "male", "--json",
                       "--betas", ",".join(map(str, betas))])
    m = caliper.measure(models["male"], betas=betas)
    assert set(m) == set(report["measurements"])
    for k, v in report["measurements"].items():
        assert abs(m[k] - v) <= MEASUREMENT_TOL, k


def test_cli_measures_a_python_glb(work):
    out = os.path.join(work, "py.glb")
    mine = run_json([sys.executable, "-m", "caliper", "create", "--json", "--sex", "male",
                     "--height", "180cm", "--weight", "80kg", "--out", out])
    report = run_json([CLI, "measure", out, "--json"])
    assert report["model_chosen_by"] == "the avatar file"  # open_model_sex in asset.extras
    # The GLB stores float32 positions: 1e-6 m covers their rounding (|x| < 2 m, 2^-24 relative).
    assert abs(report["measurements"]["height"] - mine["achieved"]["height"]) < 1e-6


def test_python_m_caliper_exit_codes(work):
    def run(*args):
        return subprocess.run([sys.executable, "-m", "caliper", *args], capture_output=True,
                              text=True, check=False)
    r = run("create", "--height", "168", "--weight", "62kg")
    assert r.returncode == 2 and "--height '168': no unit given" in r.stderr
    r = run("create", "--height", "4m", "--weight", "62kg")
    assert r.returncode == 3 and "implausible" in r.stderr
    r = run("create", "--model", os.path.join(work, "missing.npz"), "--height", "168cm")
    assert r.returncode == 1 and "missing.npz" in r.stderr
    r = run("create", "--bogus")
    assert r.returncode == 2
    # A value no body has is refused even with --force, by both.
    r = run("create", "--height", "168cm", "--weight=-5kg", "--force")
    assert r.returncode == 3 and "weight = -5 kg must be positive" in r.stderr
    assert subprocess.run([CLI, "create", "--height", "168cm", "--weight=-5kg", "--force"],
                          capture_output=True, check=False).returncode == 3
    r = run("create", "--height", "168cm", "--weight", "62kg", "--population", "martians")
    assert r.returncode == 2 and "carries no population 'martians'" in r.stderr
    r = run("create", "--height", "168cm", "--weight", "62kg", "--population", "ansur2",
            "--regressor", "R2")
    assert r.returncode == 2 and "--population takes the noise-aware regressor" in r.stderr
    # The C++ program agrees on the same three.
    assert subprocess.run([CLI, "create", "--height", "168", "--weight", "62kg"],
                          capture_output=True, check=False).returncode == 2
    assert subprocess.run([CLI, "create", "--height", "4m", "--weight", "62kg"],
                          capture_output=True, check=False).returncode == 3
