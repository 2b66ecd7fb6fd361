#!/usr/bin/env python3
"""Side-by-side timing of libsmpl (bench_smpl) and the smplx PyTorch package on one core.

Not run in CI (it needs PyTorch and a smplx checkout). Usage:

    tools/bench_vs_smplx.py --smplx ~/src/smplx [--model ~/models/SMPL_NEUTRAL.pkl] \\
        [--bench build/bin/bench_smpl] [--core 1] [--rounds 5] [--batches 1,64,4096] [--two-cores]

Model: an SMPL file (.pkl, or an .npz with the same keys) both sides load; without --model,
bench_smpl writes its own full-size random SMPL-shaped model (6890 vertices, 10 betas, 207 pose
features; bench_smpl --write_model) to a temporary .npz and both sides use that.

Before timing, the script checks that both sides compute the same bodies: bench_smpl
--write_reference gives 8 bodies' betas, poses and libsmpl's vertices and joints (shape only,
posed with double and with float pose blend shapes), smplx evaluates the same inputs in float64
and float32, and the largest differences are printed; above --tolerance metres the script stops.

Both sides run pinned to the same core (--core), one thread each (torch.set_num_threads(1); the
batch API with one thread), and in interleaved rounds: each round times every case with smplx,
then runs bench_smpl once for every case, so slow phases of a shared machine hit both sides.
Cases: shape only (smplx: its forward() with a zero pose, and forward_shape(), which gives the
vertices without joints; libsmpl: shape_batch, vertices and joints) and posed (random pose),
float32 and float64, every batch size; libsmpl runs the SIMD variant it picks for the CPU
(or --simd's). libsmpl's posed "float" is its single-precision pose blend shapes (vertices
stay double); its shape-only float32 rows are shape_batch into float vertices and joints
(smpl::BodyBatchF), the float64 rows shape_batch into double ones. Times are CPU time per
body. For each case the table gives the median per-body time of each side over the rounds and
the speed-up smplx / libsmpl (above 1: libsmpl is faster) as the median of the per-round
speed-ups with their range (min-max), so the spread shows how noisy the machine was.

--two-cores adds, in every round, the two-core throughput: smplx posed (float32 and float64) with
torch.set_num_threads(2) and libsmpl's shape only with two threads (bench_smpl's
BM_ShapeBatch/<variant>/N/2/real_time), both on every core the script may use, wall time; it
prints bodies/s per batch size and libsmpl's best shape-only throughput over smplx's best posed.

--caliper-only times only the libsmpl side (no PyTorch needed); the smplx columns read "-".
"""
import argparse
import contextlib
import io
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def parse_args(argv):
    p = argparse.ArgumentParser(
        description="Time libsmpl against smplx (PyTorch) on one core, interleaved rounds.")
    p.add_argument("--smplx", help="path of a checkout of the smplx package (the folder that "
                   "contains the smplx/ package directory); required unless --caliper-only")
    p.add_argument("--model", help="SMPL model file (.pkl or .npz) both sides load (default: "
                   "bench_smpl's full-size random SMPL-shaped model, written to a temporary .npz)")
    p.add_argument("--bench", default=os.path.join("build", "bin", "bench_smpl"),
                   help="the bench_smpl program of a Release build (default: %(default)s)")
    p.add_argument("--core", type=int, default=1, help="CPU core both sides run on (default 1)")
    p.add_argument("--rounds", type=int, default=5, help="interleaved rounds (default 5)")
    p.add_argument("--batches", default="1,64,4096",
                   help="comma-separated batch sizes (default: %(default)s)")
    p.add_argument("--min-time", type=float, default=0.3,
                   help="seconds each side spends per case per round (default 0.3)")
    p.add_argument("--simd", help="libsmpl SIMD variant to time (baseline, avx2, avx512; "
                   "default: the one libsmpl picks on this CPU)")
    p.add_argument("--two-cores", action="store_true",
                   help="also time smplx posed with 2 torch threads and libsmpl shape only with 2 "
                   "threads on every core available (wall time, bodies/s)")
    p.add_argument("--tolerance", type=float, default=1e-5,
                   help="largest vertex or joint difference in metres between the sides before "
                   "timing (default %(default)g)")
    p.add_argument("--caliper-only", action="store_true",
                   help="time only libsmpl (no PyTorch or smplx needed)")
    a = p.parse_args(argv)
    errors = []
    try:
        a.batch_sizes = [int(x) for x in a.batches.split(",") if x.strip()]
        if not a.batch_sizes or min(a.batch_sizes) < 1:
            raise ValueError
    except ValueError:
        errors.append("--batches %r: give positive integers separated by commas, e.g. 1,64,4096"
                      % a.batches)
    if a.rounds < 1:
        errors.append("--rounds %d: give at least 1" % a.rounds)
    if a.model is not None and not os.path.isfile(a.model):
        errors.append("--model %s: no such file (give an SMPL .pkl or .npz)" % a.model)
    if not (os.path.isfile(a.bench) and os.access(a.bench, os.X_OK)):
        errors.append("--bench %s: not an executable; build it with "
                      "`cmake --build --preset release --target bench_smpl`" % a.bench)
    if not a.caliper_only:
        if not a.smplx:
            errors.append("--smplx is required (the path of your smplx checkout), or use "
                          "--caliper-only")
        elif not os.path.isdir(os.path.join(a.smplx, "smplx")):
            errors.append("--smplx %s: no smplx/ package folder in it; give the folder of the "
                          "smplx repository checkout" % a.smplx)
    a.all_cores = sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else []
    if a.all_cores and a.core not in a.all_cores:
        errors.append("--core %d: not available to this process (available: %s)"
                      % (a.core, a.all_cores))
    if a.two_cores and len(a.all_cores) < 2:
        errors.append("--two-cores: this process may use only the cores %s" % a.all_cores)
    if errors:
        p.error("; ".join(errors))
    return a


