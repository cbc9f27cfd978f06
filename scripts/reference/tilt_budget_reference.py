#!/usr/bin/env python3
"""Independent reference for the tilt-noise budget: model -> transfer functions -> ROMY budget.

Run from anywhere:  python3 scripts/reference/tilt_budget_reference.py

Nothing here comes from the Rust code. The model is rebuilt from the paper (De Marchi et al.,
Phys. Rev. D 87, 122006 (2013), Appendix A and section IV.B) and the parameters of
crates/tiltnoise-core/src/params/table1.toml, in mpmath with 40 significant digits; the spectral part is
scipy.signal.csd on the real ROMY record in ../shared/tilt_data/ (read, never copied).

Writes romy_budget_reference.json next to this script (floats with repr: full double
precision). Prints the sanity checks and the key numbers. See README.md here.
"""

import hashlib
import json
import math
import os
import sys
import tomllib

import mpmath as mp
import h5py
import numpy as np
import scipy
from scipy import signal

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
PARAMS_TOML = os.path.join(REPO, "crates", "tiltnoise-core", "src", "params", "table1.toml")
ROMY_REL = "../shared/tilt_data/romy_6c_teleseism_20180123/ROMY_gulf_of_alaska_teleseism.csv"
ROMY_CSV = os.path.normpath(os.path.join(REPO, ROMY_REL))
OUT_JSON = os.path.join(HERE, "romy_budget_reference.json")
LAB_H5_REL = "tilt_data/lab_tilt_24h.h5"
LAB_JSON = os.path.join(HERE, "lab_budget_reference.json")

mp.mp.dps = 40

COORDS = ("theta_a", "eta_a", "phi_a", "delta_a", "theta_b", "eta_b", "phi_b", "delta_b")
TA, EA, PA, DA, TB, EB, PB, DB = range(8)
OUTPUTS = ("X", "phi", "phi_a")
INPUTS = ("theta_t", "eta_t")
READOUT_X_ASD = 9e-9  # m/sqrt(Hz), white (paper, section III)
WELCH = dict(window="hann", nperseg=2048, noverlap=1024, detrend="constant", scaling="density", average="mean")


# ----------------------------------------------------------------------------------------------
# Model (mpmath)
# ----------------------------------------------------------------------------------------------
def load_params(path=PARAMS_TOML):
    with open(path, "rb") as fh:
        return tomllib.load(fh)


def mpf(x):
    """The exact binary value of the f64 parameter (what the Rust code sees), as an mpf."""
    return mp.mpf(float(x))


def zeros(r, c):
    return mp.matrix(r, c)


