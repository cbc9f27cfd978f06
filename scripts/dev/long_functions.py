#!/usr/bin/env python3
"""Rust functions longer than a limit, longest first.

    python3 scripts/dev/long_functions.py [--limit 150] [PATH ...]

PATH defaults to src, crates and python/src. A function's length is the number of lines
from its `fn` line to its closing brace, both included (doc comments and attributes not
counted). Braces inside string and character literals and comments are skipped, which is
enough for this code base (no raw strings holding braces).
"""

import argparse
import os
import re

FN = re.compile(r"^\s*(pub(\([^)]*\))?\s+)?((const|async|unsafe|extern \"C\")\s+)*fn\s+(\w+)")


def braces(line, state):
    """Net brace count of `line`, skipping literals and comments; `state` carries a block
    comment across lines."""
    depth, i, n = 0, 0, len(line)
    while i < n:
        c = line[i]
        if state["block"]:
            if line.startswith("*/", i):
                state["block"] = False
                i += 2
                continue
            i += 1
            continue
        if line.startswith("//", i):
            break
        if line.startswith("/*", i):
            state["block"] = True
            i += 2
            continue
        if c == '"':
            i += 1
            while i < n and line[i] != '"':
                i += 2 if line[i] == "\\" else 1
        elif c == "'" and re.match(r"'(\\.|[^\\'])'", line[i:]):
            i += len(re.match(r"'(\\.|[^\\'])'", line[i:]).group(0)) - 1
        elif c == "{":
            depth += 1
        elif c == "}":
            depth -= 1
        i += 1
    return depth


def functions(path):
    lines = open(path, encoding="utf-8").read().splitlines()
    out = []
    for start, line in enumerate(lines):
        m = FN.match(line)
        if not m:
            continue
        state, depth, opened = {"block": False}, 0, False
        for end in range(start, len(lines)):
            if not opened and lines[end].rstrip().endswith(";") and "{" not in lines[end]:
                break  # a declaration without a body (trait method)
            d = braces(lines[end], state)
            opened = opened or "{" in lines[end]
            depth += d
            if opened and depth <= 0:
                out.append((end - start + 1, f"{path}:{start + 1}", m.group(5)))
                break
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--limit", type=int, default=150)
    ap.add_argument("paths", nargs="*", default=["src", "crates", "python/src"])
    a = ap.parse_args()
    found = []
    for root in a.paths:
        for d, _, files in os.walk(root):
            found += [f for name in files if name.endswith(".rs")
                      for f in functions(os.path.join(d, name))]
    for n, where, name in sorted(found, reverse=True):
        if n > a.limit:
            print(f"{n:5d}  {name:40s} {where}")


if __name__ == "__main__":
    main()