# "vshape": smplx's forward_shape() (vertices only: template plus shape blend shapes, no joints),
# its cheapest shape path, against the same libsmpl shape_batch figure as "shape".
CASES = [("shape", "float32"), ("shape", "float64"), ("vshape", "float32"), ("vshape", "float64"),
         ("posed", "float32"), ("posed", "float64")]
KIND_LABEL = {"shape": "shape", "vshape": "shape (smplx forward_shape)", "posed": "posed"}
SECONDS = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}


def run_bench(args, extra, env_extra=None, cores=None):
    """bench_smpl with the model file, pinned to `cores` (default: --core); returns its stdout."""
    env = dict(os.environ, CALIPER_BENCH_MODEL=os.path.abspath(args.model),
               **(env_extra or {}))
    cpus = ",".join(str(c) for c in cores) if cores else str(args.core)
    cmd = ["taskset", "-c", cpus, args.bench] + extra
    return subprocess.run(cmd, env=env, check=True, stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, universal_newlines=True).stdout


def caliper_round(args, two_cores=False):
    """One bench_smpl run over every case; returns ({(kind, dtype, n): seconds per body}, variant).

    One core: CPU time of the batch-API rows with one thread. two_cores: wall time of the
    shape-only rows with two threads, keyed ("shape2", "float64", n)."""
    sizes = ",".join(str(n) for n in args.batch_sizes)
    filt = (r"^BM_ShapeBatch/[a-z0-9]+/[0-9]+/2/real_time$" if two_cores
            else r"^BM_(ShapeBatchF?|EvaluateBatch)/[a-z0-9]+/[0-9/]+/1$")
    out = run_bench(args, ["--benchmark_format=json", "--benchmark_min_time=%g" % args.min_time,
                           "--benchmark_filter=" + filt],
                    {"CALIPER_BENCH_BATCH_SIZES": sizes},
                    args.all_cores if two_cores else None)
    report = json.loads(out)
    variant = args.simd or report["context"].get("simd_default", "")
    if variant not in report["context"].get("simd_levels", "").split():
        sys.exit("bench_vs_smplx: --simd %s: bench_smpl has only %s on this CPU"
                 % (variant, report["context"].get("simd_levels", "")))
    result = {}
    for b in report["benchmarks"]:
        parts = b["name"].split("/")  # BM_ShapeBatch/avx2/N/threads or BM_EvaluateBatch/...
        if parts[1] != variant:
            continue  # the variant asked for, else the one this CPU picks by default
        n = int(parts[2])
        t = b["real_time" if two_cores else "cpu_time"] * SECONDS[b["time_unit"]] / n
        if two_cores:
            result[("shape2", "float64", n)] = t
        elif parts[0] == "BM_ShapeBatch":  # double vertices and joints
            for kind in ("shape", "vshape"):
                result[(kind, "float64", n)] = t
        elif parts[0] == "BM_ShapeBatchF":  # float vertices and joints (BodyBatchF)
            for kind in ("shape", "vshape"):
                result[(kind, "float32", n)] = t
        else:
            result[("posed", "float32" if parts[3] == "1" else "float64", n)] = t
    return result, variant


