#!/usr/bin/env python3
"""The README's noise-budget figure (plots/budget.png) drawn with matplotlib from the Python API.

    pip install ./python matplotlib
    python examples/budget_matplotlib.py [OUT.png]      (default: budget_matplotlib.png)

The same budget as the quick start's
`tiltnoise budget --tilt tilt_data/lab_tilt_24h.h5 --nperseg 4096 --segment-duration 14400`:
one log-log panel of one-sided ASDs per observable (X, phi, phi_a), with the styles of the
command line's figure: total thick black, tilt blue, each tilt axis alone dashed, readout
grey, the 10-90 % band of the tilt ASD over the 4-hour segments shaded with its median.
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import tiltnoise  # noqa: E402

REPO = Path(__file__).resolve().parents[1]
TITLES = {
    "X": "X: test-mass displacement along x",
    "phi": "φ: test-mass torsion",
    "phi_a": "φₐ: crossbar torsion",
}
AXIS_COLOURS = {"theta_t": "#009E73", "eta_t": "#D55E00", "phi_t": "#CC79A7"}


def draw(ax, b, obs):
    f, terms = b.freq_hz, b.terms[obs]
    hours = b.segment_duration_s / 3600
    ax.loglog(f, b.total[obs], color="black", lw=3.5, label="total")
    ax.loglog(f, terms["tilt"], color="#0072B2", lw=1.8, label="tilt")
    zero = []
    for name, asd in terms.items():
        if name.startswith("tilt.") and not np.any(asd):
            zero.append(name[len("tilt."):])
        elif name.startswith("tilt."):
            axis = name[len("tilt."):]
            ax.loglog(f, asd, "--", color=AXIS_COLOURS[axis], lw=1.8, label=f"tilt, {axis} alone")
    if "readout" in terms:
        ax.loglog(f, terms["readout"], color="grey", lw=2,
                  label=f"readout, {b.readout[obs] * 1e9:g} nm/√Hz")
    band = b.segment_bands.get(obs)
    if band:
        ax.loglog(f, band["median"], color="#0072B2", lw=0.8,
                  label=f"tilt, per {hours:g} h segment median")
        ax.fill_between(f, band["lower"], band["upper"], color="#0072B2", alpha=0.25, lw=0,
                        label=f"tilt, per {hours:g} h segment "
                              f"{band['lower_pct']:g}–{band['upper_pct']:g} %")
    for axis in zero:
        ax.plot([], [], " ", label=f"{axis} alone: identically 0")
    top = b.total[obs].max()
    ax.set_ylim(top * 1e-8, top * 3)
    ax.set_xlim(f[0], f[-1])
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel(f"ASD of {obs} ({b.units[obs].replace('sqrt(Hz)', '√Hz')})")
    ax.set_title(TITLES.get(obs, obs))
    ax.grid(True, which="both", color="0.9")
    ax.legend(loc="upper left", fontsize=8)


def caption(b):
    s, i = b.source, b.input
    return "\n\n".join([
        f"Input: {Path(i['path']).name} ({i['format']} {i['kind']}, {i['quantity']}; "
        f"{i['axis_map']}), start {i['start_time']}.",
        f"Tilt ({', '.join(b.axes)}): Welch estimate at {s['sample_rate_hz']:g} Hz, "
        f"{s['n_welch_segments']} segments of {s['segment_len']} samples, overlap "
        f"{s['overlap']}, {s['averaging']} averaging; {s['n_samples']} samples.",
        "Readout noise (white, assumed): "
        + ", ".join(f"{o} {a:g} {b.units[o]}" for o, a in b.readout.items()) + ".",
        "All curves are one-sided ASDs (√PSD); total: quadrature sum of tilt and readout.",
    ])


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "budget_matplotlib.png")
    b = tiltnoise.budget_from_file(REPO / "tilt_data" / "lab_tilt_24h.h5",
                                   nperseg=4096, segment_duration=14400)
    fig, axes = plt.subplots(2, 2, figsize=(14, 11), constrained_layout=True)
    for ax, obs in zip(axes.flat, b.observables):
        draw(ax, b, obs)
    axes.flat[3].axis("off")
    axes.flat[3].text(0, 0.95, caption(b), va="top", wrap=True, fontsize=10)
    fig.suptitle("Tilt noise budget: one-sided amplitude spectral densities", fontsize=16)
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
