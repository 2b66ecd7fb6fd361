#!/usr/bin/env python3
"""Lists the C++ functions longer than a limit and fails CI when one is not on the ratchet list.

    tools/long_functions.py [--limit N] [--allow FILE] [--list] [--update] [--no-history] [PATH...]

Scans the repository's tracked C++ sources (`git ls-files`: *.cpp, *.hpp, *.h, *.cc) outside
tests/ and generated code (nothing generated is tracked; anything under a `generated/` folder is
skipped anyway), or the files or folders given as PATHs, and prints every function or method body
longer than the limit (default 100 lines), longest first: `path:line  length  name`.

The length of a function is the number of lines from the line of its opening brace to the line of
its closing brace, both included (a one-line body has length 1). Lambdas and local classes count
as part of the function that contains them; a lambda stored in a variable at namespace or class
scope counts as a function of its own, named after the variable.

Ratchet: `tools/long_functions.allow` lists the functions over the limit that are tolerated for now,
one per line: `path  name  length`. The script fails (exit 1) and says what to do when
  - a function over the limit is not on the list (split it: the list may not grow),
  - a listed function is longer than its listed length (it may not grow),
  - a listed function got shorter, fell under the limit or is gone (lower or remove its line:
    `--update` does that, and only that; it never adds a line),
  - (with git history, unless --no-history) a line of the list is not in every earlier committed
    version of the list, or its length is higher than in one of them: the list may only shrink.

Why a scanner and not libclang: the check runs first in CI, before anything is built, so it has
no compile_commands.json to give libclang, and parsing every translation unit with its headers
would take minutes; the question asked (where does each function body start and end) only needs
the braces. The scanner first blanks what can hold a brace that is not code: comments, string
literals (raw strings included), character literals (not digit separators such as 1'000) and
preprocessor lines (with their continuations); of an #if/#elif/#else chain only the first branch
is kept, so that the two branches of a conditional cannot unbalance the braces. It then reads the
braces at namespace and class scope: a brace after `namespace`, `extern ""` or a class key opens a
scope that is read further; a brace after a parameter list (and qualifiers such as const, noexcept,
override, a trailing return type or a constructor's initialiser list, whose own braces it steps
over) opens a function body, which it skips to the matching brace; any other brace (an aggregate
or a brace initialiser) is stepped over. Its tests: tests/tools (fixtures with the tricky cases).
"""

import argparse
import os
import re
import subprocess
import sys

SOURCE_SUFFIXES = (".cpp", ".hpp", ".h", ".cc")
DEFAULT_LIMIT = 100
DEFAULT_ALLOW = "tools/long_functions.allow"
QUALIFIERS = {"const", "volatile", "noexcept", "override", "final", "mutable", "&", "&&", "throw", "try"}
CLASS_KEYS = {"class", "struct", "union", "enum"}


