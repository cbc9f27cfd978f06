#!/usr/bin/env python3
"""Imports that run back up a crate's module tree: a module naming an item of its own parent or
of a module above it (`super::helper`, `crate::input::helper` from inside `input/`, `crate::X`
for an item of lib.rs). Paths to a sibling or a cousin module (`super::common::helper`) are
fine, as are paths into other crates; unit-test modules (`#[cfg(test)]`) are not counted, since
a test module is meant to see its parent.

    python3 scripts/dev/back_imports.py [--max N] [CRATE_SRC ...]

CRATE_SRC defaults to crates/tiltnoise-io/src. Prints each back-import (file:line: path ->
the module it names) and the count; exits 1 when the count exceeds --max (default 0).
"""

import argparse
import os
import re
import sys


def strip(src):
    """`src` with comments, string and character literals blanked (lines kept)."""
    out, i, n = [], 0, len(src)
    while i < n:
        if src.startswith("//", i):
            j = src.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif src.startswith("/*", i):
            depth, j = 0, i
            while True:
                if src.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif src.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                    if depth == 0:
                        break
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", src[i:j]))
            i = j
        elif (m := re.match(r'b?r(#*)"', src[i:])) and not (i and (src[i - 1].isalnum() or src[i - 1] == "_")):
            j = src.index('"' + m.group(1), i + m.end()) + 1 + len(m.group(1))
            out.append(re.sub(r"[^\n]", " ", src[i:j]))
            i = j
        elif src[i] == '"':
            j = i + 1
            while src[j] != '"':
                j += 2 if src[j] == "\\" else 1
            out.append(re.sub(r"[^\n]", " ", src[i : j + 1]))
            i = j + 1
        elif src[i] == "'" and (m := re.match(r"'(\\.[^']*|[^\\'])'", src[i:])):
            out.append(" " * m.end())
            i += m.end()
        else:
            out.append(src[i])
            i += 1
    return "".join(out)


def without_test_modules(code):
    """`code` with every `#[cfg(test)] mod NAME { ... }` blanked."""
    for m in reversed(list(re.finditer(r"#\[cfg\(test\)\]\s*mod\s+\w+\s*\{", code))):
        depth, j = 0, m.end() - 1
        while True:
            depth += {"{": 1, "}": -1}.get(code[j], 0)
            j += 1
            if depth == 0:
                break
        code = code[: m.start()] + re.sub(r"[^\n]", " ", code[m.start() : j]) + code[j:]
    return code


def modules(src_dir):
    """{module path tuple: file} of the crate, without test-only modules."""
    found = {}

    def visit(path, file):
        found[path] = file
        code = strip(open(file).read())
        here = os.path.dirname(file) if os.path.basename(file) in ("lib.rs", "mod.rs") else file[:-3]
        for m in re.finditer(r"(#\[cfg\(test\)\]\s*)?(pub(\([^)]*\))?\s+)?mod\s+(\w+)\s*;", code):
            if m.group(1):
                continue
            name = m.group(4)
            for child in (os.path.join(here, name + ".rs"), os.path.join(here, name, "mod.rs")):
                if os.path.exists(child):
                    visit(path + (name,), child)

    visit((), os.path.join(src_dir, "lib.rs"))
    return found


def use_paths(code):
    """(offset, path) of every `use` leaf (groups expanded) and of every other `super::` or
    `crate::` path in `code`."""
    found, spans = [], []
    for m in re.finditer(r"\buse\s+([^;]+);", code):
        spans.append((m.start(), m.end()))

        def expand(prefix, text):
            text = text.strip()
            g = text.find("{")
            if g < 0:
                found.append((m.start(), prefix + text.split(" as ")[0].strip()))
                return
            head, body = text[:g], text[g + 1 : text.rindex("}")]
            depth, part, parts = 0, "", []
            for c in body:
                if c == "," and depth == 0:
                    parts.append(part)
                    part = ""
                    continue
                depth += {"{": 1, "}": -1}.get(c, 0)
                part += c
            parts.append(part)
            for p in parts:
                if p.strip():
                    expand(prefix + head, p)

        expand("", m.group(1))
    for m in re.finditer(r"\b(?:super|crate)(?:\s*::\s*\w+)+", code):
        if not any(a <= m.start() < b for a, b in spans):
            found.append((m.start(), m.group(0)))
    return [(o, re.sub(r"\s+", "", p)) for o, p in found]


def target(here, path, tree):
    """The module that `path` (from module `here`) names an item of, and the item."""
    segs = path.split("::")
    if segs[0] not in ("super", "crate", "self"):
        return None
    at = list(here)
    while segs and segs[0] in ("super", "crate", "self"):
        s = segs.pop(0)
        if s == "super":
            at.pop()
        elif s == "crate":
            at = []
    while segs and tuple(at + [segs[0]]) in tree:
        at.append(segs.pop(0))
    return tuple(at), (segs[0] if segs else "self")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--max", type=int, default=0)
    ap.add_argument("src", nargs="*", default=["crates/tiltnoise-io/src"])
    args = ap.parse_args()
    total = 0
    for src_dir in args.src:
        tree = modules(src_dir)
        for here, file in sorted(tree.items()):
            code = without_test_modules(strip(open(file).read()))
            for offset, path in use_paths(code):
                t = target(here, path, tree)
                if t is None:
                    continue
                module, item = t
                if len(module) < len(here) and here[: len(module)] == module and item != "self":
                    total += 1
                    line = code.count("\n", 0, offset) + 1
                    name = "::".join(("crate",) + module)
                    print(f"{file}:{line}: {path} -> {name}")
    print(f"{total} imports run back up to a parent or higher module")
    sys.exit(1 if total > args.max else 0)


if __name__ == "__main__":
    main()