def build_model(tp):
    """M, K_gravity, K_elastic (complex, with loss angles), B (8x12), G0, G2 (8x3), C (3x8)."""
    m_a, m_b = mpf(tp["mass"]["m_a_kg"]), mpf(tp["mass"]["m_b_kg"])
    i = {k: mpf(v) for k, v in tp["inertia"].items()}
    a11, a22, a33, a23 = i["a11_kg_m2"], i["a22_kg_m2"], i["a33_kg_m2"], i["a23_kg_m2"]
    b11, b22, b33 = i["b11_kg_m2"], i["b22_kg_m2"], i["b33_kg_m2"]
    k_a, k_b = mpf(tp["torsion"]["k_a_n_m_per_rad"]), mpf(tp["torsion"]["k_b_n_m_per_rad"])
    ka_e, kb_e = mpf(tp["bouncing"]["kappa_a_n_per_m"]), mpf(tp["bouncing"]["kappa_b_n_per_m"])
    L = tp["length"]
    d, h_c, Z, Z_a, Z_b, h = (mpf(L[k]) for k in ("d_m", "h_c_m", "z_m", "z_a_m", "z_b_m", "h_m"))
    g = mpf(tp["environment"]["g_m_per_s2"])
    loss = {k: mpf(v) for k, v in tp["loss"].items()}

    y_a = d * m_b / m_a
    # Appendix A, eq. (def_I); I^b_22 where the TM turns about its own y axis (eta rows)
    I_a1 = a11 + m_a * ((Z + Z_a) ** 2 + y_a**2)
    I_b1 = b11 + m_b * ((Z + Z_b) ** 2 + d**2)
    I_a2 = a22 + m_a * (Z + Z_a) ** 2
    I_b2 = b22 + m_b * (Z + Z_b) ** 2
    I_a3 = a33 + m_a * y_a**2
    I_b3 = b33 + m_b * d**2
    I_a4 = a23 + m_b * d * (Z_a - Z_b)
    I_b4_th, I_b4_et = b11 + m_b * Z_b**2, b22 + m_b * Z_b**2
    I_b5_th, I_b5_et = b11 + m_b * Z_b * (Z + Z_b), b22 + m_b * Z_b * (Z + Z_b)
    c_1 = m_b * (Z + Z_b) + m_a * (Z + Z_a)

    M = zeros(8, 8)

    def sym(mat, r, c, v):
        mat[r, c] = v
        mat[c, r] = v

    # Appendix A, eq. (EM): inertia terms
    M[TA, TA] = I_a1 + I_b1
    sym(M, TA, TB, I_b5_th)
    sym(M, TA, DB, m_b * d)
    M[EA, EA] = I_a2 + I_b2
    sym(M, EA, PA, I_a4)
    sym(M, EA, EB, I_b5_et)
    M[PA, PA] = I_a3 + I_b3
    sym(M, PA, PB, b33)
    sym(M, PA, EB, -m_b * d * Z_b)
    M[DA, DA] = m_a + m_b
    sym(M, DA, DB, m_b)
    M[TB, TB] = I_b4_th
    M[EB, EB] = I_b4_et
    M[PB, PB] = b33
    M[DB, DB] = m_b

    # gravity stiffness (lossless) and elastic stiffness of the fibres
    Kg = zeros(8, 8)
    Kg[TA, TA] = g * c_1
    sym(Kg, TA, TB, m_b * g * Z_b)
    Kg[TB, TB] = m_b * g * Z_b
    Kg[EA, EA] = g * c_1
    sym(Kg, EA, EB, m_b * g * Z_b)
    Kg[EB, EB] = m_b * g * Z_b
    Ke = zeros(8, 8)
    Ke[PA, PA] = k_a * mp.mpc(1, loss["torsion_a_rad"])
    Ke[PB, PB] = k_b * mp.mpc(1, loss["torsion_b_rad"])
    Ke[DA, DA] = ka_e * mp.mpc(1, loss["bouncing_a_rad"])
    Ke[DB, DB] = kb_e * mp.mpc(1, loss["bouncing_b_rad"])

    # Zeroth-order generalized forces (Appendix A, last display).
    # Columns: F_a (x,y,z), F_b (x,y,z), M_a (x,y,z), M_b (x,y,z).
    FAX, FAY, FAZ, FBX, FBY, FBZ, MAX, MAY, MAZ, MBX, MBY, MBZ = range(12)
    B = zeros(8, 12)
    B[TA, FBY], B[TA, FAY], B[TA, MAX], B[TA, MBX] = Z + Z_b, Z + Z_a, 1, 1
    B[TA, FAZ], B[TA, FBZ] = y_a, -d
    B[EA, FBX], B[EA, FAX], B[EA, MAY], B[EA, MBY] = -(Z + Z_b), -(Z + Z_a), 1, 1
    B[PA, FAX], B[PA, FBX], B[PA, MAZ], B[PA, MBZ] = -y_a, d, 1, 1
    B[DA, FAZ], B[DA, FBZ] = -1, -1
    B[TB, FBY], B[TB, MBX] = Z_b, 1
    B[EB, FBX], B[EB, MBY] = -Z_b, 1
    B[PB, MBZ] = 1
    B[DB, FBZ] = -1

    # Tilt forcing, crate convention: t takes the floor frame to the inertial frame.
    # G0: potential at (theta_a - theta_t, eta_a - eta_t): columns of K_gravity.
    G0 = zeros(8, 3)
    for col, coord in ((0, TA), (1, EA)):
        for r in range(8):
            G0[r, col] = Kg[r, coord]
    # G2: apparent forces/torques per unit t'' (frame angular acceleration w' = -t'').
    I_a = mp.matrix([[a11, 0, 0], [0, a22, a23], [0, a23, a33]])
    I_b = mp.matrix([[b11, 0, 0], [0, b22, 0], [0, 0, b33]])
    r_ga0 = mp.matrix([0, y_a, -(Z + Z_a)])
    r_gb0 = mp.matrix([0, -d, -(Z + Z_b)])
    G2 = zeros(8, 3)
    for j in range(3):
        w = mp.matrix([0, 0, 0])
        w[j] = -1
        r_s = cross(w, mp.matrix([0, 0, h]))
        F_a = -m_a * (r_s + cross(w, r_ga0))
        F_b = -m_b * (r_s + cross(w, r_gb0))
        M_a = -(I_a * w)
        M_b = -(I_b * w)
        f = mp.matrix(list(F_a) + list(F_b) + list(M_a) + list(M_b))
        q = B * f
        for r in range(8):
            G2[r, j] = -q[r]

    # Observation rows: X, phi, phi_a
    C = zeros(3, 8)
    C[0, EA], C[0, EB], C[0, PA] = -(Z + Z_b + h_c), -(h_c + Z_b), d
    C[1, PA], C[1, PB] = 1, 1
    C[2, PA] = 1
    # extra rows used only by the sanity checks: Y, Z, theta, eta
    C_extra = zeros(4, 8)
    C_extra[0, TA], C_extra[0, TB] = Z + Z_b + h_c, h_c + Z_b
    C_extra[1, DA], C_extra[1, DB], C_extra[1, TA] = -1, -1, -d
    C_extra[2, TA], C_extra[2, TB] = 1, 1
    C_extra[3, EA], C_extra[3, EB] = 1, 1
    return dict(M=M, Kg=Kg, Ke=Ke, B=B, G0=G0, G2=G2, C=C, C_extra=C_extra, y_a=y_a, Z=Z, Z_b=Z_b, h_c=h_c, d=d)