def blank_non_code(text):
    """Returns `text` with comments, literals and preprocessor lines replaced by spaces (newlines kept).

    A string literal becomes `""` and a character literal `''`, so that `extern "C"` stays
    recognisable; of an #if chain only the first branch is kept.
    """
    out = []
    i = 0
    n = len(text)
    at_line_start = True  # only whitespace since the last newline
    cond_stack = []  # per open #if: True while in a branch after the first (blanked)

    def blank(s):
        return "".join("\n" if c == "\n" else " " for c in s)

    def skipping():
        return any(cond_stack)

    while i < n:
        c = text[i]
        if c == "\n":
            out.append(c)
            i += 1
            at_line_start = True
            continue
        if at_line_start and c == "#":
            # A preprocessor directive, with its backslash continuations (and comments inside it).
            j = i
            while j < n and text[j] != "\n":
                if text[j] == "\\" and j + 1 < n and text[j + 1] == "\n":
                    j += 2
                    continue
                if text.startswith("/*", j):
                    k = text.find("*/", j + 2)
                    j = n if k < 0 else k + 2
                    continue
                if text.startswith("//", j):
                    while j < n and text[j] != "\n":
                        j += 1
                    break
                j += 1
            directive = re.match(r"#\s*(\w*)", text[i:j]).group(1)
            if directive in ("if", "ifdef", "ifndef"):
                cond_stack.append(False)
            elif directive in ("elif", "else") and cond_stack:
                cond_stack[-1] = True
            elif directive == "endif" and cond_stack:
                cond_stack.pop()
            out.append(blank(text[i:j]))
            i = j
            continue
        if c in " \t\r\f\v":
            out.append(c)
            i += 1
            continue
        at_line_start = False
        if skipping():
            # Inside a later #if branch: blank up to the end of the line (literals and comments
            # in it are not read; a directive can only start a line).
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(blank(text[i:j]))
            i = j
            continue
        if text.startswith("//", i):
            j = i
            while j < n and text[j] != "\n":
                if text[j] == "\\" and j + 1 < n and text[j + 1] == "\n":
                    j += 2
                    continue
                j += 1
            out.append(blank(text[i:j]))
            i = j
            continue
        if text.startswith("/*", i):
            k = text.find("*/", i + 2)
            j = n if k < 0 else k + 2
            out.append(blank(text[i:j]))
            i = j
            continue
        m = re.match(r'(?:u8|u|U|L)?R"([^()\\\s]{0,16})\(', text[i:i + 40])
        if m and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            end = text.find(")" + m.group(1) + '"', i + m.end())
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append('""' + blank(text[i + 2:j]))
            i = j
            continue
        if c == '"' or c == "'":
            if c == "'" and i > 0 and re.match(r"[0-9A-Fa-f]", text[i - 1]):
                # A digit separator (1'000, 0xFF'FF) if the run of word characters before it
                # started with a digit; otherwise a prefixed literal such as u8'a' or L'a'.
                k = i - 1
                while k > 0 and (text[k - 1].isalnum() or text[k - 1] in "_.'"):
                    k -= 1
                if text[k].isdigit():
                    out.append(" ")
                    i += 1
                    continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(c + c + blank(text[i + 2:j]) if j - i >= 2 else blank(text[i:j]))
            i = j
            continue
        out.append(c)
        i += 1
    return "".join(out)


TOKEN = re.compile(r"[A-Za-z_]\w*|\d[\w.']*|->|::|&&|\"\"|''|\S")


def tokenize(code):
    """Returns (token, line) pairs of blanked code (lines count from 1)."""
    tokens = []
    line = 1
    pos = 0
    for m in TOKEN.finditer(code):
        line += code.count("\n", pos, m.start())
        pos = m.start()
        tokens.append((m.group(0), line))
    return tokens


def match_bracket(seq, i, open_tok, close_tok, step=1, text=lambda t: t):
    """Walking from seq[i] by `step` (1: forwards, -1: backwards, then open_tok is the closing
    bracket), the index where the bracket depth returns to 0; len(seq) or -1 if it never does.
    `text` gives an item's token text."""
    depth = 0
    k = i
    while 0 <= k < len(seq):
        t = text(seq[k])
        if t == open_tok:
            depth += 1
        elif t == close_tok:
            depth -= 1
            if depth == 0:
                return k
        k += step
    return k


def matching(tokens, i, open_tok, close_tok):
    """Index of the token closing the bracket opened at tokens[i] (len(tokens) if unbalanced)."""
    return match_bracket(tokens, i, open_tok, close_tok, text=lambda t: t[0])


def strip_template_prefix(header):
    """Drops leading `template <...>` clauses (and attributes) from a list of tokens."""
    while header:
        if header[0] == "template" and len(header) > 1 and header[1] == "<":
            header = header[match_bracket(header, 1, "<", ">") + 1:]
        elif header[:2] == ["[", "["]:
            k = 2
            while k + 1 < len(header) and header[k:k + 2] != ["]", "]"]:
                k += 1
            header = header[k + 2:]
        else:
            break
    return header


