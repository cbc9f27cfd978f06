"""Results as gwpy series and pandas frames, with their names and units (gwpy and pandas are
optional: each conversion imports its package and says how to install it when it is missing)."""

import numpy as np


def _need(package, what):
    """The module `package`, or an ImportError naming the pip package and `what` needs it."""
    try:
        if package == "gwpy":
            import gwpy.frequencyseries
            import gwpy.timeseries

            return gwpy
        if package == "pandas":
            import pandas

            return pandas
    except ImportError as e:
        raise ImportError(
            f"{what} needs {package}, which is not installed: pip install {package} (or pip "
            f"install 'tiltnoise[{package}]'); the same values are NumPy arrays on the object "
            f"({e})"
        ) from e
    raise AssertionError(package)


def astropy_unit(unit):
    """A unit as tiltnoise writes it, as astropy reads it: ``m/sqrt(Hz)`` -> ``m / Hz(1/2)``,
    ``rad/(N m)`` stays."""
    return unit.replace("sqrt(Hz)", "Hz(1/2)")


def _where(f):
    """gwpy's description of a frequency axis: f0 and df for a regular grid (a Welch grid, DC
    excluded or not), which gwpy's methods use; the frequencies themselves otherwise (an
    interpolated budget's log grid)."""
    f = np.asarray(f)
    if len(f) > 1:
        df = np.diff(f)
        if np.allclose(df, df[0], rtol=1e-9, atol=0.0):
            return {"f0": f[0], "df": df[0]}
    return {"frequencies": f}


def _budget_curves(budget):
    """``[(observable, term, ASD)]``, each observable's terms then its total."""
    out = []
    for obs in budget.observables:
        out.extend((obs, term, asd) for term, asd in budget.terms[obs].items())
        out.append((obs, "total", budget.total[obs]))
    return out


def _pct(p):
    """A percentile as the CSV's column names write it: 10 -> ``10``, 2.5 -> ``2.5``."""
    return repr(float(p)).removesuffix(".0")


def _band_curves(budget):
    """``[(observable, "TERM.median" / "TERM.pLOW" / "TERM.pHIGH", ASD)]`` of the per-segment
    bands (``segment_duration``), named as the CSV's columns."""
    out = []
    for obs, b in budget.segment_bands.items():
        t = b["term"]
        out += [(obs, f"{t}.median", b["median"]),
                (obs, f"{t}.p{_pct(b['lower_pct'])}", b["lower"]),
                (obs, f"{t}.p{_pct(b['upper_pct'])}", b["upper"])]
    return out


def budget_to_gwpy(budget):
    """``{observable: {term: FrequencySeries}}``, ``total`` included (Budget.to_gwpy)."""
    gwpy = _need("gwpy", "Budget.to_gwpy()")
    where = _where(budget.frequency_hz)
    out = {obs: {} for obs in budget.observables}
    for obs, term, asd in _budget_curves(budget):
        out[obs][term] = gwpy.frequencyseries.FrequencySeries(
            asd, unit=astropy_unit(budget.units[obs]), name=f"{obs}.{term}", **where
        )
    return out


def budget_to_pandas(budget):
    """The ASDs as a DataFrame indexed by frequency_hz, one column per ``OBS.TERM``, and the
    segment bands' ``OBS.TERM.median``, ``OBS.TERM.p10``, ... (Budget.to_pandas): the CSV's
    columns."""
    pd = _need("pandas", "Budget.to_pandas()")
    curves = _budget_curves(budget) + _band_curves(budget)
    df = pd.DataFrame(
        {f"{obs}.{term}": np.array(asd) for obs, term, asd in curves},
        index=pd.Index(np.array(budget.frequency_hz), name="frequency_hz"),
    )
    df.attrs["units"] = {f"{obs}.{term}": budget.units[obs] for obs, term, _ in curves}
    df.attrs["units"]["frequency_hz"] = "Hz"
    return df