def cross(a, b):
    return mp.matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def transfer(model, f_hz, C=None, ncols=2):
    """H(f) = C (K - w^2 M)^-1 (G0 + w^2 G2), columns (theta_t, eta_t[, phi_t]), exp(+iwt)."""
    C = model["C"] if C is None else C
    w2 = (2 * mp.pi * mp.mpf(f_hz)) ** 2
    A = model["Kg"] + model["Ke"] - w2 * model["M"]
    rhs = model["G0"] + w2 * model["G2"]
    H = zeros(C.rows, ncols)
    for j in range(ncols):
        q = mp.lu_solve(A, rhs.column(j))
        y = C * q
        for o in range(C.rows):
            H[o, j] = y[o]
    return H


def mode_frequencies(model):
    """Undamped normal-mode frequencies (Hz), ascending, from det(K - w^2 M) = 0."""
    K = model["Kg"] + mp.matrix([[mp.re(x) for x in row] for row in model["Ke"].tolist()])
    ev = mp.eig(mp.inverse(model["M"]) * K, left=False, right=False)
    return sorted(mp.sqrt(mp.re(e)) / (2 * mp.pi) for e in ev)


def sanity_checks(model, tp):
    """Physics identities the model and transfer functions must satisfy; returns a dict for the JSON."""
    M, Kg = model["M"], model["Kg"]
    assert all(M[r, c] == M[c, r] and Kg[r, c] == Kg[c, r] for r in range(8) for c in range(8))
    assert all(float(v) == 0.0 for k, v in tp["loss"].items() if k.endswith("_rad")), "the fixture assumes zero loss angles"
    assert all(float(v) == 0.0 for v in tp.get("viscous", {}).values()), "the fixture assumes no viscous damping"
    tiny = mp.mpf(10) ** -30
    # Tilt = rigid rotation of the frame + translation of the suspension point by h t'':
    # G2 + M S_rot = -B [F_trans] with F_i = -m_i (w' x (0,0,h)), where S_rot puts theta_t, eta_t,
    # phi_t on theta_a, eta_a, phi_a. For phi_t the translation vanishes (axis through the fibre).
    h = mpf(tp["length"]["h_m"])
    m_a, m_b = mpf(tp["mass"]["m_a_kg"]), mpf(tp["mass"]["m_b_kg"])
    for j, coord in ((0, TA), (1, EA), (2, PA)):
        w = mp.matrix([0, 0, 0])
        w[j] = -1
        acc = cross(w, mp.matrix([0, 0, h]))
        f = mp.matrix(list(-m_a * acc) + list(-m_b * acc) + [0] * 6)
        q = model["B"] * f
        for r in range(8):
            assert abs(model["G2"][r, j] + M[r, coord] + q[r]) < tiny, (j, r)
    C_all = mp.matrix(7, 8)
    for c in range(8):
        for r in range(3):
            C_all[r, c] = model["C"][r, c]
        for r in range(4):
            C_all[3 + r, c] = model["C_extra"][r, c]
    out = {"tilt_equals_rotation_plus_suspension_translation": True}
    lever = model["Z"] + model["Z_b"] + model["h_c"]
    # rows of C_all: X, phi, phi_a, Y, Z, theta, eta
    H0 = transfer(model, 0, C=C_all, ncols=3)
    expect = {(0, 1): -lever, (3, 0): lever, (4, 0): -model["d"], (5, 0): 1, (6, 1): 1}
    for o in range(7):
        for i in range(3):
            e = expect.get((o, i), 0)
            assert abs(H0[o, i] - e) < tiny, (o, i, H0[o, i], e)
    out["H_X_eta_t_at_0_Hz"] = float(mp.re(H0[0, 1]))
    out["minus_Z_plus_Zb_plus_hc_m"] = float(-lever)
    # cross-block entries are exact zeros at any frequency
    Hq = transfer(model, mp.mpf("0.3"), C=C_all, ncols=3)
    for o, i in ((0, 0), (1, 0), (2, 0), (3, 1), (3, 2), (4, 1), (4, 2), (5, 1), (5, 2), (6, 0)):
        assert Hq[o, i] == 0, (o, i, Hq[o, i])
    # low-frequency power laws: X + lever ~ f^2, phi ~ f^4, phi_a ~ f^4 (per eta_t)
    slopes = {}
    for name, o, offset in (("X_plus_lever", 0, lever), ("phi", 1, 0), ("phi_a", 2, 0)):
        v1 = abs(transfer(model, mp.mpf("1e-6"))[o, 1] + offset)
        v2 = abs(transfer(model, mp.mpf("1e-5"))[o, 1] + offset)
        slopes[name] = float(mp.log10(v2 / v1))
    assert abs(slopes["X_plus_lever"] - 2) < 1e-3 and abs(slopes["phi"] - 4) < 1e-3
    assert abs(slopes["phi_a"] - 4) < 1e-3
    out["low_f_loglog_slopes_1e-6_to_1e-5_Hz_per_eta_t"] = slopes
    out["mode_frequencies_hz"] = [float(v) for v in mode_frequencies(model)]
    return out


