#!/usr/bin/env python3
"""Lists the places where a front end (the command line in src/, the Python package in
python/src/) names tiltnoise-io or tiltnoise-plot directly instead of going through the job
crate (tiltnoise_job and its documented re-exports, tiltnoise_job::files).

Usage: front_end_imports.py [--require-none] [ROOT]
Prints one line per file and path found, then a count; with --require-none exits 1 if any.
"""
import pathlib
import re
import sys

FRONT_ENDS = ("src", "python/src")
LOWER = re.compile(r"\btiltnoise_(io|plot)\b")


def strip_comments(line):
    """The code of a line, without a `//` comment (doc comments included)."""
    in_str = False
    i = 0
    while i < len(line) - 1:
        c = line[i]
        if c == '"' and (i == 0 or line[i - 1] != "\\"):
            in_str = not in_str
        if not in_str and line.startswith("//", i):
            return line[:i]
        i += 1
    return line


def main(argv):
    require_none = "--require-none" in argv
    rest = [a for a in argv if not a.startswith("--")]
    root = pathlib.Path(rest[0] if rest else ".")
    found = []
    for front in FRONT_ENDS:
        for path in sorted((root / front).rglob("*.rs")):
            for number, line in enumerate(path.read_text().splitlines(), 1):
                if LOWER.search(strip_comments(line)):
                    found.append((path.relative_to(root), number, line.strip()))
    files = sorted({str(p) for p, _, _ in found})
    for path, number, line in found:
        print(f"{path}:{number}: {line}")
    print(f"front-end files naming tiltnoise-io or tiltnoise-plot: {len(files)} "
          f"({len(found)} lines)")
    if require_none and found:
        print("the front ends must import the file layer through tiltnoise_job "
              "(tiltnoise_job::files and the jobs' outcomes)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