def _units(names):
    """Units of observables by name: m for X, Y, Z, rad for the angles."""
    return {n: "m" if n in ("X", "Y", "Z") else "rad" for n in names}


def simulation_to_gwpy(sim):
    """Samples as TimeSeries and ASDs as FrequencySeries (Simulation.to_gwpy)."""
    gwpy = _need("gwpy", "Simulation.to_gwpy()")
    units = _units(sim.observables)
    series = {
        obs: gwpy.timeseries.TimeSeries(x, t0=0.0, dt=sim.dt_s, unit=units[obs], name=obs)
        for obs, x in sim.observables.items()
    }
    where = _where(sim.frequency_hz)
    asd = {
        obs: gwpy.frequencyseries.FrequencySeries(
            a, unit=astropy_unit(f"{units[obs]}/sqrt(Hz)"), name=f"{obs} ASD", **where
        )
        for obs, a in sim.asd.items()
    }
    return {"observables": series, "asd": asd}


def simulation_to_pandas(sim):
    """Samples and ASDs as DataFrames (Simulation.to_pandas)."""
    pd = _need("pandas", "Simulation.to_pandas()")
    units = _units(sim.observables)
    series = pd.DataFrame(dict(sim.observables), index=pd.Index(sim.time_s, name="time_s"))
    series.attrs["units"] = dict(units, time_s="s")
    asd = pd.DataFrame(dict(sim.asd), index=pd.Index(sim.frequency_hz, name="frequency_hz"))
    asd.attrs["units"] = {obs: f"{units[obs]}/sqrt(Hz)" for obs in sim.asd}
    asd.attrs["units"]["frequency_hz"] = "Hz"
    return {"observables": series, "asd": asd}


def transfer_to_gwpy(tf):
    """``{(output, input): FrequencySeries}`` of complex values (TransferFunction.to_gwpy)."""
    gwpy = _need("gwpy", "TransferFunction.to_gwpy()")
    where = _where(tf.freq_hz)
    return {
        (o, i): gwpy.frequencyseries.FrequencySeries(
            tf.values[:, k, j], unit=astropy_unit(tf.units[o, i]), name=f"{o}/{i}", **where
        )
        for k, o in enumerate(tf.outputs)
        for j, i in enumerate(tf.inputs)
    }


def transfer_to_pandas(tf):
    """Complex values as a DataFrame indexed by freq_hz, one column per ``OUTPUT/INPUT``
    (TransferFunction.to_pandas)."""
    pd = _need("pandas", "TransferFunction.to_pandas()")
    cols = {
        f"{o}/{i}": tf.values[:, k, j]
        for k, o in enumerate(tf.outputs)
        for j, i in enumerate(tf.inputs)
    }
    df = pd.DataFrame(cols, index=pd.Index(tf.freq_hz, name="frequency_hz"))
    df.attrs["units"] = {f"{o}/{i}": u for (o, i), u in tf.units.items()}
    df.attrs["units"]["frequency_hz"] = "Hz"
    return df


def _gps(start_time):
    """GPS seconds of an ISO 8601 start time (gwpy's reading), 0 when the records state none."""
    if start_time is None:
        return 0.0
    from gwpy.time import to_gps

    return float(to_gps(start_time))


def subtraction_to_gwpy(sub):
    """Cleaned and predicted series as TimeSeriesDicts, held-out ASDs as FrequencySeries
    (Subtraction.to_gwpy)."""
    gwpy = _need("gwpy", "Subtraction.to_gwpy()")
    t0, dt = _gps(sub.start_time), 1.0 / sub.sample_rate_hz
    out = {}
    for kind, series in (("cleaned", sub.cleaned), ("predicted", sub.predicted)):
        out[kind] = gwpy.timeseries.TimeSeriesDict(
            (obs, gwpy.timeseries.TimeSeries(x, t0=t0, dt=dt, unit=sub.units[obs],
                                             name=f"{obs}.{kind}"))
            for obs, x in series.items()
        )
    where = _where(sub.frequency_hz)
    out["asd"] = {
        obs: {
            curve: gwpy.frequencyseries.FrequencySeries(
                a, unit=astropy_unit(f"{sub.units[obs]}/sqrt(Hz)"), name=f"{obs}.{curve}",
                **where
            )
            for curve, a in curves.items()
        }
        for obs, curves in sub.asd.items()
    }
    return out


