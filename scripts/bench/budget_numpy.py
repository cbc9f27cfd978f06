#!/usr/bin/env python3
"""The tilt-noise budget as a NumPy/SciPy/h5py user would write it (benchmark baseline).

    python3 scripts/bench/budget_numpy.py --tilt IN.h5 --nperseg 16384 --save OUT.h5 [--csd broadcast|pairs]

Equivalent of `tiltnoise budget --tilt IN.h5 --nperseg 16384 --save OUT.h5` for an HDF5 tilt
series in rad (schema tiltnoise.tilt_series with datasets theta_t, eta_t, phi_t):

1. h5py reads the three channels whole.
2. Welch cross-spectral matrix, S_ij = <conj(X_i) X_j> (scipy.signal.csd's convention): periodic
   Hann, nperseg samples, 50 % overlap, constant detrend, mean, one-sided density.
   `--csd pairs` (default): 9 scipy.signal.csd calls, one per (i, j), the diagonal through
   scipy's welch path (how most scripts are written, and the fastest scipy variant here).
   `--csd broadcast`: one scipy.signal.csd call on broadcast (3,1,N) x (1,3,N) arrays.
   `--csd numpy`: the same estimate written out in NumPy (sliding windows, one rfft per channel
   and segment, one einsum); does not import scipy at all (a lean lower bound for Python).
3. Transfer functions on the Welch grid without DC: H(f) = C (K - w^2 M)^-1 (G0 + w^2 G2) by
   numpy.linalg.solve on the stacked 8x8 complex dynamic stiffness matrices; the model (M, K,
   B, G0, G2, C) is built in float64 from src/params/table1.toml exactly as in the paper's
   Appendix A with the crate's tilt convention (a float64 port of
   scripts/reference/tilt_budget_reference.py; loss angles must be 0 there and are used as
   k (1 + i phi) here).
4. Budget per observable X, phi, phi_a: tilt = sum_ij conj(H_oi) S_ij H_oj, per-axis
   |H_oi|^2 S_ii, readout (9e-9 m/sqrt(Hz))^2 on X, total = tilt + readout.
5. h5py writes the same datasets as the Rust budget file (schema tiltnoise.budget):
   /frequency_hz, /<obs>/<term>/psd and /asd, with the main root attributes.
"""

import argparse
import os
import sys
import time
import tomllib

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_PARAMS = os.path.normpath(os.path.join(HERE, "..", "..", "src", "params", "table1.toml"))

AXES = ("theta_t", "eta_t", "phi_t")
OUTPUTS = ("X", "phi", "phi_a")
UNITS = {"X": "m", "phi": "rad", "phi_a": "rad"}
READOUT_ASD = {"X": 9e-9}  # m/sqrt(Hz), white, paper section III
TA, EA, PA, DA, TB, EB, PB, DB = range(8)


