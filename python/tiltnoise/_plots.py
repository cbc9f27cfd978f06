"""Figures of results with matplotlib (optional): Budget.plot, Simulation.plot,
Subtraction.plot, TransferFunction.plot, Coherence.plot, MonteCarlo.plot. The command line's own figures are written by ``save("x.png")``."""

import numpy as np


def _pyplot(what):
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise ImportError(
            f"{what} needs matplotlib, which is not installed: pip install matplotlib ({e})"
        ) from e
    return plt


def budget_plot(budget, observables=None):
    """One log-log panel of ASDs per observable: the total thick black, each term that is not
    zero everywhere (a term's per-axis or per-element breakdown dashed)."""
    plt = _pyplot("Budget.plot()")
    names = list(budget.observables) if observables is None else list(observables)
    for o in names:
        if o not in budget.observables:
            raise KeyError(f"observable {o!r} is not in the budget; it has "
                           f"{', '.join(budget.observables)}")
    fig, axes = plt.subplots(len(names), 1, figsize=(8, 3.4 * len(names)), sharex=True,
                             squeeze=False)
    f = budget.frequency_hz
    for ax, o in zip(axes[:, 0], names):
        ax.loglog(f, budget.total[o], color="black", lw=2.5, label="total")
        for term, asd in budget.terms[o].items():
            if np.any(asd > 0):
                ax.loglog(f, asd, lw=1.2, ls="--" if "." in term else "-", label=term)
        ax.set_ylabel(f"{o} ASD ({budget.units[o]})")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8, ncol=2)
    axes[-1, 0].set_xlabel("frequency (Hz)")
    fig.suptitle("noise budget (one-sided ASD)")
    fig.tight_layout()
    return fig


# The curves of Subtraction.asd as the command line's figure draws them: label, colour, style.
_SUBTRACTION_CURVES = (
    ("measured", "measured", "tab:blue", "-"),
    ("predicted", "predicted tilt part", "tab:orange", "--"),
    ("cleaned", "cleaned", "black", "-"),
    ("wiener", "Wiener residual", "tab:green", "-."),
    ("coherence_limit", "coherence limit", "tab:gray", ":"),
    ("witness_limited", "witness-noise limit", "tab:purple", ":"),
)


def subtraction_plot(sub):
    """One log-log panel of held-out ASDs per observable: measured, the predicted tilt part,
    cleaned, the Wiener residual, the coherence and witness-noise limits (each drawn where it
    is not zero everywhere), the readout and the report band."""
    plt = _pyplot("Subtraction.plot()")
    names = sub.observables
    fig, axes = plt.subplots(len(names), 1, figsize=(8, 3.4 * len(names)), sharex=True,
                             squeeze=False)
    f = sub.frequency_hz[1:]
    readout = {r["observable"]: r["readout_asd"] for r in sub.report["residuals"]}
    band = sub.report_band_hz
    for ax, o in zip(axes[:, 0], names):
        curves = sub.asd[o]
        for key, label, color, style in _SUBTRACTION_CURVES:
            asd = curves[key][1:]
            if np.any(asd > 0):
                ax.loglog(f, asd, color=color, ls=style, lw=2.0 if key == "cleaned" else 1.2,
                          label=label)
        if readout.get(o):
            ax.axhline(readout[o], color="tab:red", lw=1.0, ls="--", label="readout")
        if band is not None:
            for edge in band:
                ax.axvline(edge, color="grey", lw=0.8, ls=":")
        ax.set_ylabel(f"{o} ASD ({sub.units[o]}/sqrt(Hz))")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8, ncol=2)
    axes[-1, 0].set_xlabel("frequency (Hz); dotted: the report band")
    fig.suptitle("tilt subtraction, held-out stretch (one-sided ASD)")
    fig.tight_layout()
    return fig


def simulation_plot(sim):
    """The observables' ASDs, log-log, displacements and angles in two panels, the modes as
    dotted vertical lines (above Nyquist, none)."""
    plt = _pyplot("Simulation.plot()")
    fig, axes = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    f = sim.frequency_hz
    for ax, unit, names in ((axes[0], "m", ("X", "Y", "Z")),
                            (axes[1], "rad", ("theta", "eta", "phi", "phi_a"))):
        for o in names:
            asd = sim.asd[o]
            if np.any(asd[1:] > 0):
                ax.loglog(f[1:], asd[1:], lw=1.2, label=o)
        for k, fk in sim.modes_hz:
            if fk <= f[-1]:
                ax.axvline(fk, color="grey", ls=":", lw=0.8)
        ax.set_ylabel(f"ASD ({unit}/sqrt(Hz))")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8, ncol=4)
    axes[1].set_xlabel("frequency (Hz); dotted: the modes")
    fig.suptitle(f"simulated free motion: {sim.n_samples} samples at {sim.dt_s} s")
    fig.tight_layout()
    return fig