def parameter_list_end(header):
    """Index of the `)` closing a function's parameter list in `header`, or None if not a function.

    After it may come only qualifiers, noexcept(...)/throw(...), a trailing return type and a
    constructor's initialiser list (whose braces the caller has already kept as tokens).
    """
    k = 0
    while k < len(header):
        t = header[k]
        if t == "operator":
            # operator==, operator(), operator[], operator new, operator bool: the name runs to
            # the `(` of the parameter list (the first `(` after `operator ()`).
            j = k + 1
            if header[j:j + 2] == ["(", ")"]:
                j += 2
            while j < len(header) and header[j] != "(":
                j += 1
            if j >= len(header):
                return None
            k = j
        elif t == "(":
            prev = header[k - 1] if k > 0 else ""
            if not (re.match(r"[A-Za-z_]", prev) or prev in (">", "]")) or prev in NOT_NAMES:
                k += paren_span(header[k:])  # decltype(...), alignas(...): not a parameter list
                continue
        elif t == "[" and k > 0 and header[k - 1] == "=" and "]" in header[k:]:
            # A lambda stored in a variable: `name = [captures](parameters) ... {`.
            k = header.index("]", k) + 1
            if k >= len(header) or header[k] != "(":
                return len(header) - 1 if tail_is_function_tail(header[k:]) else None
        elif t in ("{", "}") or (t == "=" and header[k + 1:k + 2] != ["["]):
            return None
        else:
            k += 1
            continue
        close = k + paren_span(header[k:]) - 1
        if close >= len(header) or header[close] != ")":
            return None
        if tail_is_function_tail(header[close + 1:]):
            return close
        # Not followed by a function's tail: a macro invocation without a semicolon
        # (`SMPL_KERNEL_VARIANTS(...)`) or `__attribute__((...))` before the declaration.
        k = close + 1
    return None


NOT_NAMES = QUALIFIERS | {"return", "sizeof", "decltype", "alignas", "alignof", "if", "while", "for", "switch", "typeid"}


def tail_is_function_tail(tail):
    """True if `tail` (what follows a parameter list) can precede a function body."""
    k = 0
    while k < len(tail):
        t = tail[k]
        if t in QUALIFIERS:
            if k + 1 < len(tail) and tail[k + 1] == "(" and t in ("noexcept", "throw"):
                k = k + 1 + paren_span(tail[k + 1:])
                continue
            k += 1
        elif t == "->":
            # A trailing return type: anything up to the end or an initialiser-list colon does not
            # occur (a trailing return type is only on functions, not constructors).
            return True
        elif t == ":":
            return True  # a constructor's initialiser list
        elif t == "[" and tail[k:k + 2] == ["[", "["]:
            while k < len(tail) and tail[k] != "]":
                k += 1
            k += 2
        else:
            return False
    return True


def paren_span(tokens):
    """How many tokens the parenthesised group at tokens[0] spans (all of them if unbalanced)."""
    return min(match_bracket(tokens, 0, "(", ")") + 1, len(tokens))


def function_name(header, close):
    """The (qualified) name before the parameter list that ends at header[close]."""
    k = match_bracket(header, close, ")", "(", step=-1)
    k -= 1  # the last token of the name
    if k >= 0 and header[k] == "]":
        return "<lambda>"
    op = max((j for j in range(max(0, k - 3), k + 1) if header[j] == "operator"), default=None)
    if op is not None:
        symbol = header[op + 1:k + 1]
        name = "operator" + ("".join(symbol) if symbol and not re.match(r"\w", symbol[0]) else " " + " ".join(symbol))
        k = op - 1
    else:
        k = skip_template_args(header, k)
        if k < 0 or not re.match(r"[A-Za-z_]", header[k]):
            return "<unnamed>"
        name = header[k]
        k -= 1
        if k >= 0 and header[k] == "~":
            name = "~" + name
            k -= 1
    parts = [name]
    while k >= 1 and header[k] == "::":
        k = skip_template_args(header, k - 1)
        if k < 0 or not re.match(r"[A-Za-z_]", header[k]):
            break
        parts.insert(0, header[k])
        k -= 1
    return "::".join(parts)


