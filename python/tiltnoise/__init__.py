"""tiltnoise: noise budgets for double torsion pendulums, from Python.

The 8-degree-of-freedom model of the double torsion pendulum PETER (De Marchi et al., Phys.
Rev. D 87, 122006, 2013), as the ``tiltnoise`` command line computes it: the same Rust
library, the same names (parameter keys, inputs, observables, methods, budget terms) and the
same error messages.

>>> import numpy as np, tiltnoise
>>> model = tiltnoise.Model(tiltnoise.Params().set("length.h_m", 1.5))
>>> [round(m.frequency_hz, 5) for m in model.modes()][:2]
[0.00131, 0.0022]
>>> h = model.transfer(np.logspace(-5, 2, 1000), inputs="eta_t", outputs=["X", "phi"])
>>> h.shape, h.dtype
((1000, 2, 1), dtype('complex128'))

Conventions: SI units; one-sided spectra (PSD in unit**2/Hz, ASD its square root); complex
amplitudes for ``exp(+i w t)``; the tilt ``(theta_t, eta_t, phi_t)`` is the rotation taking
the floor frame to the inertial frame, so ``X -> -eta_t (Z + Z_b + h_c)`` as ``f -> 0``.

Results carry their frequencies, names and units: ``to_gwpy()`` and ``to_pandas()`` convert
them (gwpy and pandas are optional), ``plot()`` draws them with matplotlib, and ``save("x.png")`` of a budget, a simulation or
a coherence writes the command line's figure. Every object pickles (multiprocessing,
joblib). Ctrl-C stops any long call with ``KeyboardInterrupt``.

Errors are ``ValueError`` (parameters, names, options), ``OSError`` subclasses for files that
cannot be read (``FileNotFoundError``, ...) and :class:`InputFileError` (an ``OSError``) for
files that are read but not valid.
"""

from ._tiltnoise import (
    Budget,
    Coherence,
    Fit,
    InputFileError,
    Mode,
    Model,
    MonteCarlo,
    Params,
    Simulation,
    Subtraction,
    Visibilities,
    __version__,
    budget,
    budget_from_file,
    coherence,
    csd,
    hdf5_version,
    subtract,
    welch,
    visibility,
)
from ._transfer import TransferFunction

__all__ = [
    "Budget",
    "Coherence",
    "Fit",
    "InputFileError",
    "Mode",
    "Model",
    "MonteCarlo",
    "Params",
    "Simulation",
    "Subtraction",
    "TransferFunction",
    "Visibilities",
    "__version__",
    "budget",
    "budget_from_file",
    "coherence",
    "csd",
    "hdf5_version",
    "subtract",
    "welch",
    "visibility",
]
