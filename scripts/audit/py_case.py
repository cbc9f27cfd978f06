"""Runs one Python case of the hostile-input audit: `python py_case.py CODE`.

CODE runs with the working directory as its scratch directory and may set `result`. An exception
(any, KeyboardInterrupt included) is printed as one line `TypeName: message` on stderr with exit
code 2, as the command line reports a refused input; a crash of the interpreter stays a crash.
On success every number reachable from `result` (arrays, floats, dicts, sequences, and a
tiltnoise Budget's totals and terms) is checked, and each non-finite one is printed on stdout as
`result ...: nan`, which the audit counts as a silent non-finite value. NaN is allowed where the
package documents it: the `measured` and `residual` terms outside the band of a measured record.
"""
import math
import sys

ALLOWED = ("measured", "residual")


def walk(value, where, out):
    if len(out) >= 5:
        return
    try:
        import numpy as np
    except ImportError:  # the audit's interpreter always has NumPy; a report still works without
        np = None
    if np is not None and isinstance(value, np.ndarray):
        if value.dtype.kind in "fc" and value.size and not np.isfinite(value).all():
            bad = value[~np.isfinite(value)].ravel()[0]
            out.append(f"result{where}: {bad}")
        return
    if isinstance(value, float):
        if not math.isfinite(value):
            out.append(f"result{where}: {value}")
        return
    if isinstance(value, dict):
        for k, v in value.items():
            if not any(a in str(k) for a in ALLOWED):
                walk(v, f"{where}[{k!r}]", out)
        return
    if isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            walk(v, f"{where}[{i}]", out)
        return
    if type(value).__name__ == "Budget":
        walk(value.total, ".total", out)
        walk(value.terms, ".terms", out)
        walk(value.frequency_hz, ".frequency_hz", out)


def main():
    code = sys.argv[1]
    scope = {"__name__": "__case__"}
    try:
        exec(compile(code, "<case>", "exec"), scope)
    except BaseException as e:  # noqa: BLE001 - every failure is reported the same way
        message = f"{type(e).__name__}: {e}".replace("\n", " | ")
        sys.stderr.write(message[:2000] + "\n")
        sys.exit(2)
    found = []
    walk(scope.get("result"), "", found)
    for line in found:
        print(line)
    print("ok")


if __name__ == "__main__":
    main()
