#!/usr/bin/env python3
"""Fails on a C++ function body over MAX_LINES lines outside tests/: a long
function is split into named steps a reader can follow (the project's
style: "functions read as named steps").

A function is a brace block opened right after a parameter list (")" and
qualifiers such as const, noexcept, override, a trailing return type) that
is not an if/for/while/switch/catch; nested functions (lambdas, local
classes' members) count towards the function around them. Comments, string
and character literals are blanked first, so braces inside them do not
count. Lines are counted from the opening to the closing brace.

Usage: check_function_length.py REPO_ROOT
       check_function_length.py --self-test
"""
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import source_check  # noqa: E402

MAX_LINES = 120
SKIP_TOP = {"tests"}
FUNCTION_HEAD = re.compile(r"\)\s*(const|noexcept|override|final|mutable|->\s*[\w:<>,\s*&]+|\s)*$")
CONTROL_HEAD = re.compile(r"\b(if|for|while|switch|catch)\s*\(.*\)\s*$", re.S)


def blank_comments_and_strings(text):
    out, i, n = [], 0, len(text)
    while i < n:
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
            continue
        raw = re.match(r'R"([^(\s]*)\(', text[i:i + 20]) if text[i] == "R" else None
        if raw:
            end = ")" + raw.group(1) + '"'
            j = text.find(end, i)
            j = n if j < 0 else j + len(end)
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
            continue
        c = text[i]
        if c in "\"'" and not (c == "'" and i > 0 and text[i - 1].isalnum()):  # 1'000 digit separators
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
            continue
        out.append(c)
        i += 1
    return "".join(out)


def long_functions(text, limit=MAX_LINES):
    """[(first line, length)] of the outermost functions over `limit` lines."""
    code = blank_comments_and_strings(text)
    found, stack, line = [], [], 1
    for k, ch in enumerate(code):
        if ch == "\n":
            line += 1
        elif ch == "{":
            head = code[max(0, k - 300):k]
            head = head[max(head.rfind(";"), head.rfind("{"), head.rfind("}")) + 1:]
            is_function = bool(FUNCTION_HEAD.search(head)) and not CONTROL_HEAD.search(head.strip())
            stack.append((is_function, line))
        elif ch == "}" and stack:
            is_function, start = stack.pop()
            if is_function and not any(outer for outer, _ in stack):
                length = line - start + 1
                if length > limit:
                    found.append((start, length))
    return found


def tracked_sources(root):
    return [rel for rel in source_check.tree_files(root, ("*.cpp", "*.hpp", "*.h", "*.cc"))
            if rel.split("/")[0] not in SKIP_TOP]


def main(root):
    problems = []
    files = tracked_sources(root)
    for rel in files:
        path = os.path.join(root, rel)
        if not os.path.isfile(path):
            continue
        with open(path, encoding="utf-8", errors="replace") as f:
            for start, length in long_functions(f.read()):
                problems.append("%s:%d: a function of %d lines (at most %d): split it into named steps" %
                                (rel, start, length, MAX_LINES))
    for text in problems:
        print("FUNCTION TOO LONG: " + text)
    print("%d files read, %d functions over %d lines" % (len(files), len(problems), MAX_LINES))
    return 1 if problems else 0


def self_test():
    body = "\n".join("  x += %d;" % i for i in range(MAX_LINES))
    cases = {
        "long function": ("int f(int x) {\n%s\n  return x;\n}\n" % body, [1]),
        "long if in a short function": ("void g() {\n  if (a) {\n%s\n  }\n}\n" % body, [1]),
        "short function with braces in a comment and a string": (
            "int h() {\n  // }}}}\n  const char* s = \"{{{{\";\n  return 0;\n}\n", []),
        "long lambda inside a function": ("void k() {\n  auto l = [&](int x) {\n%s\n  };\n}\n" % body, [1]),
        "class with short members": ("struct S {\n  int a() const { return 1; }\n%s\n};\n" %
                                     "\n".join("  int m%d() { return %d; }" % (i, i) for i in range(130)), []),
        "exactly the limit": ("int f() {\n%s\n}\n" % "\n".join("  ;" for _ in range(MAX_LINES - 2)), []),
    }
    ok = True
    for name, (text, expected_starts) in cases.items():
        starts = [start for start, _ in long_functions(text)]
        good = starts == expected_starts
        ok &= good
        print("%s: %s (found %s, expected %s)" % ("ok" if good else "WRONG", name, starts, expected_starts))
    print("self-test " + ("passed" if ok else "FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    source_check.run(__doc__, main, self_test)
