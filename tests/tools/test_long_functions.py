#!/usr/bin/env python3
"""Tests of tools/long_functions.py: the scanner on tricky fixtures, and the ratchet's verdicts.

    python3 tests/tools/test_long_functions.py   (ctest: tools.long_functions)
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SCRIPT = os.path.join(ROOT, "tools", "long_functions.py")
sys.path.insert(0, os.path.join(ROOT, "tools"))
import long_functions  # noqa: E402


def expectations(path):
    """{name: (line, length)} from the `// expect NAME... LENGTH` comments of a fixture."""
    out = {}
    with open(path, encoding="utf-8") as fh:
        for number, line in enumerate(fh, 1):
            m = re.search(r"// expect (.+) (\d+)$", line.rstrip())
            if m:
                out[m.group(1)] = (number, int(m.group(2)))
    return out


def run(args, cwd):
    return subprocess.run([sys.executable, SCRIPT] + args, cwd=cwd, capture_output=True, text=True)


class Scanner(unittest.TestCase):
    def test_tricky_fixture(self):
        path = os.path.join(HERE, "fixtures", "tricky.cpp")
        with open(path, encoding="utf-8") as fh:
            found = long_functions.find_functions(long_functions.blank_non_code(fh.read()))
        got = {name: (line, length) for name, line, length in found}
        self.assertEqual(got, expectations(path))

    def test_blanking_keeps_lines(self):
        text = 'a /* x\n y */ "s\\"}" // c\n#define X {\\\n}\nb'
        blanked = long_functions.blank_non_code(text)
        self.assertEqual(blanked.count("\n"), text.count("\n"))
        self.assertNotIn("{", blanked)
        self.assertNotIn("}", blanked)


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)


def function(name, lines):
    return "int %s() {\n%s}\n" % (name, "  f();\n" * (lines - 2))


class Ratchet(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.src = os.path.join(self.dir.name, "src")
        write(os.path.join(self.src, "a.cpp"), function("short_one", 5) + function("long_one", 12))
        self.allow = os.path.join(self.dir.name, "allow")

    def tearDown(self):
        self.dir.cleanup()

    def check(self, allow_text, *extra):
        write(self.allow, allow_text)
        return run(["--limit", "10", "--allow", self.allow, *extra, "src"], self.dir.name)

    def test_lists_long_functions_with_place_and_length(self):
        r = run(["--limit", "10", "--list", "src"], self.dir.name)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("src/a.cpp:6  12  long_one", r.stdout)
        self.assertNotIn("short_one", r.stdout)

    def test_unlisted_long_function_fails_and_says_split(self):
        r = self.check("")
        self.assertEqual(r.returncode, 1)
        self.assertIn("long_one is 12 lines, over the limit of 10", r.stderr)
        self.assertIn("split it", r.stderr)

    def test_listed_at_its_length_passes(self):
        r = self.check("src/a.cpp long_one 12\n")
        self.assertEqual(r.returncode, 0, r.stderr)

    def test_growth_fails(self):
        r = self.check("src/a.cpp long_one 11\n")
        self.assertEqual(r.returncode, 1)
        self.assertIn("grew to 12 lines; the allow list tolerates 11", r.stderr)

    def test_shrunk_function_must_be_lowered_and_update_does_it(self):
        r = self.check("src/a.cpp long_one 20\n")
        self.assertEqual(r.returncode, 1)
        self.assertIn("lower its line", r.stderr)
        r = run(["--limit", "10", "--allow", self.allow, "--update", "src"], self.dir.name)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(self.allow, encoding="utf-8") as fh:
            self.assertEqual(long_functions.read_allow(fh.read()), {("src/a.cpp", "long_one"): 12})

    def test_gone_function_must_be_removed_and_update_never_adds(self):
        r = self.check("src/a.cpp long_one 12\nsrc/a.cpp gone 50\n", "--update")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(self.allow, encoding="utf-8") as fh:
            self.assertEqual(long_functions.read_allow(fh.read()), {("src/a.cpp", "long_one"): 12})
        write(self.allow, "")
        r = run(["--limit", "10", "--allow", self.allow, "--update", "src"], self.dir.name)
        self.assertEqual(r.returncode, 1)
        with open(self.allow, encoding="utf-8") as fh:
            self.assertEqual(long_functions.read_allow(fh.read()), {})

    def test_bad_allow_line_is_reported(self):
        r = self.check("src/a.cpp long_one twelve\n")
        self.assertEqual(r.returncode, 2)
        self.assertIn("is not `path  name  length`", r.stderr)


@unittest.skipUnless(shutil.which("git"), "needs git")
class History(unittest.TestCase):
    """The allow list may only shrink across its committed versions."""

    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.root = self.dir.name
        os.makedirs(os.path.join(self.root, "tools"))
        with open(SCRIPT, encoding="utf-8") as fh:
            write(os.path.join(self.root, "tools", "long_functions.py"), fh.read())
        write(os.path.join(self.root, "a.cpp"), function("long_one", 120) + function("other", 130))
        self.git("init", "-q")
        self.git("config", "user.email", "t@example.invalid")
        self.git("config", "user.name", "t")

    def tearDown(self):
        self.dir.cleanup()

    def git(self, *args):
        subprocess.run(["git", "-C", self.root, *args], check=True, capture_output=True)

    def commit_allow(self, text):
        write(os.path.join(self.root, "tools", "long_functions.allow"), text)
        self.git("add", "-A")
        self.git("commit", "-q", "-m", "allow")

    def check(self):
        return subprocess.run([sys.executable, os.path.join(self.root, "tools", "long_functions.py")],
                              cwd=self.root, capture_output=True, text=True)

    def test_added_line_fails_even_when_committed(self):
        self.commit_allow("a.cpp long_one 120\n")
        self.assertEqual(self.check().returncode, 1)  # `other` is not listed
        self.commit_allow("a.cpp long_one 120\na.cpp other 130\n")
        r = self.check()
        self.assertEqual(r.returncode, 1)
        self.assertIn("other is on the allow list but was not in its version of commit", r.stderr)

    def test_unchanged_list_passes(self):
        self.commit_allow("a.cpp long_one 120\na.cpp other 130\n")
        r = self.check()
        self.assertEqual(r.returncode, 0, r.stderr)


if __name__ == "__main__":
    unittest.main()