class SmplxSide:
    """smplx forward passes, one thread on the pinned core (or two threads on two cores)."""

    def __init__(self, args):
        sys.path.insert(0, os.path.abspath(args.smplx))
        try:
            import numpy
            import torch
            import smplx
            from smplx.utils import Struct
        except ImportError as e:
            sys.exit("bench_vs_smplx: cannot import numpy, PyTorch or smplx (%s); install PyTorch "
                     "and give --smplx the path of a smplx checkout, or use --caliper-only" % e)
        self.np, self.torch, self.smplx = numpy, torch, smplx
        # smplx.SMPL unpickles model_path; an .npz is given to it as the data_struct it expects.
        self.data = None
        if args.model.endswith(".npz"):
            with numpy.load(args.model) as z:
                self.data = Struct(**{k: z[k] for k in z.files})
        torch.set_num_threads(1)
        self.args = args
        self.models = {}

    def model(self, dtype, n):
        key = (dtype, n)
        if key not in self.models:
            with contextlib.redirect_stdout(io.StringIO()):  # its warning about 10 betas
                self.models[key] = self.smplx.SMPL(
                    model_path=self.args.model, data_struct=self.data, batch_size=n, num_betas=10,
                    dtype=getattr(self.torch, dtype))
        return self.models[key]

    def forward(self, dtype, betas, poses):
        """Vertices and joints (as numpy float64) for N x 10 betas and N x 72 poses."""
        torch = self.torch
        t = getattr(torch, dtype)
        n = betas.shape[0]
        with torch.no_grad():
            out = self.model(dtype, n)(betas=torch.tensor(betas, dtype=t),
                                       global_orient=torch.tensor(poses[:, :3], dtype=t),
                                       body_pose=torch.tensor(poses[:, 3:], dtype=t))
        return out.vertices.double().numpy(), out.joints.double().numpy()

    def forward_shape(self, dtype, betas):
        """forward_shape()'s vertices (as numpy float64) for N x 10 betas."""
        torch = self.torch
        with torch.no_grad():
            out = self.model(dtype, betas.shape[0]).forward_shape(
                betas=torch.tensor(betas, dtype=getattr(torch, dtype)))
        return out.vertices.double().numpy()

    def time(self, kind, dtype, n, wall=False):
        """Median seconds per body of forward() (CPU time, or wall time when `wall`)."""
        torch = self.torch
        t = getattr(torch, dtype)
        m = self.model(dtype, n)
        g = torch.Generator().manual_seed(n)
        betas = torch.randn(n, 10, generator=g, dtype=t)
        body_pose = (0.3 * torch.randn(n, 69, generator=g, dtype=t) if kind == "posed"
                     else torch.zeros(n, 69, dtype=t))
        orient = torch.zeros(n, 3, dtype=t)
        clock = time.perf_counter if wall else time.process_time

        def call():
            if kind == "vshape":
                return m.forward_shape(betas=betas)
            return m(betas=betas, body_pose=body_pose, global_orient=orient)

        with torch.no_grad():
            call()  # warm-up
            times = []
            spent = 0.0
            while spent < self.args.min_time or len(times) < 3:
                t0 = clock()
                call()
                dt = clock() - t0
                times.append(dt)
                spent += dt
        return statistics.median(times) / n

    def time_two_cores(self):
        """{("posed", dtype, n): wall seconds per body} with two torch threads on every core."""
        os.sched_setaffinity(0, self.args.all_cores)
        self.torch.set_num_threads(2)
        try:
            return {("posed", d, n): self.time("posed", d, n, wall=True)
                    for d in ("float32", "float64") for n in self.args.batch_sizes}
        finally:
            self.torch.set_num_threads(1)
            os.sched_setaffinity(0, {self.args.core})


