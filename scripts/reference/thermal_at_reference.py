#!/usr/bin/env python3
"""Independent reference for the thermal terms of the budget summary at chosen frequencies.

Run from anywhere:  python3 scripts/reference/thermal_at_reference.py

The thermal noise of X, phi and phi_a of examples/damped.toml at exactly 1, 2 and 5 mHz (the
values `tiltnoise budget --at` must print; a log-log interpolation between Welch bins misses
them by up to 68 % next to the torsion modes). Nothing here comes from the Rust code: the model
is tilt_budget_reference.py's (the paper's Appendix A in mpmath, 40 digits), the damping and the
fluctuation-dissipation theorem are those of docs/damping.md:

* structural loss: every elastic element k -> k (1 + i phi); torsion and bouncing on phi_a,
  phi_b, delta_a, delta_b; swing of fibre a on theta_a, eta_a with the gravity stiffness
  k_ga = g (m_a (Z + Z_a) + m_b Z), of fibre b on the test mass's absolute angles
  theta_a + theta_b, eta_a + eta_b with k_gb = m_b g Z_b, each with phi = bending / dilution;
* thermal PSD of an observable with observation row c, one-sided:
  S = 4 k_B T / w * z^T Im(K_c) conj(z),  (K_c - w^2 M) z = c^T  (K_c symmetric),
  which is sum_e c H S_Q,e H^H c^T with S_Q,e = 4 k_B T Im(K_e) / w.

Writes thermal_at_reference.json next to this script.
"""

import json
import os
import sys
import tomllib

import mpmath as mp

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import tilt_budget_reference as ref  # noqa: E402  (the model of the paper, mpmath)

REPO = ref.REPO
PARAMS_REL = "examples/damped.toml"
OUT_JSON = os.path.join(HERE, "thermal_at_reference.json")
FREQS_HZ = ("1e-3", "2e-3", "5e-3")
K_B = mp.mpf("1.380649e-23")  # J/K, exact (SI 2019)


def swing_loss(tp, model):
    """Im(K) of the swing of both fibres (docs/damping.md), 8x8."""
    TA, EA, TB, EB = ref.TA, ref.EA, ref.TB, ref.EB
    m_a, m_b = ref.mpf(tp["mass"]["m_a_kg"]), ref.mpf(tp["mass"]["m_b_kg"])
    L = tp["length"]
    Z, Z_a, Z_b = (ref.mpf(L[k]) for k in ("z_m", "z_a_m", "z_b_m"))
    g = ref.mpf(tp["environment"]["g_m_per_s2"])
    loss = {k: ref.mpf(v) for k, v in tp["loss"].items()}
    k_ga = g * (m_a * (Z + Z_a) + m_b * Z)
    k_gb = m_b * g * Z_b
    phi_a = loss["bending_a_rad"] / loss["dilution_a"]
    phi_b = loss["bending_b_rad"] / loss["dilution_b"]
    im = mp.matrix(8, 8)
    for a in (TA, EA):
        im[a, a] += phi_a * k_ga
    for a, b in ((TA, TB), (EA, EB)):  # u = e_a + e_b: u u^T
        for r in (a, b):
            for c in (a, b):
                im[r, c] += phi_b * k_gb
    return im


def thermal_psd(tp, model, f_hz):
    """One-sided thermal PSD of X, phi, phi_a at f_hz (m^2/Hz, rad^2/Hz)."""
    T = ref.mpf(tp["environment"]["temperature_k"])
    w = 2 * mp.pi * mp.mpf(f_hz)
    swing = swing_loss(tp, model)
    # K_c = K_gravity + K_elastic (torsion and bouncing losses in it) + i Im(K_swing)
    A = model["Kg"] + model["Ke"] - w**2 * model["M"]
    im_k = mp.matrix(8, 8)
    for r in range(8):
        for c in range(8):
            A[r, c] += mp.mpc(0, swing[r, c])
            im_k[r, c] = mp.im(model["Ke"][r, c]) + swing[r, c]
    out = []
    for o in range(3):
        c = mp.matrix([model["C"][o, k] for k in range(8)])
        z = mp.lu_solve(A, c)
        acc = mp.mpc(0)
        for r in range(8):
            for s in range(8):
                acc += z[r] * im_k[r, s] * mp.conj(z[s])
        assert abs(mp.im(acc)) <= mp.mpf(10) ** -30 * abs(acc)
        out.append(4 * K_B * T / w * mp.re(acc))
    return out


def main():
    with open(os.path.join(REPO, PARAMS_REL), "rb") as fh:
        tp = tomllib.load(fh)
    assert all(float(v) == 0.0 for v in tp["viscous"].values()), "structural damping only"
    model = ref.build_model(tp)
    rows = []
    for f in FREQS_HZ:
        psd = thermal_psd(tp, model, f)
        rows.append({"freq_hz": float(f), **{o: float(p) for o, p in zip(ref.OUTPUTS, psd)}})
        print(f"{float(f) * 1e3:g} mHz: " + ", ".join(
            f"{o} thermal ASD {float(mp.sqrt(p)):.4e}" for o, p in zip(ref.OUTPUTS, psd)))
    doc = {
        "schema": "tiltnoise.reference.thermal_at",
        "schema_version": 1,
        "generator": {"script": "scripts/reference/thermal_at_reference.py",
                      "python": sys.version.split()[0], "mpmath": mp.__version__,
                      "mp_dps": mp.mp.dps},
        "parameters": PARAMS_REL,
        "conventions": "one-sided thermal PSD of X (m^2/Hz), phi, phi_a (rad^2/Hz), sum over "
        "every dissipative element, exactly at freq_hz; k_B = 1.380649e-23 J/K",
        "thermal_psd": rows,
    }
    with open(OUT_JSON, "w") as fh:
        json.dump(doc, fh, indent=1)
        fh.write("\n")
    print(f"wrote {OUT_JSON}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