def skip_template_args(header, k):
    """If header[k] closes template arguments (`>`), the index of the token before their `<`."""
    if k < 0 or header[k] != ">":
        return k
    k = match_bracket(header, k, ">", "<", step=-1)
    return k - 1 if k >= 0 else k


def find_functions(code):
    """Returns (name, first line, length) of every function body at namespace or class scope."""
    tokens = tokenize(code)
    found = []
    scopes = []  # names of the enclosing classes (namespaces are not part of the reported name)

    def read_scope(i, class_name):
        header = []
        header_lines = []
        while i < len(tokens):
            t, line = tokens[i]
            if t == "}":
                return i + 1
            if t == ";":
                header = []
                header_lines = []
                i += 1
                continue
            if t != "{":
                header.append(t)
                header_lines.append(line)
                i += 1
                continue
            h = strip_template_prefix(header)
            close = parameter_list_end(h)
            # Member initialisers in a constructor's initialiser list: `: a_{x}, b_{y} {`.
            if close is not None and ":" in h[close + 1:] and h and (re.match(r"\w", h[-1]) and h[-1] not in QUALIFIERS or h[-1] == ">"):
                end = matching(tokens, i, "{", "}")
                header.extend(tok for tok, _ in tokens[i:end + 1])
                header_lines.extend(ln for _, ln in tokens[i:end + 1])
                i = end + 1
                continue
            if close is not None:
                end = matching(tokens, i, "{", "}")
                end_line = tokens[end][1] if end < len(tokens) else tokens[-1][1]
                if is_lambda_variable(h):
                    name = lambda_variable_name(h) + " (lambda)"
                else:
                    name = function_name(h, close)
                if class_name and "::" not in name:
                    name = class_name + "::" + name
                found.append((name, line, end_line - line + 1))
                i = end + 1
                header = []
                header_lines = []
                # `};` after a lambda variable: the `;` resets the header.
                continue
            is_namespace = h[:1] == ["namespace"] or h[:2] == ["inline", "namespace"] or h[:2] == ["extern", '""']
            class_key = next((k for k, tok in enumerate(h) if tok in CLASS_KEYS), None)
            if is_namespace:
                i = read_scope(i + 1, class_name)
                header = []
                header_lines = []
                continue
            if class_key is not None and "=" not in h and "(" not in h[:class_key]:
                name_tokens = [tok for tok in h[class_key + 1:] if re.match(r"[A-Za-z_]\w*$", tok)
                               and tok not in ("final", "class", "struct", "alignas", "public", "private", "protected", "virtual")]
                inner = name_tokens[0] if name_tokens else "<anonymous>"
                if h[class_key] == "enum":
                    i = matching(tokens, i, "{", "}") + 1
                else:
                    qualified = class_name + "::" + inner if class_name else inner
                    i = read_scope(i + 1, qualified)
                # A declarator may follow (`struct { ... } x;`): keep reading up to the `;`.
                header = ["}"]
                header_lines = [line]
                continue
            # An aggregate or brace initialiser: step over it and keep the header.
            end = matching(tokens, i, "{", "}")
            header.extend(tok for tok, _ in tokens[i:end + 1])
            header_lines.extend(ln for _, ln in tokens[i:end + 1])
            i = end + 1
        return i

    i = 0
    while i < len(tokens):
        i = read_scope(i, "")
    return found


def is_lambda_variable(h):
    if "=" not in h:
        return False
    k = h.index("=")
    return k + 1 < len(h) and h[k + 1] == "["