def build_model(tp):
    """M, K (complex, with loss angles), G0, G2 (8x3: theta_t, eta_t, phi_t), C (3x8: X, phi, phi_a)."""
    m_a, m_b = tp["mass"]["m_a_kg"], tp["mass"]["m_b_kg"]
    i = tp["inertia"]
    a11, a22, a33, a23 = i["a11_kg_m2"], i["a22_kg_m2"], i["a33_kg_m2"], i["a23_kg_m2"]
    b11, b22, b33 = i["b11_kg_m2"], i["b22_kg_m2"], i["b33_kg_m2"]
    k_a, k_b = tp["torsion"]["k_a_n_m_per_rad"], tp["torsion"]["k_b_n_m_per_rad"]
    ka_e, kb_e = tp["bouncing"]["kappa_a_n_per_m"], tp["bouncing"]["kappa_b_n_per_m"]
    L = tp["length"]
    d, h_c, Z, Z_a, Z_b, h = (L[k] for k in ("d_m", "h_c_m", "z_m", "z_a_m", "z_b_m", "h_m"))
    g = tp["environment"]["g_m_per_s2"]
    loss = tp["loss"]

    y_a = d * m_b / m_a
    # Appendix A, eq. (def_I); I^b_22 where the test mass turns about its own y axis (eta rows).
    I_a1 = a11 + m_a * ((Z + Z_a) ** 2 + y_a * y_a)
    I_b1 = b11 + m_b * ((Z + Z_b) ** 2 + d * d)
    I_a2 = a22 + m_a * (Z + Z_a) ** 2
    I_b2 = b22 + m_b * (Z + Z_b) ** 2
    I_a3 = a33 + m_a * y_a * y_a
    I_b3 = b33 + m_b * d * d
    I_a4 = a23 + m_b * d * (Z_a - Z_b)
    I_b4_th, I_b4_et = b11 + m_b * Z_b * Z_b, b22 + m_b * Z_b * Z_b
    I_b5_th, I_b5_et = b11 + m_b * Z_b * (Z + Z_b), b22 + m_b * Z_b * (Z + Z_b)
    c_1 = m_b * (Z + Z_b) + m_a * (Z + Z_a)

    M = np.zeros((8, 8))

    def sym(mat, r, c, v):
        mat[r, c] = v
        mat[c, r] = v

    # Appendix A, eq. (EM): inertia terms.
    sym(M, TA, TA, I_a1 + I_b1)
    sym(M, TA, TB, I_b5_th)
    sym(M, TA, DB, m_b * d)
    sym(M, EA, EA, I_a2 + I_b2)
    sym(M, EA, PA, I_a4)
    sym(M, EA, EB, I_b5_et)
    sym(M, PA, PA, I_a3 + I_b3)
    sym(M, PA, PB, b33)
    sym(M, PA, EB, -m_b * d * Z_b)
    sym(M, DA, DA, m_a + m_b)
    sym(M, DA, DB, m_b)
    sym(M, TB, TB, I_b4_th)
    sym(M, EB, EB, I_b4_et)
    sym(M, PB, PB, b33)
    sym(M, DB, DB, m_b)

    # Gravity stiffness (lossless) + elastic stiffness of the fibres, k (1 + i phi).
    Kg = np.zeros((8, 8))
    for a, b in ((TA, TB), (EA, EB)):
        Kg[a, a] = g * c_1
        sym(Kg, a, b, m_b * g * Z_b)
        Kg[b, b] = m_b * g * Z_b
    K = Kg.astype(complex)
    for c, k, phi in (
        (PA, k_a, loss["torsion_a_rad"]),
        (PB, k_b, loss["torsion_b_rad"]),
        (DA, ka_e, loss["bouncing_a_rad"]),
        (DB, kb_e, loss["bouncing_b_rad"]),
    ):
        K[c, c] += complex(k, k * phi)

    # Zeroth-order generalized forces (Appendix A, last display).
    # Columns: F_a (x,y,z), F_b (x,y,z), M_a (x,y,z), M_b (x,y,z).
    FAX, FAY, FAZ, FBX, FBY, FBZ, MAX, MAY, MAZ, MBX, MBY, MBZ = range(12)
    B = np.zeros((8, 12))
    B[TA, FBY], B[TA, FAY], B[TA, MAX], B[TA, MBX] = Z + Z_b, Z + Z_a, 1, 1
    B[TA, FAZ], B[TA, FBZ] = y_a, -d
    B[EA, FBX], B[EA, FAX], B[EA, MAY], B[EA, MBY] = -(Z + Z_b), -(Z + Z_a), 1, 1
    B[PA, FAX], B[PA, FBX], B[PA, MAZ], B[PA, MBZ] = -y_a, d, 1, 1
    B[DA, FAZ], B[DA, FBZ] = -1, -1
    B[TB, FBY], B[TB, MBX] = Z_b, 1
    B[EB, FBX], B[EB, MBY] = -Z_b, 1
    B[PB, MBZ] = 1
    B[DB, FBZ] = -1

    # Tilt forcing, crate convention (t takes the floor frame to the inertial frame).
    # G0: the potential at (theta_a - theta_t, eta_a - eta_t): columns of K_gravity.
    G0 = np.zeros((8, 3))
    G0[:, 0], G0[:, 1] = Kg[:, TA], Kg[:, EA]
    # G2: apparent forces and torques per unit t'' (frame angular acceleration w' = -t'').
    I_a = np.array([[a11, 0, 0], [0, a22, a23], [0, a23, a33]])
    I_b = np.diag([b11, b22, b33])
    r_ga0 = np.array([0.0, y_a, -(Z + Z_a)])
    r_gb0 = np.array([0.0, -d, -(Z + Z_b)])
    G2 = np.zeros((8, 3))
    for j in range(3):
        w = np.zeros(3)
        w[j] = -1.0
        r_s = np.cross(w, [0.0, 0.0, h])
        F_a = -m_a * (r_s + np.cross(w, r_ga0))
        F_b = -m_b * (r_s + np.cross(w, r_gb0))
        M_a = -(I_a @ w)
        M_b = -(I_b @ w)
        G2[:, j] = -(B @ np.concatenate([F_a, F_b, M_a, M_b]))

    # Observation rows: X, phi, phi_a (section II.D).
    C = np.zeros((3, 8))
    C[0, EA], C[0, EB], C[0, PA] = -(Z + Z_b + h_c), -(h_c + Z_b), d
    C[1, PA], C[1, PB] = 1, 1
    C[2, PA] = 1
    return M, K, G0, G2, C


