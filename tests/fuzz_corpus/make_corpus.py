#!/usr/bin/env python3
"""Writes the seed corpus of the reader fuzz targets (tests/it/fuzz.rs): small valid inputs, one
directory per target. Rerun after a format change; needs numpy and h5py.

    python3 tests/fuzz_corpus/make_corpus.py

Every file is valid for its reader, so that mutations start from inputs that reach the deep
checks. Values come from a fixed seed: a rerun rewrites the text files byte for byte (the HDF5
files may differ in timestamps and free-space layout between HDF5 versions). The parameter files
are copies of the embedded Table I and of examples/damped.toml.

Crashing inputs found by the fuzzer go to <target>/regressions/ (kept by hand, not written here).
"""
import os
import shutil

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
RNG = np.random.default_rng(20240301)


def path(target, name):
    d = os.path.join(HERE, target)
    os.makedirs(d, exist_ok=True)
    return os.path.join(d, name)


def text(target, name, body):
    with open(path(target, name), "w", newline="") as f:
        f.write(body)


def series_rows(names, n, fs, scale):
    lines = ["time_s," + ",".join(names)]
    data = scale * RNG.standard_normal((n, len(names)))
    for i in range(n):
        lines.append(f"{i / fs!r}," + ",".join(f"{v:.9e}" for v in data[i]))
    return "\n".join(lines) + "\n"


def asd_rows(names, freqs, scale):
    lines = ["freq_hz," + ",".join(names)]
    for f in freqs:
        lines.append(f"{f!r}," + ",".join(f"{scale * (1 + 1 / f) * (k + 1):.6e}"
                                          for k in range(len(names))))
    return "\n".join(lines) + "\n"


# tilt_csv: read_tilt on CSV, series and spectra.
text("tilt_csv", "series_angle.csv", series_rows(["theta_t", "eta_t"], 16, 10.0, 1e-9))
text("tilt_csv", "series_rate_meta.csv",
     "# units: LJN=rad/s, LJE=rad/s\n"
     "# axes: theta_t=-LJE,eta_t=-LJN\n"
     "# start_time: 2018-01-23T09:31:42.5+01:00\n"
     "# description: fuzz seed, \"quoted\" text\n"
     "# t0 = 2018-01-23T09:31:42.000000Z\n"
     + series_rows(["LHN", "LJN", "LJE", "LJZ"], 12, 1.0, 1e-12).replace("time_s,LHN", "time_s,\"LHN\""))
text("tilt_csv", "series_gaps_crlf.csv",
     ("\ufefftime_s,E,N,Z\n0.00,1e-9,2e-9,3e-9\n0.25,,2e-9,nan\n0.50,1e-9, \"3e-9\" ,3e-9\n"
      "\n0.75,2e-9,inf,3e-9\n1.00,1e-9,2e-9,3e-9\n").replace("\n", "\r\n"))
text("tilt_csv", "spectra_asd.csv",
     "# units: rad/sqrt(Hz)\n" + asd_rows(["theta_t", "eta_t", "phi_t"], [1e-3, 1e-2, 0.1, 1.0, 10.0], 1e-9))
text("tilt_csv", "spectra_rate.csv",
     "# units: rad/s/√Hz\n# axes: theta_t=+BJE, eta_t=-BJN\n"
     + asd_rows(["BJN", "BJE"], [0.5, 1.0, 2.0, 4.0], 1e-12))

# measured_csv: read_measured_input / read_measured on CSV.
text("measured_csv", "spectra.csv", asd_rows(["X", "phi", "phi_a"], [1e-3, 1e-2, 0.1, 1.0], 1e-8))
text("measured_csv", "series.csv", series_rows(["X", "Y", "theta", "phi"], 16, 4.0, 1e-7))

# measured_modes: read_measured_modes (Measured::parse).
text("measured_modes", "with_sigma.csv",
     "# measured modes\nmode,frequency_hz,sigma_hz\n1,0.001331,\n2,0.002117,1e-6\n"
     "5,0.58815,\n8,10.393,0.01\n")
text("measured_modes", "without_sigma.csv", "mode,frequency_hz\n3,0.406\n4,\"0.4065\"\n7,7.926e0\n")

# freq_file: read_freq_file.
text("freq_file", "grid.txt", "# Hz\n1e-4\n0.001\n\n 0.5 \n\"2\"\n30\n")

# freq_spec: freq::parse_spec, one spec per line.
text("freq_spec", "specs.txt", "1e-4:2000:30\n0.5:1:0.5\n 1e-3 : 16 : 1e2 \n")

# params_override: Params::with_override on Table I, one assignment per line.
text("params_override", "assignments.txt",
     "length.h_m=1.5\nmass.m_b_kg = 0.2\nloss.torsion_a_rad=1e-4\n"
     "environment.temperature_k=4.2\ninertia.a23_kg_m2=-1e-3\n")

# params_toml: Params::from_file.
shutil.copy(os.path.join(ROOT, "crates/tiltnoise-core/src/params/table1.toml"),
            path("params_toml", "table1.toml"))