def subtraction_to_pandas(sub):
    """Cleaned and predicted series and the held-out ASDs as DataFrames
    (Subtraction.to_pandas)."""
    pd = _need("pandas", "Subtraction.to_pandas()")
    out = {}
    for kind, series in (("cleaned", sub.cleaned), ("predicted", sub.predicted)):
        n = len(next(iter(series.values()))) if series else 0
        df = pd.DataFrame(dict(series),
                          index=pd.Index(np.arange(n) / sub.sample_rate_hz, name="time_s"))
        df.attrs["units"] = dict(sub.units, time_s="s")
        out[kind] = df
    cols = {f"{obs}.{curve}": a for obs, curves in sub.asd.items() for curve, a in curves.items()}
    asd = pd.DataFrame(cols, index=pd.Index(sub.frequency_hz, name="frequency_hz"))
    asd.attrs["units"] = {f"{obs}.{curve}": f"{sub.units[obs]}/sqrt(Hz)"
                          for obs, curves in sub.asd.items() for curve in curves}
    asd.attrs["units"]["frequency_hz"] = "Hz"
    out["asd"] = asd
    return out


def _coherence_columns(coh):
    """``[(key, observable, axis or None, name, values, unit)]`` of a coherence report: per
    observable its PSD and multiple coherence, then per axis the coherence, the measured
    transfer function, its confidence radius and the model's."""
    units = _units(coh.observables)
    per_axis = (("coherence", coh.coherence, ""), ("transfer", coh.transfer, "tf"),
                ("transfer_radius", coh.transfer_radius, "tf"), ("model", coh.model, "tf"))
    out = []
    for obs in coh.observables:
        out.append(("psd", obs, None, f"{obs}.psd", coh.psd[obs], f"{units[obs]}^2/Hz"))
        out.append(("multiple_coherence", obs, None, f"{obs}.multiple_coherence",
                    coh.multiple_coherence[obs], ""))
        for key, values, unit in per_axis:
            for axis, v in values[obs].items():
                out.append((key, obs, axis, f"{obs}.{axis}.{key}", v,
                            coh.units[obs] if unit == "tf" else ""))
    return out


def coherence_to_gwpy(coh):
    """The coherence report as FrequencySeries (Coherence.to_gwpy)."""
    gwpy = _need("gwpy", "Coherence.to_gwpy()")
    where = _where(coh.frequency_hz)
    out = {"coherence": {}, "multiple_coherence": {}, "transfer": {}, "transfer_radius": {},
           "model": {}, "psd": {}}
    for key, obs, axis, name, values, unit in _coherence_columns(coh):
        series = gwpy.frequencyseries.FrequencySeries(
            values, unit=astropy_unit(unit).replace("^2", "**2"), name=name, **where
        )
        if axis is None:
            out[key][obs] = series
        else:
            out[key].setdefault(obs, {})[axis] = series
    return out


def coherence_to_pandas(coh):
    """The coherence report as a DataFrame indexed by frequency_hz (Coherence.to_pandas)."""
    pd = _need("pandas", "Coherence.to_pandas()")
    columns = _coherence_columns(coh)
    df = pd.DataFrame({name: np.array(v) for _, _, _, name, v, _ in columns},
                      index=pd.Index(np.array(coh.frequency_hz), name="frequency_hz"))
    df.attrs["units"] = {name: unit for _, _, _, name, _, unit in columns}
    df.attrs["units"]["frequency_hz"] = "Hz"
    return df