def read_series(path):
    with h5py.File(path, "r") as f:
        fs = float(f.attrs["sample_rate_hz"])
        for a in AXES:
            u = f[a].attrs.get("units", "rad")
            if (u.decode() if isinstance(u, bytes) else u) != "rad":
                sys.exit(f"{path}: dataset /{a} has units {u!r}; this baseline handles angles in rad only")
        x = np.stack([f[a][()] for a in AXES])
    return fs, x


def csd_matrix(x, fs, nperseg, how):
    """(freqs, S[i, j, k]) with S_ij = <conj(X_i) X_j>, one-sided density, DC dropped."""
    if how == "numpy":
        return welch_numpy(x, fs, nperseg)
    from scipy import signal  # imported here: the numpy variant never pays for it

    kw = dict(fs=fs, window="hann", nperseg=nperseg, noverlap=nperseg // 2, detrend="constant",
              return_onesided=True, scaling="density", average="mean")
    if how == "broadcast":
        f, S = signal.csd(x[:, None, :], x[None, :, :], **kw)
    else:
        n = len(x)
        S = None
        for i in range(n):
            for j in range(n):
                f, s = signal.csd(x[i], x[i] if i == j else x[j], **kw)
                if S is None:
                    S = np.empty((n, n, len(f)), dtype=complex)
                S[i, j] = s
    return f[1:], S[:, :, 1:]