# ----------------------------------------------------------------------------------------------
# ROMY record -> tilt angles -> cross-spectral matrix
# ----------------------------------------------------------------------------------------------
def read_romy(path=ROMY_CSV):
    with open(path) as fh:
        lines = [ln.strip() for ln in fh if ln.strip() and not ln.startswith("#")]
    header = lines[0].split(",")
    rows = [[float(x) for x in ln.split(",")] for ln in lines[1:]]
    cols = {name: [r[k] for r in rows] for k, name in enumerate(header)}
    t = cols["time_s"]
    assert len(t) == 8192 and t[0] == 0.0, (len(t), t[0])
    dt = {t[k + 1] - t[k] for k in range(len(t) - 1)}
    assert dt == {1.0}, dt
    return cols


def csd_matrix(x, fs):
    """S[k][i][j] = scipy.signal.csd(x_i, x_j) (conj(X_i) X_j), one-sided density, k = 0 dropped."""
    n = len(x)
    S = None
    for i in range(n):
        for j in range(n):
            a, b = x[i], (x[i] if i == j else x[j])  # same object on the diagonal: welch path
            f, s = signal.csd(a, b, fs=fs, return_onesided=True, **WELCH)
            if S is None:
                S = np.zeros((len(f), n, n), dtype=complex)
            S[:, i, j] = s
    return f[1:], S[1:]


