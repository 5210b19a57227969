#!/usr/bin/env python3
"""Fails on a line of the tree that names a development session or an issue
number (an ordinal before "session", "issue" before a number, "issue point"):
the tree describes the present (a figure with its command, machine and
date); its history is git's, and the tracker is not in the repository.

Reads every tracked text file (and untracked ones git does not ignore);
binary files and recorded logs are skipped.

Usage: check_present_tense.py REPO_ROOT
       check_present_tense.py --self-test
"""
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import source_check  # noqa: E402

ORDINALS = ("first|second|third|fourth|fifth|sixth|seventh|eighth|ninth|tenth|eleventh|twelfth|thirteenth|"
            "fourteenth|fifteenth|sixteenth|seventeenth|eighteenth|nineteenth|twentieth|[0-9]+(st|nd|rd|th)")
HISTORY = re.compile(r"\b(%s)[ -]session|\b(this|last|previous|earlier|next) session's\b|\bissue #?[0-9]+|"
                     r"\bissue point\b|\bissues? [0-9]+(, [0-9]+)* and [0-9]+" % ORDINALS, re.I)
SKIP_SUFFIXES = (".lcmlog", ".xz", ".png", ".jpg", ".stl", ".obj", ".dae", ".key")
# This file's pattern itself would match its own text.
SELF = "tests/format/check_present_tense.py"


def tracked_files(root):
    return [rel for rel in source_check.tree_files(root) if not rel.endswith(SKIP_SUFFIXES) and rel != SELF]


def history_lines(text):
    return [(number, line.strip()) for number, line in enumerate(text.splitlines(), 1) if HISTORY.search(line)]


def main(root):
    problems, read = [], 0
    for rel in tracked_files(root):
        path = os.path.join(root, rel)
        if not os.path.isfile(path):
            continue
        with open(path, "rb") as f:
            data = f.read()
        if b"\0" in data:
            continue
        read += 1
        for number, line in history_lines(data.decode("utf-8", errors="replace")):
            problems.append("%s:%d: %s" % (rel, number, line[:160]))
    for text in problems:
        print("NAMES ITS HISTORY: " + text)
    print("%d files read, %d lines name a session or an issue number" % (read, len(problems)))
    return 1 if problems else 0


def self_test():
    # (Put together here, so that this file names no session or issue
    # itself.)
    session, issue = " session", "issue "
    bad = ["measured in the fourteenth" + session, issue + "17's targets", "(" + issue + "point 5)",
           "the 3rd" + session + "'s run", issue.replace(" ", "s ") + "14 and 15", "as " + issue + "#13 asked"]
    good = ["a debugging session (gdb)", "a recording session on the robot", "the issue of stale frames",
            "the 14th frame", "docs/benchmarks.md, \"Targets\""]
    ok = True
    for line in bad:
        if not history_lines(line):
            ok = False
            print("SELF-TEST: not found: " + line)
    for line in good:
        if history_lines(line):
            ok = False
            print("SELF-TEST: wrongly found: " + line)
    print("self-test " + ("passed" if ok else "FAILED"))
    return 0 if ok else 1


if __name__ == "__main__":
    source_check.run(__doc__, main, self_test)
