#!/usr/bin/env python3
"""Runs clang-tidy 14 with the repository's .clang-tidy on every library and program source.

Usage: .ci/clang-tidy.py BUILD_DIR [-j N] [--include-tests] [--summary-only] [--only REGEX]
                         [--progress]
Takes the sources from BUILD_DIR/compile_commands.json: every file under libsmpl/, libcaliper/ and
apps/, and with --include-tests also tests/; code generated into the build tree is left out. In a
unity build (CMAKE_UNITY_BUILD, as the sanitizer presets configure it) the compile database names
CMake's unity files (Unity/unity_N_cxx.cxx, each including a batch of sources): clang-tidy then
runs once per unity file, so the headers every source of a batch includes are parsed and matched
once, and the warnings in the batch's sources are reported through the HeaderFilterRegex of
.clang-tidy, which names every directory the sources live in. Same checks, a fraction of the time. A warning in a header is counted once however many
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


UNITY_INCLUDE = re.compile(r'^#include "(.+)"$', re.M)


def unity_members(path):
    """The sources a CMake unity file includes (empty for any other file)."""
    if not re.search(r"/Unity/unity_\w+\.cxx$", path):
        return []
    with open(path, encoding="utf-8") as f:
        return [os.path.realpath(m) for m in UNITY_INCLUDE.findall(f.read())]


def sources(build_dir, include_tests):
    """(translation unit, its project sources) pairs: a source is its own unit, a unity file's
    units are the project sources it includes."""
    areas = ("libsmpl", "libcaliper", "apps") + (("tests",) if include_tests else ())
    entries = json.load(open(os.path.join(build_dir, "compile_commands.json"), encoding="utf-8"))
    out = {}
    for e in entries:
        path = os.path.realpath(os.path.join(e["directory"], e["file"]))
        members = unity_members(path) or [path]
        members = [m for m in members if os.path.relpath(m, ROOT).split(os.sep)[0] in areas]
        if members:
            out[path] = members
    return sorted(out.items())


def tidy(build_dir, path):
    # -Wno-error: a compile database of a -Werror build (the asan preset's) would turn clang's own
    # warnings into errors; they are reported and counted as warnings all the same.
    run = subprocess.run(["clang-tidy-14", "-p", build_dir, "--quiet", "--extra-arg=-Wno-error", path],
                         capture_output=True, text=True)
    warnings = []
    for line in run.stdout.splitlines():
        m = WARNING.match(line)
        # A unity file is CMake's, not the project's: its #include of each .cpp of the batch is
        # what bugprone-suspicious-include flags there.
        if m and not unity_members(m.group(1)):
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
    units = [(u, m) for u, m in sources(build_dir, args.include_tests)
             if any(re.search(args.only, os.path.relpath(f, ROOT)) for f in m)]
    files = [u for u, _ in units]
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
    print(f"clang-tidy: {sum(len(m) for _, m in units)} sources in {len(files)} translation "
          f"units, {len(found)} warnings, {len(errors)} errors, "
          f"{usage.ru_utime + usage.ru_stime:.1f} s of CPU")
    if found or errors:
        print("clang-tidy: fix the warnings above (or, for a proven false positive, a NOLINT(check) "
              "with the reason on the same line); .clang-tidy says which checks run")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