def transfer_plot(tf):
    """Bode plot of every ratio of a TransferFunction."""
    plt = _pyplot("TransferFunction.plot()")
    fig, (mag, phase) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    f = tf.freq_hz
    for (o, i), unit in tf.units.items():
        h = tf[o, i]
        (line,) = mag.loglog(f, np.abs(h), lw=1.2, label=f"{o}/{i} ({unit})")
        phase.semilogx(f, np.degrees(np.angle(h)), lw=1.0, color=line.get_color())
    mag.set_ylabel("|H|")
    mag.grid(True, which="both", alpha=0.3)
    mag.legend(fontsize=8, ncol=2)
    phase.set_ylabel("phase (deg), exp(+i w t)")
    phase.set_yticks(range(-180, 181, 90))
    phase.grid(True, which="both", alpha=0.3)
    phase.set_xlabel("frequency (Hz)")
    fig.tight_layout()
    return fig


def coherence_plot(coh):
    """Per observable, two panels: the ordinary coherence with each axis and the multiple
    coherence against their noise thresholds; |H| measured (with its confidence band) and the
    model's, log-log."""
    plt = _pyplot("Coherence.plot()")
    names = list(coh.observables)
    fig, axes = plt.subplots(len(names), 2, figsize=(12, 3.6 * len(names)), sharex=True,
                             squeeze=False)
    f = coh.frequency_hz
    gamma, multiple = coh.coherence, coh.multiple_coherence
    measured, radius, model = coh.transfer, coh.transfer_radius, coh.model
    for (left, right), o in zip(axes, names):
        for a in coh.axes:
            (line,) = left.semilogx(f, gamma[o][a], lw=1.0, label=f"{a}")
            h, r = np.abs(measured[o][a]), radius[o][a]
            right.loglog(f, h, lw=1.0, color=line.get_color(), label=f"{a} measured")
            lower = np.where(h - r > 0, h - r, np.nan)
            right.fill_between(f, lower, h + r, color=line.get_color(), alpha=0.2, lw=0)
            m = np.abs(model[o][a])
            if np.any(m > 0):
                right.loglog(f, m, lw=1.4, ls="--", color=line.get_color(), label=f"{a} model")
        left.semilogx(f, multiple[o], color="black", lw=1.4, label="multiple")
        left.axhline(coh.coherence_threshold, color="grey", ls=":", lw=0.9,
                     label=f"threshold ({coh.confidence:.0%})")
        left.axhline(coh.multiple_coherence_threshold, color="black", ls=":", lw=0.9)
        left.set_ylim(0, 1)
        left.set_ylabel(f"{o}: coherence")
        right.set_ylabel(f"|H| ({coh.units[o]})")
        for ax in (left, right):
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=7, ncol=2)
    for ax in axes[-1]:
        ax.set_xlabel("frequency (Hz)")
    fig.suptitle("coherence with the tilt axes and measured transfer functions")
    fig.tight_layout()
    return fig


def monte_carlo_plot(mc):
    """One histogram per mode of the accepted draws, the nominal frequency dashed black and
    the mean orange, as the command line's figure marks them."""
    plt = _pyplot("MonteCarlo.plot()")
    fig, axes = plt.subplots(4, 2, figsize=(9, 10), squeeze=False)
    f = mc.freqs_hz
    for k, ax in enumerate(axes.flat):
        ax.hist(f[:, k], bins=40, color="tab:blue", alpha=0.7)
        ax.axvline(mc.nominal_hz[k], color="black", ls="--", label="nominal")
        ax.axvline(mc.mean_hz[k], color="tab:orange", label="mean")
        ax.set_xlabel(f"nu_{k + 1} (Hz)")
        if k % 2 == 0:
            ax.set_ylabel("draws")
        # The low modes' frequencies in mHz would crowd their tick labels: few, scientific.
        ax.locator_params(axis="x", nbins=5)
        ax.ticklabel_format(axis="x", style="sci", scilimits=(-2, 3))
        ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(f"Monte Carlo of the normal modes: {mc.samples} draws, "
                 f"{mc.rejected} rejected, seed {mc.seed}")
    fig.tight_layout()
    return fig
