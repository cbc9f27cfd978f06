#!/usr/bin/env python3
"""The visibility map of docs/asymmetry.md: for each [asymmetry] offset of 1 mm, the channels in
which a mode appears that the symmetric pendulum keeps exactly dark, with the signed ratio to the
mode's reference observable of the same unit, as `tiltnoise modes --format json` computes it.

Usage: scripts/docs/visibility_map.py [path/to/tiltnoise]   (default: target/release/tiltnoise)
Prints a Markdown table. Leakage is linear in an offset along x (tests/it/as_built.rs), so the
ratios are per mm of offset.
"""
import json
import subprocess
import sys

BIN = sys.argv[1] if len(sys.argv) > 1 else "target/release/tiltnoise"
OBS = ["X", "Y", "Z", "theta", "eta", "phi", "phi_a"]
KEYS = [
    "crossbar_com_x_m",
    "crossbar_com_y_m",
    "tm_com_x_m",
    "tm_com_y_m",
    "lower_attachment_x_m",
    "lower_attachment_y_m",
]
THRESHOLD = 1e-6  # a ratio below it is not listed (a peak 120 dB down)


def modes(*sets):
    args = [BIN]
    for s in sets:
        args += ["--set", s]
    out = subprocess.run(args + ["modes", "--format", "json"], check=True, capture_output=True)
    return {m["index"]: m for m in json.loads(out.stdout)["modes"]}


def main():
    symmetric = modes()
    print("| offset (1 mm) | mode | newly visible (signed ratio to the symmetric mode's reference) | relative frequency shift |")
    print("|---|---|---|---|")
    for key in KEYS:
        built = modes(f"asymmetry.{key}=1e-3")
        for k in range(1, 9):
            lit = []
            amp = built[k]["observable_amplitude"]
            for o in OBS:
                before, after = symmetric[k]["ratio"][o], built[k]["ratio"][o]
                if before == 0.0 and abs(after) >= THRESHOLD:
                    # Against the symmetric mode's reference of the same unit, which stays the
                    # same channel as the offset grows (the built mode's own may change).
                    unit = OBS[:3] if o in OBS[:3] else OBS[3:]
                    ref = next(r for r in unit if symmetric[k]["ratio"][r] == 1.0)
                    lit.append(f"{o}/{ref} {amp[o] / amp[ref]:+.2e}")
            if lit:
                df = built[k]["frequency_hz"] / symmetric[k]["frequency_hz"] - 1.0
                print(f"| `{key}` | nu_{k} | {', '.join(lit)} | {df:+.1e} |")
        if not any(
            symmetric[k]["ratio"][o] == 0.0 and abs(built[k]["ratio"][o]) >= THRESHOLD
            for k in range(1, 9)
            for o in OBS
        ):
            print(f"| `{key}` | - | none (the mirror plane x = 0 holds) | |")


if __name__ == "__main__":
    main()