shutil.copy(os.path.join(ROOT, "examples/damped.toml"), path("params_toml", "damped.toml"))
text("params_toml", "uncertainty.toml",
     "[mass]\nm_b_kg = 0.2\n\n[uncertainty]\n"
     "\"mass.m_a_kg\" = { rel_sigma = 0.03, distribution = \"uniform\" }\n"
     "\"length.h_m\" = { rel_sigma = 0.0 }\ntorsion.k_b_n_m_per_rad = { rel_sigma = 0.05 }\n")


# tilt_h5_bytes: read_tilt and the other HDF5 readers on HDF5 files, in the default format
# (no metadata checksums) except where noted, so that byte mutations reach the readers.
def vlen(f_or_ds, name, value, encoding="utf-8"):
    f_or_ds.attrs.create(name, value, dtype=h5py.string_dtype(encoding))


with h5py.File(path("tilt_h5_bytes", "series_angle.h5"), "w") as f:
    f.attrs["sample_rate_hz"] = 10.0
    for ch in ("theta_t", "eta_t"):
        d = f.create_dataset(ch, data=1e-9 * RNG.standard_normal(16))
        vlen(d, "units", "rad")

with h5py.File(path("tilt_h5_bytes", "series_rate_schema.h5"), "w") as f:
    vlen(f, "schema", "tiltnoise.tilt_series")
    f.attrs["schema_version"] = 1
    f.attrs["sample_rate_hz"] = np.int32(2)
    vlen(f, "start_time", "2024-03-01T00:00:00Z", "ascii")
    f.attrs["description"] = np.bytes_(b"PETER lab floor")
    vlen(f, "axis_map", "theta_t=-E,eta_t=-N,phi_t=+Z")
    for ch in ("E", "N", "Z"):
        d = f.create_dataset(ch, data=(1e-12 * RNG.standard_normal(12)).astype("f4"))
        d.attrs["units"] = np.bytes_(b"rad/s")
    f.create_group("extra").create_dataset("E", data=np.arange(3))

with h5py.File(path("tilt_h5_bytes", "series_chunked_gzip.h5"), "w") as f:
    f.attrs["sample_rate_hz"] = 1.0
    for ch in ("LJE", "LJN"):
        f.create_dataset(ch, data=1e-9 * RNG.standard_normal(32), chunks=(8,),
                         compression="gzip", shuffle=True)

with h5py.File(path("tilt_h5_bytes", "spectra_asd.h5"), "w") as f:
    freqs = np.array([1e-3, 1e-2, 0.1, 1.0])
    f.create_dataset("frequency_hz", data=freqs)
    d = f.create_dataset("asd", data=1e-9 * (1 + 1 / freqs)[:, None] * np.ones((4, 2)))
    vlen(d, "units", "rad/sqrt(Hz)")
    f.attrs.create("axes", ["theta_t", "eta_t"], dtype=h5py.string_dtype())
    vlen(f, "schema", "tiltnoise.tilt_spectra")

with h5py.File(path("tilt_h5_bytes", "spectra_csd_latest.h5"), "w", libver="latest") as f:
    freqs = np.array([0.01, 0.1, 1.0])
    f.create_dataset("frequency_hz", data=freqs)
    x = RNG.standard_normal((3, 2)) + 1j * RNG.standard_normal((3, 2))
    csd = np.conj(x)[:, :, None] * x[:, None, :]
    d = f.create_dataset("csd", data=1e-18 * csd)
    d.attrs["units"] = np.bytes_(b"rad^2/Hz")
    f.attrs["axes"] = np.array([b"E", b"N"])

# measured_h5_bytes: read_measured_input on an observable series (tiltnoise simulate's layout).
with h5py.File(path("measured_h5_bytes", "observables.h5"), "w") as f:
    vlen(f, "schema", "tiltnoise.observable_series")
    f.attrs["sample_rate_hz"] = 4.0
    for name, unit in (("X", "m"), ("phi", "rad"), ("phi_a", "rad")):
        d = f.create_dataset(name, data=1e-8 * RNG.standard_normal(16))
        vlen(d, "units", unit)
    f.create_dataset("time_s", data=np.arange(16) / 4.0)


# tilt_h5_bytes/regressions: series_angle.h5 with the size of its global heap's free-space
# object set to 0. Unpatched HDF5 decodes that heap forever; the vendored library refuses it
# (vendor/README.md), and the test a_global_heap_with_an_empty_free_space_object_is_refused
# replays it under a time bound.
def zero_free_space(src, dst):
    import struct
    data = bytearray(open(src, "rb").read())
    base = data.find(b"GCOL")
    end = base + struct.unpack_from("<Q", data, base + 8)[0]
    p = base + 16
    while p + 16 <= end:
        index, size = struct.unpack_from("<H", data, p)[0], struct.unpack_from("<Q", data, p + 8)[0]
        if index == 0:
            struct.pack_into("<Q", data, p + 8, 0)
            break
        p += 16 + (size + 7) // 8 * 8
    with open(dst, "wb") as f:
        f.write(data)


zero_free_space(path("tilt_h5_bytes", "series_angle.h5"),
                path("tilt_h5_bytes/regressions", "global_heap_free_space_of_size_0.h5"))

# miniSEED: the synthetic fixtures of the reader (written with ObsPy by
# tests/fixtures/input/miniseed/make_miniseed_fixtures.py).
for name in ("gap_overlap.mseed", "little_endian.mseed"):
    shutil.copy(os.path.join(ROOT, "tests/fixtures/input/miniseed", name), path("miniseed", name))
