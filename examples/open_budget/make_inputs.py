#!/usr/bin/env python3
"""Writes the three ASD files of the README's open-budget example (illustrative spectra, not
measurements): a coloured readout of phi, the ASD of a force on the test mass along x, and a
magnetic coupling seen in phi. Each is a one-sided ASD on 1e-5 .. 10 Hz (61 log-spaced points),
wide enough for any budget of the bundled records. Run from anywhere; writes beside itself.

    python3 examples/open_budget/make_inputs.py
"""

from pathlib import Path

HERE = Path(__file__).resolve().parent
FREQS_HZ = [10 ** (-5 + 6 * k / 60) for k in range(61)]


def write(name, column, unit, comment, asd):
    lines = [f"# {comment}", f"# one-sided ASD in {unit}/sqrt(Hz)", f"frequency_hz,{column}"]
    lines += [f"{f:.6e},{asd(f):.6e}" for f in FREQS_HZ]
    (HERE / name).write_text("\n".join(lines) + "\n")


# Readout of the crossbar-test-mass angle: 1 nrad/sqrt(Hz) white, rising as 1/f below 1 mHz.
write("phi_readout.csv", "phi", "rad", "coloured readout of phi (illustrative)",
      lambda f: 1e-9 * (1 + 1e-3 / f))
# Actuation force noise on the test mass along x: 2e-14 N/sqrt(Hz), 1/f below 0.5 mHz.
write("force_asd.csv", "asd", "N", "force noise F_b.x on the test mass (illustrative)",
      lambda f: 2e-14 * (1 + 5e-4 / f))
# A magnetic coupling seen directly in phi: 3e-10 rad/sqrt(Hz) at 1 mHz, falling as 1/f.
write("phi_magnetic.csv", "asd", "rad", "magnetic coupling seen in phi (illustrative)",
      lambda f: 3e-10 * 1e-3 / f)