def check_same_bodies(args, side):
    """Stops unless smplx and libsmpl give the same vertices and joints for the same inputs."""
    np = side.np
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "reference.npz")
        run_bench(args, ["--write_reference=" + path])
        with np.load(path) as z:
            ref = {k: z[k] for k in z.files}
    betas, poses = ref["betas"], ref["poses"]
    n = betas.shape[0]
    worst = 0.0
    lines = []
    for label, dtype, rest, key in [("shape only", "float64", True, "shape"),
                                    ("shape only", "float32", True, "shape"),
                                    ("posed", "float64", False, "posed_%s_double"),
                                    ("posed", "float32", False, "posed_%s_float")]:
        v, j = side.forward(dtype, betas, np.zeros_like(poses) if rest else poses)
        if rest:  # libsmpl's float shape batch against smplx float32
            suffix = "_float" if dtype == "float32" else ""
            rv, rj = ref["shape_vertices" + suffix], ref["shape_joints" + suffix]
        else:
            rv, rj = ref[key % "vertices"], ref[key % "joints"]
        dv = float(np.abs(v.reshape(n, -1) - rv).max())
        k = rj.shape[1] // 3
        dj = float(np.abs(j[:, :k, :].reshape(n, -1) - rj).max())
        worst = max(worst, dv, dj)
        lines.append("  %s, smplx %s: vertices differ by at most %.2g m, joints by %.2g m"
                     % (label, dtype, dv, dj))
        if rest:
            vs = side.forward_shape(dtype, betas)
            dv = float(np.abs(vs.reshape(n, -1) - rv).max())
            worst = max(worst, dv)
            lines.append("  shape only, smplx %s forward_shape: vertices differ by at most %.2g m"
                         % (dtype, dv))
    print("same bodies (%d random bodies, largest |smplx - libsmpl|):" % n)
    print("\n".join(lines))
    if not worst <= args.tolerance:
        sys.exit("bench_vs_smplx: the sides differ by %.3g m (above --tolerance %g): not the "
                 "same model or not the same computation; no timing" % (worst, args.tolerance))


def fmt_time(s):
    if s is None:
        return "-"
    if s < 1e-4:
        return "%.1f us" % (s * 1e6)
    return "%.0f us" % (s * 1e6) if s < 1e-3 else "%.2f ms" % (s * 1e3)


def speedups(cal, ref, key):
    """Per-round smplx time / libsmpl time for `key`."""
    return [r[key] / c[key] for c, r in zip(cal, ref) if key in c and key in r]


def fmt_range(values, digits=2):
    if not values:
        return "-"
    f = "%%.%df" % digits
    return (f + " (" + f + "-" + f + ")") % (statistics.median(values), min(values), max(values))


def table(args, cal, ref, level):
    lines = ["| per body (CPU time) | smplx | libsmpl (%s) | speed-up smplx / libsmpl (range) |"
             % level, "|---|---|---|---|"]
    for kind, dtype in CASES:
        for n in args.batch_sizes:
            key = (kind, dtype, n)
            c = [r[key] for r in cal if key in r]
            s = [r[key] for r in ref if key in r]
            lines.append("| %s, %s, batch %d | %s | %s | %s |" % (
                KIND_LABEL[kind], dtype, n, fmt_time(statistics.median(s) if s else None),
                fmt_time(statistics.median(c) if c else None), fmt_range(speedups(cal, ref, key))))
    return "\n".join(lines)


