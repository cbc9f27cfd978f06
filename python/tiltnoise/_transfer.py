"""TransferFunction: transfer functions with their frequencies, names and units."""

import numpy as np


def _fixed(a, dtype):
    """A read-only copy of `a`."""
    a = np.array(a, dtype=dtype)
    a.setflags(write=False)
    return a


def ratio_unit(num, den):
    """``num/den``, the denominator in parentheses when it is a product: ``rad/(N m)``."""
    return f"{num}/({den})" if " " in den else f"{num}/{den}"


class TransferFunction:
    """Transfer functions from inputs to observables on a frequency grid, with their names and
    units (:meth:`Model.transfer_function`).

    ``freq_hz`` (Hz) and ``values``, complex ``H[n_freq, n_outputs, n_inputs]`` for
    ``exp(+i w t)``, are read-only arrays; ``inputs`` and ``outputs`` name the axes;
    ``units[output, input]`` is the unit of each ratio (``m/rad``, ``rad/(N m)``);
    ``tf["X", "eta_t"]`` is one ratio against frequency; ``numpy.asarray(tf)`` is ``values``.
    ``to_gwpy()``, ``to_pandas()`` and ``plot()`` convert and draw it (gwpy, pandas and
    matplotlib are optional). Equal when every value, name and unit is; pickles.
    """

    __slots__ = ("freq_hz", "values", "inputs", "outputs", "input_units", "output_units",
                 "method", "_model", "_rel_tol", "_outputs_given")

    def __init__(self, freq_hz, values, inputs, outputs, input_units, output_units,
                 method="auto", model=None, rel_tol=1e-9, outputs_given=True):
        self.freq_hz = _fixed(np.atleast_1d(freq_hz), np.float64)
        self.values = _fixed(values, np.complex128)
        self.inputs, self.outputs = tuple(inputs), tuple(outputs)
        self.input_units, self.output_units = tuple(input_units), tuple(output_units)
        self.method = method
        # The request, for `save`: the model, the tolerance of `auto`, and whether the
        # observables were named (if not, the figure is the paper's Figure 5).
        self._model, self._rel_tol, self._outputs_given = model, rel_tol, outputs_given
        shape = (len(self.freq_hz), len(self.outputs), len(self.inputs))
        if self.values.shape != shape or len(self.input_units) != len(self.inputs) or len(
                self.output_units) != len(self.outputs):
            raise ValueError(
                f"values: shape {self.values.shape} does not fit (n_freq, n_outputs, n_inputs) "
                f"= {shape}, or the units do not fit the names")

    def _of(self, model, rel_tol, outputs_given):
        """This transfer function, with the request :meth:`save` runs again."""
        self._model, self._rel_tol, self._outputs_given = model, rel_tol, outputs_given
        return self

    def save(self, path, observables=None, phase=False):
        """Writes the transfer functions as the command line's ``tf --save`` does for the same
        request, atomically: ``.h5``/``.hdf5`` (schema ``tiltnoise.tf``, with the parameters and
        modes), ``.csv``, or the figure (``|H|`` per observable, one panel per kind of input)
        as ``.png`` or ``.svg``. ``observables``: the observables the figure draws, each one of
        :attr:`outputs` (the command line's ``--plot-observables``; default every output, or
        ``X``, ``phi``, ``phi_a`` as the paper's Figure 5 when the outputs were not named);
        ``phase``: a phase panel (degrees) beside each magnitude panel (``--phase``). The
        values are computed again by :meth:`Model.transfer_function`'s request through the
        command line's code. Raises ``ValueError`` for another extension or a drawn observable
        not computed, ``OSError`` if it cannot be written or is the parameter file, and
        ``TypeError`` for a transfer function built by hand (without its model). The figure's
        caption names the option that chooses its panels as Python spells it
        (``observables``), so a figure that leaves computed observables out differs from the
        command line's in that word only."""
        if self._model is None:
            raise TypeError("save: this TransferFunction has no model; make it with "
                            "Model.transfer_function")
        if observables is None:
            drawn = self.outputs if self._outputs_given else ("X", "phi", "phi_a")
        elif isinstance(observables, str):
            drawn = [o for o in observables.split(",") if o]
        else:
            drawn = observables
        outputs = list(self.outputs) if self._outputs_given else None
        self._model._save_transfer(path, self.freq_hz, list(self.inputs), outputs, self.method,
                                   self._rel_tol, list(drawn), phase)

    @property
    def units(self):
        """``{(output, input): unit}``."""
        return {
            (o, i): ratio_unit(ou, iu)
            for o, ou in zip(self.outputs, self.output_units)
            for i, iu in zip(self.inputs, self.input_units)
        }

    def __getitem__(self, key):
        """``tf[output, input]``: that ratio against frequency (read-only)."""
        output, input_ = key
        for name, names in (("output", self.outputs), ("input", self.inputs)):
            value = output if name == "output" else input_
            if value not in names:
                raise KeyError(f"{name} {value!r} is not in the transfer function; it has "
                               f"{', '.join(names)}")
        return self.values[:, self.outputs.index(output), self.inputs.index(input_)]

    def __array__(self, dtype=None, copy=None):
        if copy:
            return np.array(self.values, dtype=dtype)
        return np.asarray(self.values, dtype=dtype)

    def __len__(self):
        return len(self.freq_hz)

    def __eq__(self, other):
        if not isinstance(other, TransferFunction):
            return NotImplemented
        return (self.freq_hz.tobytes() == other.freq_hz.tobytes()
                and self.values.tobytes() == other.values.tobytes()
                and self.values.shape == other.values.shape
                and (self.inputs, self.outputs, self.input_units, self.output_units, self.method)
                == (other.inputs, other.outputs, other.input_units, other.output_units,
                    other.method))

    __hash__ = None

    def __reduce__(self):
        return (TransferFunction, (self.freq_hz, self.values, self.inputs, self.outputs,
                                   self.input_units, self.output_units, self.method,
                                   self._model, self._rel_tol, self._outputs_given))

    def __repr__(self):
        f = self.freq_hz
        return (f"TransferFunction({len(f)} frequencies {f.min():.4e}..{f.max():.4e} Hz; "
                f"outputs {', '.join(self.outputs)}; inputs {', '.join(self.inputs)})")

    def to_gwpy(self):
        """``{(output, input): gwpy.frequencyseries.FrequencySeries}`` of complex values, each
        named ``"OUTPUT/INPUT"`` with its unit. Needs gwpy (``pip install gwpy``)."""
        from ._convert import transfer_to_gwpy

        return transfer_to_gwpy(self)

    def to_pandas(self):
        """A complex ``pandas.DataFrame`` indexed by ``frequency_hz``, one column per
        ``"OUTPUT/INPUT"``, units in ``df.attrs["units"]``. Needs pandas."""
        from ._convert import transfer_to_pandas

        return transfer_to_pandas(self)

    def plot(self):
        """Bode plot (magnitude log-log, phase in degrees) of every ratio; a new
        ``matplotlib.figure.Figure``. Needs matplotlib."""
        from ._plots import transfer_plot

        return transfer_plot(self)
