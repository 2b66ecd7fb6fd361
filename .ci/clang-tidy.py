#!/usr/bin/env python3
"""Runs clang-tidy 14 with the repository's .clang-tidy on every library and program source.

Usage: .ci/clang-tidy.py BUILD_DIR [-j N] [--include-tests] [--summary-only] [--only REGEX]
                         [--progress]
Takes the sources from BUILD_DIR/compile_commands.json (the Release build's, so no extra build):
every file under libsmpl/, libcaliper/ and apps/, and with --include-tests also tests/; code
generated into the build tree is left out. A warning in a header is counted once however many
sources include it. Prints each warning, then the counts per check and per directory, the CPU
time clang-tidy used, and exits 1 when there is any warning (0 when there are none). --only
keeps the sources whose path relative to the repository matches REGEX (to check a few files).
"""
import argparse
import collections
import concurrent.futures
import json
import os
import re
import resource
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WARNING = re.compile(r"^(/\S+?):(\d+):(\d+): warning: (.*) \[([\w.,-]+)\]$")


def sources(build_dir, include_tests):
    areas = ("libsmpl", "libcaliper", "apps") + (("tests",) if include_tests else ())
    entries = json.load(open(os.path.join(build_dir, "compile_commands.json"), encoding="utf-8"))
    out = []
    for e in entries:
        path = os.path.realpath(os.path.join(e["directory"], e["file"]))
        rel = os.path.relpath(path, ROOT)
        if rel.split(os.sep)[0] in areas:
            out.append(path)
    return sorted(set(out))


def tidy(build_dir, path):
    run = subprocess.run(["clang-tidy-14", "-p", build_dir, "--quiet", path],
                         capture_output=True, text=True)
    warnings = []
    for line in run.stdout.splitlines():
        m = WARNING.match(line)
        if m:
            warnings.append((os.path.relpath(m.group(1), ROOT), int(m.group(2)), int(m.group(3)),
                             m.group(5), m.group(4)))
    # clang-tidy exits non-zero on compiler errors (a source that does not parse): report them.
    errors = [l for l in (run.stdout + run.stderr).splitlines() if ": error: " in l]
    return path, warnings, errors


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("build_dir")
    ap.add_argument("-j", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--include-tests", action="store_true")
    ap.add_argument("--summary-only", action="store_true")
    ap.add_argument("--only", default="")
    ap.add_argument("--progress", action="store_true", help="name each source as it is done")
    args = ap.parse_args()
    build_dir = os.path.abspath(args.build_dir)
    files = [f for f in sources(build_dir, args.include_tests)
             if re.search(args.only, os.path.relpath(f, ROOT))]
    if not files:
        sys.exit(f"clang-tidy: no sources in {build_dir}/compile_commands.json; run "
                 "`cmake --preset release` first")
    found, errors = set(), []
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.j) as pool:
        for path, warnings, errs in pool.map(lambda f: tidy(build_dir, f), files):
            found.update(warnings)
            if args.progress:
                print(f"clang-tidy: {os.path.relpath(path, ROOT)}: {len(warnings)} warnings",
                      *(f"  {w[0]}:{w[1]}:{w[2]}: {w[4]} [{w[3]}]" for w in warnings),
                      sep="\n", file=sys.stderr, flush=True)
            errors += [f"{os.path.relpath(path, ROOT)}: {e}" for e in errs]
    if not args.summary_only:
        for f, line, col, check, text in sorted(found):
            print(f"{f}:{line}:{col}: {text} [{check}]")
    for e in errors:
        print(e)
    by_check = collections.Counter(w[3] for w in found)
    by_dir = collections.Counter("/".join(w[0].split("/")[:2]) for w in found)
    for title, counts in (("check", by_check), ("directory", by_dir)):
        for name, n in counts.most_common():
            print(f"{n:6d}  {name}")
        if counts:
            print(f"        (per {title})")
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(f"clang-tidy: {len(files)} sources, {len(found)} warnings, {len(errors)} errors, "
          f"{usage.ru_utime + usage.ru_stime:.1f} s of CPU")
    if found or errors:
        print("clang-tidy: fix the warnings above (or, for a proven false positive, a NOLINT(check) "
              "with the reason on the same line); .clang-tidy says which checks run")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
