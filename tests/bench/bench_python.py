"""Python overhead of the caliper module over the same C++ work (docs/performance.md).

    PYTHONPATH=build/python /usr/bin/python3 tests/bench/bench_python.py [--bodies 4096]

create: caliper.create() vs the C++ of create() (caliper::create_avatar on the same model,
regressors and inputs); batch: caliper.evaluate() of N bodies vs the same C++ loop (both allocate
a fresh uninitialised output of the same dtype per call). Two baselines: the C++ work timed inside
C++, and the same baseline call timed from Python (docs/performance.md explains why both). Thread
CPU time on both sides (CLOCK_THREAD_CPUTIME_ID; wall time would measure the neighbours on a
shared machine).

Paired: each Python call is paired with one baseline call (Python first in even rounds, the
baseline first in odd rounds, so that an advantage of going first or second cancels), and the
overhead is the median of the per-pair differences, so drifts of a shared machine cancel. A
control row pairs the baseline call with itself: its overhead against the second baseline is the
method's noise floor on the machine at that moment.
"""
import argparse
import functools
import platform
import statistics
import time

import numpy as np

import caliper

print = functools.partial(print, flush=True)  # noqa: A001 (progress when redirected)


def paired(py_call, cpp_call, pairs):
    """Medians over `pairs` rounds of: the Python call; the C++ baseline call as timed inside
    C++; the same baseline call as timed from Python (its binding does no conversion work);
    and the per-round differences of the Python call to each. Seconds."""
    py, inner, outer, d_inner, d_outer = [], [], [], [], []

    def timed_py():
        t0 = time.thread_time()
        py_call()
        return time.thread_time() - t0

    def timed_cpp():
        t0 = time.thread_time()
        c = cpp_call()
        return c, time.thread_time() - t0

    for i in range(pairs):
        if i % 2 == 0:
            p = timed_py()
            c, o = timed_cpp()
        else:
            c, o = timed_cpp()
            p = timed_py()
        py.append(p)
        inner.append(c)
        outer.append(o)
        d_inner.append(p - c)
        d_outer.append(p - o)
    m = statistics.median
    return m(py), m(inner), m(outer), m(d_inner), m(d_outer)


def report(what, unit, scale, r):
    py, inner, outer, d_inner, d_outer = r
    print(f"{what}: Python {py * scale:.1f} {unit}; C++ timed inside C++ {inner * scale:.1f} "
          f"{unit} (overhead {d_inner * scale:+.1f} {unit}, {100 * d_inner / inner:+.2f} %); "
          f"C++ baseline call timed from Python {outer * scale:.1f} {unit} (overhead "
          f"{d_outer * scale:+.1f} {unit}, {100 * d_outer / outer:+.2f} %)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bodies", type=int, default=4096)
    ap.add_argument("--create-pairs", type=int, default=1000)
    ap.add_argument("--batch-pairs", type=int, default=8)
    ap.add_argument("--only", choices=("create", "batch"), help="run one half only")
    a = ap.parse_args()
    model = caliper.open_model("female")
    regs = caliper.train_regressors(model)
    tc = caliper._caliper._time_create_cpp
    te = caliper._caliper._time_evaluate_cpp
    print(f"python {platform.python_version()}, caliper {caliper.__version__}, model "
          f"{model.name} ({model.num_vertices} vertices, {model.num_joints} joints, "
          f"{model.num_pose_features} pose features)")
    print(f"load average at start: {' '.join(open('/proc/loadavg').read().split()[:3])}")
    si = {"height": 1.68, "weight": 62.0}
    create_rows = (
        ("control: the baseline call itself", lambda: tc(model, regs, si, repeats=1)),
        ("dict of SI numbers", lambda: caliper.create(model, regs, si)),
        ("keywords with units", lambda: caliper.create(model, regs, height="168cm",
                                                       weight="62kg")))
    for label, call in create_rows if a.only != "batch" else ():
        report(f"create R2 ({label}), {a.create_pairs} pairs", "us", 1e6,
               paired(call, lambda: tc(model, regs, si, repeats=1), a.create_pairs))

    rng = np.random.default_rng(1)
    betas = rng.normal(size=(a.bodies, 10))
    poses = rng.normal(scale=0.3, size=(a.bodies, 3 * model.num_joints))
    for label, pose_arg in (("rest pose", None), ("posed", poses)) if a.only != "create" else ():
        for dtype in (np.float64, np.float32):
            f32 = dtype == np.float32
            report(f"evaluate {a.bodies} bodies, {label}, {np.dtype(dtype).name} out, "
                   f"{a.batch_pairs} pairs", "ms", 1e3,
                   paired(lambda: caliper.evaluate(model, betas, pose_arg, dtype=dtype),
                          lambda: te(model, betas, pose_arg, float32=f32, repeats=1),
                          a.batch_pairs))


if __name__ == "__main__":
    main()