def budget(H_list, S):
    """Per output: tilt PSD = diag(conj(H) S H^T) (scipy's CSD convention), per-axis |H_oi|^2 S_ii."""
    n_f, n_o, n_i = len(H_list), H_list[0].rows, H_list[0].cols
    tilt = np.zeros((n_o, n_f))
    per_axis = np.zeros((n_o, n_i, n_f))
    for k, H in enumerate(H_list):
        Sk = [[mp.mpc(complex(S[k, i, j])) for j in range(n_i)] for i in range(n_i)]
        for o in range(n_o):
            acc = mp.mpc(0)
            for i in range(n_i):
                for j in range(n_i):
                    acc += mp.conj(H[o, i]) * Sk[i][j] * H[o, j]
                per_axis[o, i, k] = float(abs(H[o, i]) ** 2 * mp.re(Sk[i][i]))
            assert abs(mp.im(acc)) <= mp.mpf(10) ** -25 * abs(acc) + mp.mpf(10) ** -60
            tilt[o, k] = float(mp.re(acc))
    return tilt, per_axis


def sha256(path):
    with open(path, "rb") as fh:
        return hashlib.sha256(fh.read()).hexdigest()


def lab_budget(model, generator):
    """Budget of tilt_data/lab_tilt_24h.h5: whole day and hour by hour (small JSON fixture)."""
    with h5py.File(os.path.join(REPO, LAB_H5_REL), "r") as h:
        fs = float(h.attrs["sample_rate_hz"])
        x = [h["theta_t"][()], h["eta_t"][()]]
    cases = []
    # whole day: f = k/4000 puts 1, 2, 5, 10 mHz on bins 4, 8, 20, 40
    # hourly: 3600 samples per hour, nperseg=1200 puts 5 and 10 mHz on bins 6 and 12
    for label, nper, spans, bins in (
        ("day", 4000, [(0, len(x[0]))], (4, 8, 20, 40)),
        ("hourly", 1200, [(3600 * hr, 3600 * (hr + 1)) for hr in range(24)], (6, 12)),
    ):
        welch = dict(WELCH, nperseg=nper, noverlap=nper // 2)
        H_list = [transfer(model, mp.mpf(k) / nper) for k in bins]
        for lo, hi in spans:
            seg = [c[lo:hi] for c in x]
            S = np.zeros((len(bins), 2, 2), dtype=complex)
            for i in range(2):
                for j in range(2):
                    f, s = signal.csd(seg[i], seg[i] if i == j else seg[j], fs=fs, return_onesided=True, **welch)
                    S[:, i, j] = s[list(bins)]
            assert np.all(f[list(bins)] == np.array(bins) / nper)
            tilt, per_axis = budget(H_list, S)
            cases.append({
                "segment": label, "sample_range": [lo, hi], "nperseg": nper, "noverlap": nper // 2,
                "freqs_hz": [k / nper for k in bins],
                "csd_re": S.real.reshape(-1).tolist(), "csd_im": S.imag.reshape(-1).tolist(),
                "tf_re": [float(mp.re(H[o, i])) for H in H_list for o in range(3) for i in range(2)],
                "tf_im": [float(mp.im(H[o, i])) for H in H_list for o in range(3) for i in range(2)],
                "tilt_psd": {name: tilt[o].tolist() for o, name in enumerate(OUTPUTS)},
                "per_axis_psd": {name: {inp: per_axis[o, i].tolist() for i, inp in enumerate(INPUTS)}
                                 for o, name in enumerate(OUTPUTS)},
            })
    doc = {
        "schema": "tiltnoise.reference.lab_budget",
        "schema_version": 1,
        "generator": generator,
        "input": {"file": LAB_H5_REL, "sha256": sha256(os.path.join(REPO, LAB_H5_REL)),
                  "channels": list(INPUTS), "note": "angles used as stored (no integration)"},
        "welch": dict(WELCH, return_onesided=True, nperseg="per case", noverlap="nperseg // 2"),
        "conventions": "as romy_budget_reference.json (csd = <conj(X_i) X_j>, arrays flattened [freq][row][col])",
        "cases": cases,
    }
    with open(LAB_JSON, "w") as fh:
        json.dump(doc, fh, separators=(",", ":"))
        fh.write("\n")
    print(f"wrote {LAB_JSON} ({os.path.getsize(LAB_JSON)} bytes)")
    day = cases[0]
    print("lab_tilt_24h, whole day (nperseg=4000):")
    for k, f in enumerate(day["freqs_hz"]):
        a_eta = math.sqrt(day["csd_re"][4 * k + 3])
        ax = math.sqrt(day["tilt_psd"]["X"][k])
        print(f"  {f * 1e3:g} mHz: eta_t {a_eta:.3g} rad/sqrt(Hz), X tilt {ax:.3g} m/sqrt(Hz), "
              f"phi {math.sqrt(day['tilt_psd']['phi'][k]):.3g}, phi_a {math.sqrt(day['tilt_psd']['phi_a'][k]):.3g} rad/sqrt(Hz)")
    hourly = np.array([[math.sqrt(v) for v in c["tilt_psd"]["X"]] for c in cases[1:]])
    for k, f in enumerate(cases[1]["freqs_hz"]):
        col = hourly[:, k]
        print(f"  hourly X tilt ASD at {f * 1e3:g} mHz: min {col.min():.3g} (hour {col.argmin():02d}), "
              f"median {np.median(col):.3g}, max {col.max():.3g} (hour {col.argmax():02d}) m/sqrt(Hz)")


def main():
    tp = load_params()
    model = build_model(tp)
    checks = sanity_checks(model, tp)
    print("sanity checks passed:")
    print(f"  H_X/eta_t(0) = {checks['H_X_eta_t_at_0_Hz']!r} m/rad (-(Z+Z_b+h_c) = {checks['minus_Z_plus_Zb_plus_hc_m']!r})")
    print(f"  log-log slopes 1e-6..1e-5 Hz: {checks['low_f_loglog_slopes_1e-6_to_1e-5_Hz_per_eta_t']}")
    print("  modes (Hz): " + ", ".join(f"{v:.6g}" for v in checks["mode_frequencies_hz"]))

    cols = read_romy()
    fs = 1.0
    # lab x = East, y = North; t is minus the floor rotation. The rates stay rates: their CSD
    # divided by (2 pi f)^2 is the angle's (exp(+i w t): T = R / (i w)); k = 0 has no angle.
    theta_t_rate = np.array([-v for v in cols["LJE"]])
    eta_t_rate = np.array([-v for v in cols["LJN"]])
    freqs, S_rate = csd_matrix([theta_t_rate, eta_t_rate], fs)
    assert np.all(freqs == np.arange(1, len(freqs) + 1) / WELCH["nperseg"])
    S = S_rate / ((2 * np.pi * freqs) ** 2)[:, None, None]

    H_list = [transfer(model, mp.mpf(int(k)) / WELCH["nperseg"]) for k in range(1, len(freqs) + 1)]
    tilt, per_axis = budget(H_list, S)
    modes = checks["mode_frequencies_hz"]
    closest = min((abs(f / nu - 1.0), f, nu) for f in freqs for nu in modes)

    outputs = {}
    units = {"X": "m^2/Hz", "phi": "rad^2/Hz", "phi_a": "rad^2/Hz"}
    for o, name in enumerate(OUTPUTS):
        readout = READOUT_X_ASD**2 if name == "X" else 0.0
        outputs[name] = {
            "psd_unit": units[name],
            "tilt_psd": tilt[o].tolist(),
            "tilt_asd": np.sqrt(tilt[o]).tolist(),
            "per_axis_psd": {inp: per_axis[o, i].tolist() for i, inp in enumerate(INPUTS)},
            "readout_psd": readout,
            "total_psd": (tilt[o] + readout).tolist(),
        }

    doc = {
        "schema": "tiltnoise.reference.romy_budget",
        "schema_version": 1,
        "generator": {
            "script": "scripts/reference/tilt_budget_reference.py",
            "python": sys.version.split()[0],
            "numpy": np.__version__,
            "scipy": scipy.__version__,
            "mpmath": mp.__version__,
            "mp_dps": mp.mp.dps,
        },
        "inputs": {
            "file": ROMY_REL,
            "file_relative_to": "repository root",
            "sha256": sha256(ROMY_CSV),
            "sample_rate_hz": fs,
            "n_samples": len(theta_t_rate),
            "mapping": "lab x = East, y = North; theta_t rate = -LJE, eta_t rate = -LJN (rad/s); "
            "t is minus the floor rotation (tiltnoise sign convention)",
            "rate_to_angle": "no time integration: csd of the rates (rad^2/s^2/Hz) divided by "
            "(2 pi f)^2 at every bin k >= 1; k = 0 carries no angle information",
            "theta_t_rate_first": theta_t_rate[:6].tolist(),
            "eta_t_rate_first": eta_t_rate[:6].tolist(),
            "welch": dict(WELCH, return_onesided=True, window_note="periodic Hann (scipy get_window)"),
            "dropped": "k = 0 (DC)",
        },
        "parameters": {
            "source": "crates/tiltnoise-core/src/params/table1.toml",
            "values": tp,
            "derived": {"y_a_m": float(model["y_a"]), "Z_plus_Zb_plus_hc_m": -checks["minus_Z_plus_Zb_plus_hc_m"]},
            "generalization": "I^b_22 in the eta rows (I_b2, I_b4, I_b5), I^b_11 in the theta rows",
        },
        "conventions": {
            "tf": "H[k][o][i]: complex amplitude of output o per unit input i for exp(+i w t); "
            "outputs (X [m], phi [rad], phi_a [rad]), inputs (theta_t, eta_t) [rad]; "
            "H = C (K - w^2 M)^-1 (G0 + w^2 G2), mpmath 40 digits, rounded to double",
            "csd": "csd[k][i][j] = scipy.signal.csd(x_i, x_j) = <conj(X_i) X_j>, one-sided density, "
            "rad^2/Hz, channels (theta_t, eta_t)",
            "output_psd": "S_o = sum_ij conj(H_oi) csd_ij H_oj (= (H S^T H^H)_oo); "
            "per_axis_psd[i] = |H_oi|^2 csd_ii; total = tilt + readout (readout only for X: (9e-9 m)^2/Hz)",
            "flattening": "tf and csd arrays are flattened [freq][row][col]",
        },
        "checks": dict(checks, closest_bin_to_mode={"rel_offset": closest[0], "freq_hz": closest[1], "mode_hz": closest[2]}),
        "freqs_hz": freqs.tolist(),
        "csd": {
            "channels": list(INPUTS),
            "re": S.real.reshape(-1).tolist(),
            "im": S.imag.reshape(-1).tolist(),
        },
        "tf": {
            "outputs": list(OUTPUTS),
            "inputs": list(INPUTS),
            "re": [float(mp.re(H[o, i])) for H in H_list for o in range(3) for i in range(2)],
            "im": [float(mp.im(H[o, i])) for H in H_list for o in range(3) for i in range(2)],
        },
        "outputs": outputs,
    }
    with open(OUT_JSON, "w") as fh:
        json.dump(doc, fh, separators=(",", ":"))
        fh.write("\n")
    print(f"wrote {OUT_JSON} ({os.path.getsize(OUT_JSON)} bytes)")
    print(f"closest bin to a mode: f = {closest[1]} Hz vs {closest[2]:.9g} Hz (rel. offset {closest[0]:.3g})")
    print("ROMY tilt ASD and X tilt ASD near 1, 2, 5, 10 mHz:")
    for k in (2, 4, 10, 20):
        i = k - 1
        a_eta = math.sqrt(S[i, 1, 1].real)
        a_th = math.sqrt(S[i, 0, 0].real)
        ax = math.sqrt(tilt[0, i])
        print(
            f"  f = {freqs[i] * 1e3:.4f} mHz: theta_t {a_th:.3g}, eta_t {a_eta:.3g} rad/sqrt(Hz); "
            f"X tilt {ax:.3g} m/sqrt(Hz) (= {ax / a_eta:.4g} m x eta_t ASD; |H_X,eta_t| = "
            f"{float(abs(H_list[i][0, 1])):.4g}); phi {math.sqrt(tilt[1, i]):.3g}, phi_a {math.sqrt(tilt[2, i]):.3g} rad/sqrt(Hz)"
        )
    lab_budget(model, doc["generator"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
