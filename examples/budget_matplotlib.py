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
# The command line's symbols (tiltnoise-plot's labels).
SYMBOLS = {"X": "X", "phi": "φ", "phi_a": "φₐ", "theta_t": "θₜ", "eta_t": "ηₜ", "phi_t": "φₜ"}
TITLES = {
    "X": "X: test-mass displacement along x",
    "phi": "φ: test-mass torsion",
    "phi_a": "φₐ: crossbar torsion",
}
AXIS_COLOURS = {"theta_t": "#009E73", "eta_t": "#D55E00", "phi_t": "#CC79A7"}
TILT_COLOUR = "#0072B2"
MAX_DECADES = 8  # the y axis spans whole decades, at most 8 below the top, as the CLI's


def si_asd(value, unit):
    """`9 nm/√Hz`: an ASD with an SI prefix."""
    for exponent, prefix in ((-18, "a"), (-15, "f"), (-12, "p"), (-9, "n"), (-6, "µ"),
                             (-3, "m"), (0, "")):
        if value < 10.0 ** (exponent + 3) * (1 - 1e-9):
            return f"{value / 10.0 ** exponent:.4g} {prefix}{unit}/√Hz"
    return f"{value:.4g} {unit}/√Hz"


def duration(seconds):
    """`4 h`, `1 d`, `4096 s`."""
    for size, unit in ((86400, "d"), (3600, "h")):
        if seconds >= size and abs(seconds / size - round(seconds / size)) < 1e-9:
            return f"{seconds / size:.4g} {unit}"
    return f"{seconds:.4g} s"


def draw(ax, b, obs):
    f, terms = b.frequency_hz, b.terms[obs]
    hours = b.segment_duration_s / 3600
    curves = [b.total[obs], terms["tilt"]]
    ax.loglog(f, b.total[obs], color="black", lw=3.5, label="total")
    ax.loglog(f, terms["tilt"], color=TILT_COLOUR, lw=1.8, label="tilt")
    zero = []
    for name, asd in terms.items():
        if name.startswith("tilt.") and not np.any(asd):
            zero.append(name[len("tilt."):])
        elif name.startswith("tilt."):
            axis = name[len("tilt."):]
            ax.loglog(f, asd, "--", color=AXIS_COLOURS[axis], lw=1.8,
                      label=f"tilt, {SYMBOLS[axis]} alone")
            curves.append(asd)
    if "readout" in terms:
        unit = b.units[obs].split("/")[0]
        ax.loglog(f, terms["readout"], color="grey", lw=2,
                  label=f"readout, {si_asd(b.readout[obs], unit)}")
        curves.append(terms["readout"])
    band = b.segment_bands.get(obs)
    if band:
        ax.loglog(f, band["median"], color=TILT_COLOUR, lw=0.8,
                  label=f"tilt, per {hours:g} h segment median")
        ax.fill_between(f, band["lower"], band["upper"], color=TILT_COLOUR, alpha=0.25, lw=0,
                        label=f"tilt, per {hours:g} h segment "
                              f"{band['lower_pct']:g}–{band['upper_pct']:g} %")
        curves += [band["lower"], band["upper"]]
    for axis in zero:
        ax.plot([], [], " ", label=f"{SYMBOLS[axis]} alone: identically 0")
    values = np.concatenate(curves)
    values = values[values > 0]
    top = np.ceil(np.log10(values.max()))
    bottom = max(np.floor(np.log10(values.min())), top - MAX_DECADES)
    ax.set_ylim(10.0 ** bottom, 10.0 ** top)
    ax.set_xlim(f[0], f[-1])
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel(f"ASD of {SYMBOLS[obs]} ({b.units[obs].replace('sqrt(Hz)', '√Hz')})")
    ax.set_title(TITLES.get(obs, obs))
    ax.grid(True, which="both", color="0.9")
    ax.legend(loc="upper left", fontsize=9)


def caption(b):
    s, i = b.source, b.input
    fs = s["sample_rate_hz"]
    axes = ", ".join(SYMBOLS[a] for a in b.axes)
    band = next(iter(b.segment_bands.values()))
    with_readout = [f"{SYMBOLS[o]} {si_asd(a, b.units[o].split('/')[0])}"
                    for o, a in b.readout.items()]
    without = [SYMBOLS[o] for o in b.observables if o not in b.readout]
    return "\n\n".join([
        f"Input: {Path(i['path']).name} ({i['format']} {i['kind']}, {i['quantity']}; "
        f"{i['axis_map']}), start {i['start_time']}.",
        f"Tilt ({axes}): Welch estimate at {fs:g} Hz, {s['n_welch_segments']} segments of "
        f"{s['segment_len']} samples ({duration(s['segment_len'] / fs)}), overlap "
        f"{s['overlap']}, {s['averaging']} averaging; {s['n_samples']} samples "
        f"({duration(s['n_samples'] / fs)}).",
        f"Band: {band['lower_pct']:g}th to {band['upper_pct']:g}th percentile of the tilt ASD "
        f"over {band['n_segments']} segments of {duration(b.segment_duration_s)}; thin line: "
        "median.",
        "Readout noise (white, assumed): " + ", ".join(with_readout)
        + (f"; none on {', '.join(without)}" if without else "") + ".",
        "All curves are one-sided ASDs (√PSD). tilt: all axes with their cross-spectra; "
        "“alone”: one axis, for diagnosis; total: quadrature sum of tilt and readout.",
    ])


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "budget_matplotlib.png")
    b = tiltnoise.budget_from_file(REPO / "tilt_data" / "lab_tilt_24h.h5",
                                   nperseg=4096, segment_duration=14400)
    fig, axes = plt.subplots(2, 2, figsize=(14, 11), constrained_layout=True)
    for ax, obs in zip(axes.flat, b.observables):
        draw(ax, b, obs)
    axes.flat[3].axis("off")
    axes.flat[3].text(0, 0.95, caption(b), va="top", wrap=True, fontsize=11, linespacing=1.6)
    fig.suptitle("Tilt noise budget: one-sided amplitude spectral densities", fontsize=16)
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