def lambda_variable_name(h):
    k = h.index("=")
    return h[k - 1] if k > 0 else "<lambda>"


def repo_root():
    return os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def list_sources(root, paths):
    """Repository-relative paths of the C++ sources to scan."""
    if paths:
        files = []
        for p in paths:
            if os.path.isdir(p):
                for d, _, names in os.walk(p):
                    files.extend(os.path.join(d, f) for f in names if f.endswith(SOURCE_SUFFIXES))
            else:
                files.append(p)
        return sorted(files)
    out = subprocess.run(["git", "-C", root, "ls-files", "--", "*.cpp", "*.hpp", "*.h", "*.cc"],
                         check=True, capture_output=True, text=True).stdout.split("\n")
    return sorted(f for f in out if f and not f.startswith("tests/") and "/generated/" not in f)


def scan(root, files, limit):
    """(path, line, name, length) of every function longer than `limit`, longest first."""
    long_ones = []
    for f in files:
        path = f if os.path.isabs(f) else os.path.join(root, f)
        with open(path, encoding="utf-8", errors="replace") as fh:
            code = blank_non_code(fh.read())
        seen = {}
        for name, line, length in find_functions(code):
            if length <= limit:
                continue
            # Two long overloads of one name in one file: the second is `name#2`.
            seen[name] = seen.get(name, 0) + 1
            key = name if seen[name] == 1 else "%s#%d" % (name, seen[name])
            long_ones.append((f, line, key, length))
    long_ones.sort(key=lambda e: (-e[3], e[0], e[1]))
    return long_ones


def read_allow(text):
    """{(path, name): length} from the text of an allow file; raises ValueError on a bad line."""
    entries = {}
    for number, raw in enumerate(text.split("\n"), 1):
        line = raw.split("#", 1)[0].strip() if raw.lstrip().startswith("#") else raw.strip()
        if not line:
            continue
        fields = line.split()
        if len(fields) != 3 or not fields[2].isdigit():
            raise ValueError("line %d: %r is not `path  name  length`" % (number, raw))
        entries[(fields[0], fields[1])] = int(fields[2])
    return entries


ALLOW_HEADER = """\
# Functions over the length limit of tools/long_functions.py, tolerated for now: path  name  length.
# This list may only shrink: a listed function may not grow, and no line may be added. Split a
# function and then run `tools/long_functions.py --update` to lower or remove its line.
"""


def format_allow(entries):
    rows = sorted(entries.items(), key=lambda e: (e[0][0], e[0][1]))
    width_path = max((len(p) for (p, _), _ in rows), default=0)
    width_name = max((len(n) for (_, n), _ in rows), default=0)
    return ALLOW_HEADER + "".join("%-*s  %-*s  %d\n" % (width_path, p, width_name, n, length)
                                  for (p, n), length in rows)


