#!/usr/bin/env python3
"""Side-by-side timing of libsmpl (bench_smpl) and the smplx PyTorch package on one core.

Not run in CI (it needs PyTorch and a user's smplx checkout). Usage:

    tools/bench_vs_smplx.py --smplx ~/src/smplx --model ~/models/SMPL_NEUTRAL.pkl \\
        [--bench build/bin/bench_smpl] [--core 1] [--rounds 5] [--batches 1,64,4096]

Both sides run pinned to the same core (--core), one thread each (torch.set_num_threads(1); the
batch API with one thread), and in interleaved rounds: each round times every case with smplx,
then runs bench_smpl once for every case, so slow phases of a shared machine hit both sides.
Cases: shape only (zero pose) and posed (random pose), float32 and float64, every batch size.
libsmpl's "float" is its single-precision pose blend shapes (vertices stay double); its shape-only
path has no precision choice and is listed in both rows. For each case the table gives the median
per-body time of each side over the rounds and the ratio libsmpl / smplx as the median of the
per-round ratios with their range (min-max), so the spread shows how noisy the machine was.

--caliper-only times only the libsmpl side (no PyTorch needed); the smplx columns read "-".
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time


def parse_args(argv):
    p = argparse.ArgumentParser(
        description="Time libsmpl against smplx (PyTorch) on one core, interleaved rounds.")
    p.add_argument("--smplx", help="path of a checkout of the smplx package (the folder that "
                   "contains the smplx/ package directory); required unless --caliper-only")
    p.add_argument("--model", required=True, help="SMPL model file (.pkl or .npz) both sides load")
    p.add_argument("--bench", default=os.path.join("build", "bin", "bench_smpl"),
                   help="the bench_smpl program of a Release build (default: %(default)s)")
    p.add_argument("--core", type=int, default=1, help="CPU core both sides run on (default 1)")
    p.add_argument("--rounds", type=int, default=5, help="interleaved rounds (default 5)")
    p.add_argument("--batches", default="1,64,4096",
                   help="comma-separated batch sizes (default: %(default)s)")
    p.add_argument("--min-time", type=float, default=0.3,
                   help="seconds each side spends per case per round (default 0.3)")
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
    if not os.path.isfile(a.model):
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
    if hasattr(os, "sched_getaffinity") and a.core not in os.sched_getaffinity(0):
        errors.append("--core %d: not available to this process (available: %s)"
                      % (a.core, sorted(os.sched_getaffinity(0))))
    if errors:
        p.error("; ".join(errors))
    return a


CASES = [("shape", "float32"), ("shape", "float64"), ("posed", "float32"), ("posed", "float64")]


def caliper_round(args):
    """One bench_smpl run over every case; returns {(kind, dtype, n): seconds per body}."""
    env = dict(os.environ, CALIPER_BENCH_MODEL=os.path.abspath(args.model),
               CALIPER_BENCH_BATCH_SIZES=",".join(str(n) for n in args.batch_sizes))
    cmd = ["taskset", "-c", str(args.core), args.bench, "--benchmark_format=json",
           "--benchmark_min_time=%g" % args.min_time,
           "--benchmark_filter=^BM_(Shape|Evaluate)Batch/[a-z0-9]+/"]
    out = subprocess.run(cmd, env=env, check=True, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, universal_newlines=True).stdout
    report = json.loads(out)
    default = report["context"].get("simd_default", "")
    result = {}
    for b in report["benchmarks"]:
        parts = b["name"].split("/")  # BM_ShapeBatch/avx2/N/threads or BM_EvaluateBatch/...
        if parts[1] != default:
            continue  # the variant this CPU picks by default
        n = int(parts[2])
        per_body = b["cpu_time"] * {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]] / n
        if parts[0] == "BM_ShapeBatch":
            result[("shape", "float32", n)] = per_body
            result[("shape", "float64", n)] = per_body
        else:
            dtype = "float32" if parts[3] == "1" else "float64"
            result[("posed", dtype, n)] = per_body
    return result, default


class SmplxSide:
    """smplx forward passes with one thread on the pinned core."""

    def __init__(self, args):
        sys.path.insert(0, os.path.abspath(args.smplx))
        try:
            import torch  # noqa: F401
            import smplx  # noqa: F401
        except ImportError as e:
            sys.exit("bench_vs_smplx: cannot import PyTorch or smplx (%s); install PyTorch and "
                     "give --smplx the path of a smplx checkout, or use --caliper-only" % e)
        self.torch, self.smplx = torch, smplx
        torch.set_num_threads(1)
        self.args = args
        self.models = {}

    def _model(self, dtype, n):
        key = (dtype, n)
        if key not in self.models:
            t = getattr(self.torch, dtype)
            self.models[key] = self.smplx.SMPL(model_path=self.args.model, batch_size=n,
                                               num_betas=10, dtype=t)
        return self.models[key]

    def time(self, kind, dtype, n):
        torch = self.torch
        t = getattr(torch, dtype)
        m = self._model(dtype, n)
        g = torch.Generator().manual_seed(n)
        betas = torch.randn(n, 10, generator=g, dtype=t)
        body_pose = (torch.zeros(n, 69, dtype=t) if kind == "shape"
                     else 0.3 * torch.randn(n, 69, generator=g, dtype=t))
        orient = torch.zeros(n, 3, dtype=t)
        with torch.no_grad():
            m(betas=betas, body_pose=body_pose, global_orient=orient)  # warm-up
            times = []
            spent = 0.0
            while spent < self.args.min_time or len(times) < 3:
                t0 = time.process_time()
                m(betas=betas, body_pose=body_pose, global_orient=orient)
                dt = time.process_time() - t0
                times.append(dt)
                spent += dt
        return statistics.median(times) / n


def fmt_time(s):
    if s is None:
        return "-"
    return "%.0f us" % (s * 1e6) if s < 1e-3 else "%.2f ms" % (s * 1e3)


def table(args, cal, ref, level):
    lines = ["| per body | smplx | libsmpl (%s) | ratio libsmpl/smplx (range) |" % level,
             "|---|---|---|---|"]
    for kind, dtype in CASES:
        for n in args.batch_sizes:
            key = (kind, dtype, n)
            c = [r[key] for r in cal if key in r]
            s = [r[key] for r in ref if key in r]
            ratios = [ci / si for ci, si in zip(c, s)]
            ratio = ("%.2f (%.2f-%.2f)" % (statistics.median(ratios), min(ratios), max(ratios))
                     if ratios else "-")
            lines.append("| %s, %s, batch %d | %s | %s | %s |" % (
                kind, dtype, n, fmt_time(statistics.median(s) if s else None),
                fmt_time(statistics.median(c) if c else None), ratio))
    return "\n".join(lines)


def main(argv):
    args = parse_args(argv)
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {args.core})
    ref_side = None if args.caliper_only else SmplxSide(args)
    cal, ref, level = [], [], ""
    for r in range(args.rounds):
        if ref_side:
            ref.append({(k, d, n): ref_side.time(k, d, n) for k, d in CASES
                        for n in args.batch_sizes})
        res, level = caliper_round(args)
        cal.append(res)
        print("round %d/%d done" % (r + 1, args.rounds), file=sys.stderr)
    print("model: %s; core %d; %d interleaved rounds; per-body CPU time, medians"
          % (args.model, args.core, args.rounds))
    print(table(args, cal, ref, level))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