def two_core_table(args, cal2, ref2, ref):
    def rate(rounds, key):
        v = [1.0 / r[key] for r in rounds if key in r]
        return statistics.median(v) if v else None

    lines = ["| two cores, bodies/s (wall time) | smplx posed float32 (2 threads) | smplx posed "
             "float64 (2 threads) | libsmpl shape only (2 threads) |", "|---|---|---|---|"]
    for n in args.batch_sizes:
        cells = [rate(ref2, ("posed", d, n)) for d in ("float32", "float64")]
        cells.append(rate(cal2, ("shape2", "float64", n)))
        lines.append("| batch %d | %s |" % (n, " | ".join(
            "-" if x is None else "{:,.0f}".format(x) for x in cells)))
    # Per round: libsmpl's best shape-only throughput over smplx's best posed one.
    ratios = []
    for c, r in zip(cal2, ref2):
        if c and r:
            ratios.append(max(1.0 / t for t in c.values()) / max(1.0 / t for t in r.values()))
    lines.append("")
    lines.append("libsmpl's best shape-only throughput / smplx's best posed throughput, both on "
                 "two cores (per round; median (range)): %s" % fmt_range(ratios))
    # On a loaded machine two torch threads can lose most of their wall time waiting for each
    # other; smplx's two-core throughput cannot exceed twice its one-core (CPU-time) throughput,
    # so this bound does not depend on how busy the second core was.
    bound = []
    for c, r in zip(cal2, ref):
        posed = [1.0 / t for k, t in r.items() if k[0] == "posed"]
        if c and posed:
            bound.append(max(1.0 / t for t in c.values()) / (2.0 * max(posed)))
    lines.append("libsmpl's best two-thread shape-only throughput / (2 x smplx's best one-core "
                 "posed throughput, i.e. perfect two-core scaling) (per round): %s"
                 % fmt_range(bound))
    return "\n".join(lines)


def write_bench_model(args, tmp):
    """Has bench_smpl write its random full-size model to `tmp`; returns the path."""
    path = os.path.join(tmp, "bench_smpl_random_model.npz")
    subprocess.run([args.bench, "--write_model=" + path], check=True)
    return path


def main(argv):
    args = parse_args(argv)
    label = args.model or "bench_smpl's random full-size SMPL-shaped model"
    with tempfile.TemporaryDirectory() as tmp:
        if args.model is None:
            args.model = write_bench_model(args, tmp)
        # smplx (torch, its BLAS) is loaded before the pinning so that it sees every core.
        ref_side = None if args.caliper_only else SmplxSide(args)
        if hasattr(os, "sched_setaffinity"):
            os.sched_setaffinity(0, {args.core})
        if ref_side:
            check_same_bodies(args, ref_side)
        cal, ref, cal2, ref2, level = [], [], [], [], ""
        for r in range(args.rounds):
            if ref_side:
                ref.append({(k, d, n): ref_side.time(k, d, n) for k, d in CASES
                            for n in args.batch_sizes})
            res, level = caliper_round(args)
            cal.append(res)
            if args.two_cores:
                ref2.append(ref_side.time_two_cores() if ref_side else {})
                cal2.append(caliper_round(args, two_cores=True)[0])
            # The table so far, so that a run stopped early still leaves its figures.
            print("round %d/%d done; the table so far:\n%s" % (r + 1, args.rounds,
                  table(args, cal, ref, level)), file=sys.stderr)
            if args.two_cores:
                print(two_core_table(args, cal2, ref2, ref), file=sys.stderr)
    print("model: %s; core %d; %d interleaved rounds; per-body CPU time, medians"
          % (label, args.core, args.rounds))
    print(table(args, cal, ref, level))
    if args.two_cores:
        print()
        print(two_core_table(args, cal2, ref2, ref))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