def welch_numpy(x, fs, nperseg):
    """The same estimate as scipy.signal.csd, written out in NumPy (one FFT per channel and
    segment, the 3x3 products in one einsum)."""
    noverlap = nperseg // 2
    step = nperseg - noverlap
    n_seg = (x.shape[1] - noverlap) // step
    segs = np.lib.stride_tricks.sliding_window_view(x, nperseg, axis=-1)[:, ::step][:, :n_seg]
    segs = segs - segs.mean(axis=-1, keepdims=True)  # detrend='constant'
    win = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(nperseg) / nperseg)  # periodic Hann
    X = np.fft.rfft(segs * win, axis=-1)  # (channel, segment, freq)
    S = np.einsum("isk,jsk->ijk", X.conj(), X) / (n_seg * fs * (win * win).sum())
    S[..., 1 : (nperseg + 1) // 2] *= 2  # one-sided: all but DC and (even nperseg) Nyquist
    f = np.arange(nperseg // 2 + 1) * (fs / nperseg)
    return f[1:], S[:, :, 1:]


def transfer(M, K, G0, G2, C, freqs):
    """H[k, o, i] = (C (K - w^2 M)^-1 (G0 + w^2 G2))[o, i] at every frequency (stacked solve)."""
    w2 = (2 * np.pi * freqs) ** 2
    A = K[None, :, :] - w2[:, None, None] * M[None, :, :]
    rhs = (G0[None, :, :] + w2[:, None, None] * G2[None, :, :]).astype(complex)
    return C @ np.linalg.solve(A, rhs)


def budget(H, S):
    """Per output o: tilt PSD sum_ij conj(H_oi) S_ij H_oj and per-axis |H_oi|^2 S_ii."""
    tilt = np.einsum("koi,ijk,koj->ok", H.conj(), S, H).real
    tilt = np.maximum(tilt, 0.0)
    diag = np.einsum("iik->ik", S).real  # (axis, freq)
    per_axis = np.abs(H.transpose(1, 2, 0)) ** 2 * diag[None, :, :]  # (output, axis, freq)
    out = {}
    for o, name in enumerate(OUTPUTS):
        terms = {"tilt": tilt[o]}
        for i, a in enumerate(AXES):
            terms[f"tilt.{a}"] = per_axis[o, i]
        total = tilt[o]
        if name in READOUT_ASD:
            terms["readout"] = np.full(len(tilt[o]), READOUT_ASD[name] ** 2)
            total = total + terms["readout"]
        terms["total"] = total
        out[name] = terms
    return out


def write_budget(path, freqs, terms, meta):
    tmp = path + ".tmp"
    with h5py.File(tmp, "w") as f:
        f.attrs["schema"] = "tiltnoise.budget"
        f.attrs["schema_version"] = 1
        f.attrs["tool_version"] = "budget_numpy.py (benchmark baseline)"
        f.attrs["spectral_convention"] = "one-sided; PSD in unit^2/Hz, ASD = sqrt(PSD) in unit/sqrt(Hz)"
        f.attrs["source"] = "welch"
        for k, v in meta.items():
            f.attrs[k] = v
        f.attrs["tilt_axes"] = list(AXES)
        f.attrs["observables"] = list(OUTPUTS)
        d = f.create_dataset("frequency_hz", data=freqs)
        d.attrs["units"] = "Hz"
        for name, ts in terms.items():
            u = UNITS[name]
            g = f.create_group(name)
            g.attrs["unit"] = u
            g.attrs["terms"] = list(ts)
            if name in READOUT_ASD:
                g.attrs["readout_asd"] = READOUT_ASD[name]
                g.attrs["readout_asd_units"] = f"{u}/sqrt(Hz)"
            for term, psd in ts.items():
                tg = g.create_group(term)
                d = tg.create_dataset("psd", data=psd)
                d.attrs["units"] = f"{u}^2/Hz"
                d = tg.create_dataset("asd", data=np.sqrt(psd))
                d.attrs["units"] = f"{u}/sqrt(Hz)"
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tilt", required=True)
    ap.add_argument("--nperseg", type=int, default=16384)
    ap.add_argument("--save", required=True)
    ap.add_argument("--params", default=DEFAULT_PARAMS)
    ap.add_argument("--csd", choices=("broadcast", "pairs", "numpy"), default="pairs")
    ap.add_argument("--timing", action="store_true", help="print per-stage wall times to stderr")
    args = ap.parse_args()

    t = [time.perf_counter()]
    with open(args.params, "rb") as fh:
        M, K, G0, G2, C = build_model(tomllib.load(fh))
    fs, x = read_series(args.tilt)
    t.append(time.perf_counter())
    if args.csd != "numpy":
        from scipy import signal  # noqa: F401  (timed on its own: most of the scipy variants' cost)
    t.append(time.perf_counter())
    freqs, S = csd_matrix(x, fs, args.nperseg, args.csd)
    t.append(time.perf_counter())
    H = transfer(M, K, G0, G2, C, freqs)
    t.append(time.perf_counter())
    terms = budget(H, S)
    t.append(time.perf_counter())
    n_seg = (x.shape[1] - args.nperseg // 2) // (args.nperseg - args.nperseg // 2)
    meta = dict(sample_rate_hz=fs, welch_segment_len=args.nperseg, welch_overlap=args.nperseg // 2,
                welch_averaging="mean", welch_n_segments=n_seg, n_samples=x.shape[1],
                input_path=os.path.abspath(args.tilt))
    write_budget(args.save, freqs, terms, meta)
    t.append(time.perf_counter())
    if args.timing:
        names = ("model+read", "import-scipy", "csd", "tf", "budget", "write")
        print("  ".join(f"{n} {b - a:.3f}s" for n, a, b in zip(names, t, t[1:])), file=sys.stderr)


if __name__ == "__main__":
    main()
