"""Budget.to_gwpy(): the budget's ASDs as gwpy FrequencySeries (gwpy is optional)."""

import numpy as np


def _unit(unit):
    """``m/sqrt(Hz)`` -> ``m / Hz(1/2)``, as astropy writes it."""
    return unit.replace("/sqrt(Hz)", " / Hz(1/2)")


def to_gwpy(budget):
    """``{observable: {term: FrequencySeries}}``, ``total`` included (see Budget.to_gwpy)."""
    try:
        from gwpy.frequencyseries import FrequencySeries
    except ImportError as e:
        raise ImportError(
            "Budget.to_gwpy() needs gwpy, which is not installed: pip install gwpy "
            f"(or pip install './python[gwpy]'); the arrays are in Budget.terms ({e})"
        ) from e
    f = budget.frequency_hz
    # A Welch grid is regular (f0 = df, no DC): give gwpy f0 and df, which its methods use;
    # interpolated spectra sit on a log grid and keep their frequencies.
    df = np.diff(f)
    regular = len(f) > 1 and np.allclose(df, df[0], rtol=1e-9, atol=0.0)
    where = {"f0": f[0], "df": df[0]} if regular else {"frequencies": f}
    out = {}
    for obs in budget.observables:
        unit = _unit(budget.units[obs])
        curves = dict(budget.terms[obs])
        curves["total"] = budget.total[obs]
        out[obs] = {
            name: FrequencySeries(asd, unit=unit, name=f"{obs} {name}", **where)
            for name, asd in curves.items()
        }
    return out
