#!/usr/bin/env python3
"""Expected tilt ASD levels of published noise models at 1, 2, 5 and 10 mHz.

Run from anywhere:  python3 scripts/reference/noise_model_levels.py

Reads (never copies) the tables in ../shared/tilt_data/brotzer2023_rlnm/ and the project's own
tilt_data/peterson1993_coefficients.csv, and writes noise_model_levels.json next to this script:
for each model the acceleration PSD interpolated log-log (linear in dB against log10 f) at the
target frequencies and the tilt-equivalent ASD sqrt(PSD)/g in rad/sqrt(Hz), g = 9.80665 m/s^2.
"""

import csv
import hashlib
import json
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
SHARED_REL = "../shared/tilt_data/brotzer2023_rlnm"
GSN_REL = f"{SHARED_REL}/GSN_noise_model.csv"
RLNM_REL = f"{SHARED_REL}/RLNM_model_data.csv"
PETERSON_REL = "tilt_data/peterson1993_coefficients.csv"
OUT_JSON = os.path.join(HERE, "noise_model_levels.json")
G = 9.80665
FREQS_HZ = [1e-3, 2e-3, 5e-3, 1e-2]


def path(rel):
    return os.path.normpath(os.path.join(REPO, rel))


def sha256(rel):
    with open(path(rel), "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def read_csv(rel):
    with open(path(rel), newline="") as fh:
        return list(csv.DictReader(ln for ln in fh if not ln.startswith("#")))


def interp_db(freq_hz, db, targets):
    """dB values interpolated linearly in log10(f) (= log-log in PSD and ASD)."""
    x = np.log10(np.asarray(freq_hz, dtype=float))
    order = np.argsort(x)
    x, y = x[order], np.asarray(db, dtype=float)[order]
    t = np.log10(np.asarray(targets, dtype=float))
    assert np.all((t >= x[0]) & (t <= x[-1])), "target outside the table"
    return np.interp(t, x, y)


def entry(source, column, conversion, db):
    psd = 10.0 ** (np.asarray(db) / 10.0)
    return {
        "source": source,
        "column": column,
        "conversion": conversion,
        "accel_psd_db": [float(v) for v in db],
        "accel_psd_m2_s4_per_hz": psd.tolist(),
        "tilt_asd_rad_per_rthz": (np.sqrt(psd) / G).tolist(),
    }


def peterson_db(rows, model, freq_hz):
    """Exact Peterson (1993) value A + B log10(P) from the project's coefficient table."""
    out = []
    for f in freq_hz:
        p = 1.0 / f
        band = [r for r in rows if r["model"] == model and float(r["period_min_s"]) <= p < float(r["period_max_s"])]
        assert len(band) == 1
        out.append(float(band[0]["a_db"]) + float(band[0]["b_db"]) * math.log10(p))
    return out


def main():
    gsn = read_csv(GSN_REL)
    rl = read_csv(RLNM_REL)
    pet = read_csv(PETERSON_REL)
    f_gsn = [1.0 / float(r["period"]) for r in gsn]
    f_rl = [float(r["frequency"]) for r in rl]

    def rl_db(col):
        return interp_db(f_rl, [10.0 * math.log10(float(r[col])) for r in rl], FREQS_HZ)

    models = {
        "gsn_min_h": entry(GSN_REL, "minH", "PSD = 10**(minH/10); tilt ASD = sqrt(PSD)/g",
                           interp_db(f_gsn, [float(r["minH"]) for r in gsn], FREQS_HZ)),
        "nhnm": entry(RLNM_REL, "nhnm_acc", "PSD = nhnm_acc; tilt ASD = sqrt(PSD)/g", rl_db("nhnm_acc")),
        "nlnm": entry(RLNM_REL, "nlnm_acc", "PSD = nlnm_acc; tilt ASD = sqrt(PSD)/g", rl_db("nlnm_acc")),
        "peterson_nhnm_exact": entry(PETERSON_REL, "NHNM a_db + b_db log10(P)", "exact formula, no interpolation",
                                     peterson_db(pet, "NHNM", FREQS_HZ)),
        "peterson_nlnm_exact": entry(PETERSON_REL, "NLNM a_db + b_db log10(P)", "exact formula, no interpolation",
                                     peterson_db(pet, "NLNM", FREQS_HZ)),
    }
    doc = {
        "schema": "tiltnoise.reference.noise_model_levels",
        "schema_version": 1,
        "generator": {"script": "scripts/reference/noise_model_levels.py", "python": sys.version.split()[0],
                      "numpy": np.__version__},
        "g_m_per_s2": G,
        "interpolation": "linear in dB against log10(frequency) between table rows (log-log in PSD/ASD)",
        "paths_relative_to": "repository root",
        "inputs_sha256": {GSN_REL: sha256(GSN_REL), RLNM_REL: sha256(RLNM_REL), PETERSON_REL: sha256(PETERSON_REL)},
        "freqs_hz": FREQS_HZ,
        "models": models,
    }
    with open(OUT_JSON, "w") as fh:
        json.dump(doc, fh, indent=1)
        fh.write("\n")
    print(f"wrote {OUT_JSON}")
    for name, m in models.items():
        print(f"  {name:20s} " + "  ".join(
            f"{f * 1e3:g} mHz: {a:.3g}" for f, a in zip(FREQS_HZ, m["tilt_asd_rad_per_rthz"])) + " rad/sqrt(Hz)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