def allow_history(root, allow_rel):
    """The allow file's text in every commit that changed it (oldest first), or None without git."""
    try:
        revs = subprocess.run(["git", "-C", root, "log", "--format=%H", "--", allow_rel],
                              check=True, capture_output=True, text=True).stdout.split()
    except (OSError, subprocess.CalledProcessError):
        return None
    texts = []
    for rev in reversed(revs):
        shown = subprocess.run(["git", "-C", root, "show", "%s:%s" % (rev, allow_rel)],
                               capture_output=True, text=True)
        if shown.returncode == 0:
            texts.append((rev[:10], shown.stdout))
    return texts


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("paths", nargs="*", help="files or folders to scan (default: the repository's sources outside tests/)")
    parser.add_argument("--limit", type=int, default=DEFAULT_LIMIT, help="longest function allowed, in lines (default %(default)s)")
    parser.add_argument("--allow", help="ratchet list (default: %s; with PATHs: none)" % DEFAULT_ALLOW)
    parser.add_argument("--list", action="store_true", help="only list the long functions, check nothing")
    parser.add_argument("--update", action="store_true", help="lower or remove the lines of the allow list that are too high (never adds one)")
    parser.add_argument("--no-history", action="store_true", help="do not compare the allow list with its committed versions")
    args = parser.parse_args(argv)
    if args.limit < 1:
        parser.error("--limit must be at least 1")

    root = repo_root() if not args.paths else os.getcwd()
    long_ones = scan(root, list_sources(root, args.paths), args.limit)
    for f, line, name, length in long_ones:
        print("%s:%d  %d  %s" % (f, line, length, name))
    print("%d functions over %d lines" % (len(long_ones), args.limit))
    if args.list:
        return 0

    allow_path = args.allow or (None if args.paths else os.path.join(root, DEFAULT_ALLOW))
    allow = {}
    allow_text = ""
    if allow_path:
        try:
            with open(allow_path, encoding="utf-8") as fh:
                allow_text = fh.read()
        except FileNotFoundError:
            allow_text = ""
        try:
            allow = read_allow(allow_text)
        except ValueError as e:
            print("%s: %s" % (allow_path, e), file=sys.stderr)
            return 2

    shown_allow = os.path.relpath(allow_path) if allow_path else "the allow list"
    found = {(f, name): (line, length) for f, line, name, length in long_ones}
    problems = []
    for (f, name), (line, length) in sorted(found.items()):
        if (f, name) not in allow:
            problems.append("%s:%d: %s is %d lines, over the limit of %d and not on %s: split it "
                            "(the list may not grow)" % (f, line, name, length, args.limit, shown_allow))
        elif length > allow[(f, name)]:
            problems.append("%s:%d: %s grew to %d lines; the allow list tolerates %d: shorten it "
                            "to %d lines or fewer (better: split it under %d)"
                            % (f, line, name, length, allow[(f, name)], allow[(f, name)], args.limit))
    updated = dict(allow)
    for (f, name), listed in sorted(allow.items()):
        if (f, name) not in found:
            problems.append("%s: %s is no longer over %d lines (or is gone, or moved): remove its "
                            "line from the allow list (`tools/long_functions.py --update`)" % (f, name, args.limit))
            del updated[(f, name)]
        elif found[(f, name)][1] < listed:
            problems.append("%s: %s is now %d lines, the allow list says %d: lower its line "
                            "(`tools/long_functions.py --update`)" % (f, name, found[(f, name)][1], listed))
            updated[(f, name)] = found[(f, name)][1]

    if allow_path and not args.no_history and not args.paths:
        history = allow_history(root, os.path.relpath(allow_path, root))
        for rev, text in history or []:
            try:
                old = read_allow(text)
            except ValueError:
                continue
            for key, listed in sorted(allow.items()):
                if key not in old:
                    problems.append("%s: %s is on the allow list but was not in its version of commit %s: "
                                    "the list may only shrink; split the function instead"
                                    % (key[0], key[1], rev))
                elif listed > old[key]:
                    problems.append("%s: %s is listed with %d lines but with %d in commit %s: the list "
                                    "may only shrink; split the function instead" % (key[0], key[1], listed, old[key], rev))

    if args.update:
        if allow_path and updated != allow:
            tmp = allow_path + ".tmp"
            with open(tmp, "w", encoding="utf-8") as fh:
                fh.write(format_allow(updated))
            os.replace(tmp, allow_path)
            print("updated %s: %d lines (was %d)" % (allow_path, len(updated), len(allow)))
        problems = [p for p in problems if "--update" not in p]

    if problems:
        print("", file=sys.stderr)
        for p in problems:
            print(p, file=sys.stderr)
        print("long functions: %d problem(s); limit %d lines (tools/long_functions.py, docs/ci.md)"
              % (len(problems), args.limit), file=sys.stderr)
        return 1
    print("long functions: %d over %d lines, all on the allow list at their listed length"
          % (len(long_ones), args.limit))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
