#!/usr/bin/env python3
"""The repository's notebooks: committed without outputs, and run from top to bottom in CI.

    python3 scripts/ci/notebook.py check NOTEBOOK...   fails if a code cell has outputs or an
                                                        execution count (standard library only)
    python3 scripts/ci/notebook.py strip NOTEBOOK...   removes them in place (before committing)
    python scripts/ci/notebook.py run NOTEBOOK...      executes each with nbclient in the
                                                        notebook's directory (nbclient, nbformat
                                                        and ipykernel in this Python); fails on
                                                        the first cell that raises, prints the
                                                        run time

`run` also fails when a notebook draws no figure (an image/png output) or when a code cell
produced an error stream, so a notebook that "ran" by printing a traceback does not pass.
"""

import json
import sys
import time
from pathlib import Path


def load(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def dirty_cells(notebook):
    """(index, what) of every code cell with outputs or an execution count."""
    found = []
    for i, cell in enumerate(notebook.get("cells", [])):
        if cell.get("cell_type") != "code":
            continue
        if cell.get("outputs"):
            found.append((i, f"{len(cell['outputs'])} output(s)"))
        if cell.get("execution_count") is not None:
            found.append((i, f"execution_count {cell['execution_count']}"))
    return found


def check(paths):
    failed = False
    for path in paths:
        dirty = dirty_cells(load(path))
        for i, what in dirty:
            print(f"{path}: cell {i} has {what}; strip it: "
                  f"python3 scripts/ci/notebook.py strip {path}", file=sys.stderr)
        failed |= bool(dirty)
        if not dirty:
            print(f"{path}: no outputs, no execution counts")
    return 1 if failed else 0


def strip(paths):
    for path in paths:
        notebook = load(path)
        for cell in notebook.get("cells", []):
            if cell.get("cell_type") == "code":
                cell["outputs"] = []
                cell["execution_count"] = None
        text = json.dumps(notebook, indent=1, ensure_ascii=False) + "\n"
        Path(path).write_text(text, encoding="utf-8")
    return 0


def run(paths):
    import nbformat
    from nbclient import NotebookClient

    for path in paths:
        path = Path(path).resolve()
        notebook = nbformat.read(path, as_version=4)
        client = NotebookClient(notebook, timeout=600, kernel_name="python3",
                                resources={"metadata": {"path": str(path.parent)}})
        start = time.perf_counter()
        client.execute()  # raises CellExecutionError on the first cell that raises
        seconds = time.perf_counter() - start
        figures = errors = 0
        for cell in notebook.cells:
            for output in cell.get("outputs", []):
                figures += "image/png" in output.get("data", {})
                errors += output.get("output_type") == "error"
                errors += output.get("name") == "stderr" and "Traceback" in output.get("text", "")
        code_cells = sum(cell.cell_type == "code" for cell in notebook.cells)
        print(f"{path.name}: {code_cells} code cells, {figures} figures, ran in {seconds:.1f} s")
        if errors or not figures:
            print(f"{path}: {errors} error output(s), {figures} figure(s)", file=sys.stderr)
            return 1
    return 0


def main(argv):
    commands = {"check": check, "strip": strip, "run": run}
    if len(argv) < 3 or argv[1] not in commands:
        print(__doc__, file=sys.stderr)
        return 2
    return commands[argv[1]](argv[2:])


if __name__ == "__main__":
    sys.exit(main(sys.argv))
