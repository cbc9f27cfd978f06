"""tiltnoise: noise budgets, coherence, tilt subtraction and the mode model of double torsion
pendulums, from Python.

The 8-degree-of-freedom model of the double torsion pendulum PETER (De Marchi et al., Phys.
Rev. D 87, 122006, 2013) and everything the ``tiltnoise`` command line does with it: the same
Rust library and jobs, the same names (parameter keys, inputs, observables, methods, budget
terms), the same numbers, files and figures, and the same error messages in Python spelling
(``nperseg=`` for ``--nperseg``).

What it offers (command line -> Python):

- ``params`` -> :class:`Params` (Table I, ``set``, ``from_toml``, ``to_toml``);
  ``modes`` -> :meth:`Model.modes`; ``tf`` -> :meth:`Model.transfer` (arrays) and
  :meth:`Model.transfer_function` (a :class:`TransferFunction` with names and units);
  ``methods`` -> :meth:`Model.methods`.
- ``budget`` -> :func:`budget` (arrays in hand) and :func:`budget_from_file` (HDF5, CSV,
  miniSEED, gwpy layouts): a :class:`Budget` of tilt, thermal, readout and user terms.
- ``coherence`` -> :func:`coherence`: a :class:`Coherence` of measured observables with the
  tilt axes, measured transfer functions against the model's.
- ``subtract`` -> :func:`subtract`: a :class:`Subtraction`, the fitted coupling and the cleaned
  record.
- ``simulate`` -> :meth:`Model.simulate` (a :class:`Simulation`); ``visibility`` ->
  :func:`visibility` (:class:`Visibilities`); ``fit`` -> :meth:`Model.fit` (a :class:`Fit`);
  ``mc`` -> :meth:`Model.monte_carlo` (a :class:`MonteCarlo`).
- Welch spectra with scipy's conventions and scaling: :func:`welch`, :func:`csd`.

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

Results carry their frequencies, names and units. Figures and files: ``save("x.png")`` or
``save("x.svg")`` of a budget, coherence, subtraction, simulation or Monte Carlo writes the
command line's figure, byte for byte, and ``save("x.h5")`` (``.csv``, ``.json`` where the
command line writes them) its files; ``plot()`` draws the result with matplotlib. ``summary``
and ``report`` hold the command line's JSON reports; ``to_gwpy()`` and ``to_pandas()`` convert
spectra, transfer functions and series (gwpy, pandas and matplotlib are optional). Every object
pickles (multiprocessing, joblib). Ctrl-C stops any long call with ``KeyboardInterrupt``.

Errors are ``TypeError`` for an argument of the wrong type (``KW=VALUE: expected WHAT, got
TYPE``; a single ``str`` or path is a one-item list), ``ValueError`` (parameters, names,
options, values out of range), ``OSError`` subclasses for files that cannot be read
(``FileNotFoundError``, ``IsADirectoryError``, ``PermissionError``, in every call) and
:class:`InputFileError` (an ``OSError``) for files that are read but not valid.
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
