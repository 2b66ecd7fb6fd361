#!/usr/bin/env python3
"""Proves .ci/install-deps.sh: every system header a build included must come from a package
that a fresh Debian 12 machine gets from that script (a named package or one of its Depends).

Usage: .ci/check-deps.py BUILD_DIR [BUILD_DIR ...]
Reads the compiler's dependency records (`ninja -t deps`), keeps the headers outside the source
and build trees, finds each one's package with `dpkg -S`, and fails naming the header and the
package when that package is not in the closure of the script's package list.
"""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def named_packages():
    text = open(os.path.join(ROOT, ".ci", "install-deps.sh"), encoding="utf-8").read()
    m = re.search(r"packages=\(([^)]*)\)", text, re.S)
    if not m:
        sys.exit("check-deps: no packages=( ... ) list in .ci/install-deps.sh")
    return sorted(set(m.group(1).split()))


def closure(packages):
    """Named packages plus everything they Depend/Pre-Depend on, recursively (no Recommends,
    as install-deps.sh installs with --no-install-recommends)."""
    out = subprocess.run(
        ["apt-cache", "depends", "--recurse", "--no-recommends", "--no-suggests",
         "--no-conflicts", "--no-breaks", "--no-replaces", "--no-enhances"] + packages,
        check=True, capture_output=True, text=True).stdout
    names = set()
    for line in out.splitlines():
        if line and not line[0].isspace():
            names.add(line.strip().strip("<>").split(":")[0])
    return names


def system_headers(build_dir):
    out = subprocess.run(["ninja", "-C", build_dir, "-t", "deps"], check=True,
                         capture_output=True, text=True).stdout
    headers = set()
    for line in out.splitlines():
        if not line.startswith("    "):
            continue
        path = os.path.normpath(os.path.join(build_dir, line.strip()))
        if not os.path.isabs(line.strip()):
            continue  # relative: inside the build tree
        if path.startswith(ROOT + os.sep) or path.startswith(os.path.abspath(build_dir) + os.sep):
            continue
        headers.add(os.path.realpath(path))
    return headers


def owners(paths):
    """Map each path to its package with one dpkg -S call per batch."""
    result = {}
    paths = sorted(paths)
    for i in range(0, len(paths), 200):
        batch = paths[i:i + 200]
        proc = subprocess.run(["dpkg", "-S"] + batch, capture_output=True, text=True)
        for line in proc.stdout.splitlines():
            pkgs, _, path = line.partition(": ")
            for pkg in pkgs.split(", "):
                result.setdefault(path.strip(), set()).add(pkg.split(":")[0])
    return result


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    headers = set()
    for build_dir in sys.argv[1:]:
        headers |= system_headers(os.path.abspath(build_dir))
    allowed = closure(named_packages())
    found = owners(headers)
    problems = []
    for h in sorted(headers):
        # dpkg records /usr/include paths; /usr/lib/... symlinks are resolved above.
        pkgs = found.get(h)
        if not pkgs:
            problems.append(f"{h}: belongs to no installed package (dpkg -S finds nothing)")
        elif not pkgs & allowed:
            problems.append(f"{h}: from {', '.join(sorted(pkgs))}, which .ci/install-deps.sh "
                            "does not install: add it to the packages list")
    if problems:
        print("check-deps: system headers outside .ci/install-deps.sh:")
        for p in problems:
            print("  " + p)
        sys.exit(1)
    pk = sorted({p for h in headers for p in found.get(h, ())})
    print(f"check-deps: {len(headers)} system headers from {len(pk)} packages, "
          f"all installed by .ci/install-deps.sh: {' '.join(pk)}")


if __name__ == "__main__":
    main()
