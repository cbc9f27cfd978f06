"""tiltnoise.Model: modes and transfer functions equal to the command line's, physics limits,
the matrices, the Monte Carlo, and errors."""

import json

import numpy as np
import pytest

import tiltnoise

TILT = ["theta_t", "eta_t", "phi_t"]
OBSERVABLES = ["X", "Y", "Z", "theta", "eta", "phi", "phi_a"]


@pytest.fixture(scope="module")
def model():
    return tiltnoise.Model()


def read_tf_csv(path):
    """`tiltnoise tf --save tf.csv` as (freq, H[n_freq, n_entries], entry names)."""
    with open(path) as fh:
        lines = fh.read().splitlines()
    at = next(i for i, l in enumerate(lines) if not l.startswith("#"))
    header = lines[at].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=at + 1, ndmin=2)
    return data[:, 0], data[:, 1::2] + 1j * data[:, 2::2], [n[: -len(".re")] for n in header[1::2]]


def test_low_frequency_limit_of_x_per_eta_t(model):
    """X -> -eta_t (Z + Z_b + h_c) as f -> 0 (section IV.B): -1.664 m/rad for Table I. At 0 Hz
    exactly, to the rounding of the three lengths' sum (a few eps); above it the quasi-static
    response departs as f**2 (the next term of the expansion in w**2), so the deviation at
    1e-5 Hz is 100 times that at 1e-6 Hz."""
    p = model.params
    lever = p.get("length.z_m") + p.get("length.z_b_m") + p.get("length.h_c_m")
    eps = np.finfo(float).eps
    h = model.transfer([0.0, 1e-6, 1e-5], inputs="eta_t", outputs="X")
    assert h.shape == (3, 1, 1) and h.dtype == np.complex128
    assert lever == pytest.approx(1.664, abs=1e-12)
    assert abs(h[0, 0, 0] + lever) <= 4 * eps * lever and h[0, 0, 0].imag == 0
    dev = (h[1:, 0, 0].real + lever) / lever
    assert dev[1] / dev[0] == pytest.approx(100, rel=1e-2)
    # Y -> +theta_t (Z + Z_b + h_c), and X does not see theta_t at all.
    h = model.transfer(0.0, inputs=["theta_t"], outputs=["Y", "X"])
    assert abs(h[0, 0, 0] - lever) <= 4 * eps * lever and h[0, 1, 0] == 0


def test_modes_equal_the_command_lines(model, cli):
    expected = json.loads(cli("modes", "--format", "json"))["modes"]
    got = model.modes()
    assert len(got) == len(expected) == 8
    for m, e in zip(got, expected):
        assert m.index == e["index"] and m.block == e["block"]
        assert m.frequency_hz == e["frequency_hz"]
        assert m.omega_sq_rad2_per_s2 == e["omega_sq_rad2_per_s2"]
        # JSON has no infinity: an undamped mode's Q is null there, with "undamped": true.
        assert m.q == float("inf") and e["quality_factor"] is None and e["undamped"]
        assert m.seen_by == e["seen_by"]
        assert m.dominant_coordinates == [
            (d["coordinate"], d["energy_share"]) for d in e["dominant_coordinates"]
        ]
        assert m.observable_amplitude == e["observable_amplitude"]
        assert abs(sum(m.energy_share.values()) - 1) < 1e-12


def test_damped_modes_have_the_command_lines_q(cli):
    params = tiltnoise.Params().set("loss.torsion_b_rad", 1e-3)
    expected = json.loads(cli("--set", "loss.torsion_b_rad=1e-3", "modes", "--format", "json"))
    q = [m.q for m in tiltnoise.Model(params).modes()]
    assert q == [float("inf") if e["undamped"] else e["quality_factor"]
                 for e in expected["modes"]]
    assert q[1] == pytest.approx(1e3, rel=1e-2)


@pytest.mark.parametrize(
    "inputs, method",
    [("tilt", "auto"), ("F_b.x,M_b.z,F_a.y", "auto"), ("tilt", "split"), ("M_b.z", "direct")],
)
def test_transfer_equals_the_command_lines_file(model, cli, tmp_path, inputs, method):
    f = np.concatenate([[0.0], np.logspace(-5, 2, 301)])
    grid = tmp_path / "grid.txt"
    grid.write_text("".join(f"{float(x)!r}\n" for x in f))
    out = tmp_path / "tf.csv"
    cli("tf", "--freq-file", grid, "--input", inputs, "--method", method, "--save", out)
    freq, h_cli, names = read_tf_csv(out)
    h = model.transfer(f, inputs=inputs, method=method)
    assert np.array_equal(freq, f)
    ins = [n for n in inputs.split(",")] if inputs != "tilt" else TILT
    assert names == [f"{o}.{i}" for o in OBSERVABLES for i in ins]
    assert h.shape == (len(f), 7, len(ins))
    np.testing.assert_array_equal(h.reshape(len(f), -1), h_cli)


def test_transfer_order_threads_and_out(model):
    f = np.logspace(-4, 1.5, 20_000)
    h = model.transfer(f)
    swapped = model.transfer(f, inputs=["phi_t", "theta_t"], outputs=("phi_a", "X"))
    np.testing.assert_array_equal(swapped[:, 0, 0], h[:, 6, 2])
    np.testing.assert_array_equal(swapped[:, 1, 1], h[:, 0, 0])
    one = model.transfer(f, threads=1)
    np.testing.assert_array_equal(one, h)
    out = np.empty_like(h)
    assert model.transfer(f, out=out) is out
    np.testing.assert_array_equal(out, h)
    with pytest.raises(ValueError, match="out: shape"):
        model.transfer(f[:10], out=out)


def test_matrices_rebuild_the_transfer_functions(model):
    """H = C (K - w^2 M)^-1 (G0 + w^2 G2) in NumPy, away from the resonances, where the direct
    solve in f64 is accurate."""
    m = model.matrices()
    assert m["M"].shape == (8, 8) and m["G0"].shape == (8, 3) and m["C"].shape == (7, 8)
    assert m["observables"] == OBSERVABLES and m["tilt_inputs"] == TILT
    f = np.array([3e-3, 0.05, 0.3, 2.0, 30.0])
    w2 = (2 * np.pi * f) ** 2
    d = m["K"] + 1j * m["K_imag"] - w2[:, None, None] * m["M"]
    g = m["G0"] + w2[:, None, None] * m["G2"]
    h_np = m["C"] @ np.linalg.solve(d, g.astype(complex))
    h = model.transfer(f)
    scale = np.abs(h).max(axis=0, keepdims=True)
    np.testing.assert_allclose(h_np, h, rtol=0, atol=1e-9 * scale.max())
    forces = model.transfer(f, inputs="forces")
    h_np = m["C"] @ np.linalg.solve(d, np.broadcast_to(m["F"], (len(f), 8, 12)).astype(complex))
    np.testing.assert_allclose(h_np, forces, rtol=1e-8, atol=1e-12 * np.abs(forces).max())


def test_floor_translation_is_the_apparent_force_and_acts_as_tilt(model):
    """The translation columns are C D^-1 (w^2 G2_translation) in NumPy; per unit floor
    acceleration they tend to the tilt's static response per g (eta_t = a_x / g,
    theta_t = -a_y / g) as f -> 0."""
    m = model.matrices()
    assert m["translation_inputs"] == ["x_t", "y_t", "z_t"]
    assert m["G2_translation"].shape == (8, 3)
    f = np.array([3e-3, 0.05, 0.3, 2.0, 30.0])
    w2 = (2 * np.pi * f) ** 2
    d = m["K"] + 1j * m["K_imag"] - w2[:, None, None] * m["M"]
    g = w2[:, None, None] * m["G2_translation"]
    h_np = m["C"] @ np.linalg.solve(d, np.broadcast_to(g, (len(f), 8, 3)).astype(complex))
    h = model.transfer(f, inputs="translation")
    np.testing.assert_allclose(h_np, h, rtol=0, atol=1e-9 * np.abs(h).max())
    ground = model.transfer(f, inputs="ground")
    np.testing.assert_array_equal(ground[:, :, 3:], h)
    low = 1e-6
    per_acceleration = model.transfer(low, inputs="x_t,y_t", outputs="X,Y")[0] / -(
        (2 * np.pi * low) ** 2
    )
    static = model.transfer(0.0, inputs="eta_t,theta_t", outputs="X,Y")[0]
    g_earth = model.params.get("environment.g_m_per_s2")
    np.testing.assert_allclose(per_acceleration[0, 0], static[0, 0] / g_earth, rtol=1e-6)
    np.testing.assert_allclose(per_acceleration[1, 1], -static[1, 1] / g_earth, rtol=1e-6)


def test_monte_carlo_equals_the_command_lines(model, cli):
    expected = json.loads(cli("mc", "--samples", 300, "--seed", 7, "--format", "json"))
    got = model.monte_carlo(samples=300, seed=7, threads=1)
    assert (got.samples, got.rejected) == (expected["samples"], expected["rejected"])
    assert got.mean_hz == [m["mean_hz"] for m in expected["modes"]]
    assert got.std_hz == [m["std_hz"] for m in expected["modes"]]
    assert got.freqs_hz.shape == (300 - got.rejected, 8)
    again = model.monte_carlo(samples=300, seed=7, threads=2)
    np.testing.assert_array_equal(again.freqs_hz, got.freqs_hz)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"inputs": "F_c.x"}, ["unknown input", "F_c.x", "M_b.z", "theta_t"]),
        ({"inputs": "tilt,eta_t"}, ["eta_t is given twice"]),
        ({"inputs": ""}, ["inputs \"\": empty name in the list"]),
        ({"inputs": []}, ["inputs: an empty sequence names nothing"]),
        ({"outputs": "x"}, ["unknown observable", "phi_a"]),
        ({"method": "fast"}, ["unknown method", "polezero"]),
        ({"rel_tol": 0.0}, ["rel_tol", "(0, 1)"]),
        ({"method": "torsion2"}, ["torsion2", "theta_t"]),
    ],
)
def test_bad_requests_raise_value_error_naming_the_item(model, kwargs, words):
    with pytest.raises(ValueError) as e:
        model.transfer([1e-3, 1e-2], **kwargs)
    for w in words:
        assert w in str(e.value)


def test_bad_frequencies_and_resonances_raise_value_error(model):
    with pytest.raises(ValueError, match=r"frequency -1 Hz .* must be finite and >= 0"):
        model.transfer([1e-3, -1.0])
    with pytest.raises(ValueError, match="finite"):
        model.transfer(np.nan)
    with pytest.raises(ValueError, match="1-D"):
        model.transfer(np.ones((2, 2)))
    nu_1 = model.modes()[0].frequency_hz
    with pytest.raises(ValueError, match="singular"):
        model.transfer([1e-3, nu_1], method="direct")


def test_explain_names_the_pick(model):
    text = model.explain(np.logspace(-5, 2, 100))
    assert "picked `polezero`" in text


def test_fit_equals_the_command_lines(model, cli):
    expected = json.loads(cli("fit", "--format", "json"))
    got = model.fit()
    for name in ("chi2", "chi2_nominal", "dof", "iterations", "evaluations", "stop",
                 "prior_term", "projected_gradient", "singular_values"):
        assert getattr(got, name) == expected[name], name
    assert got.measured_origin == expected["measured_origin"]
    assert got.parameters == expected["parameters"]
    assert got.modes == expected["modes"]
    assert got.params.to_toml() == expected["fitted_params_toml"]


def test_fit_to_visibilities_equals_the_command_lines(cli, tmp_path):
    # nu_6 seen in Y and Z (forbidden by the mirror plane of the symmetric pendulum) and nu_2 in
    # Y: a test-mass offset along x explains them; its prior error bar 1 mm.
    params = tmp_path / "p.toml"
    params.write_text(cli("params")
                      + '\n[uncertainty]\n"asymmetry.tm_com_x_m" = { sigma = 1e-3 }\n')
    vis = tmp_path / "vis.csv"
    vis.write_text("mode,observable,reference,ratio,sigma\n"
                   "6,Y,X,1.2e-3,1e-4\n6,Z,X,-7.5e-4,1e-4\n2,Y,X,1.6,0.1\n")
    args = ("fit", "--visibility", str(vis), "--free", "asymmetry.tm_com_x_m",
            "--bound-sigmas", "3", "--format", "json")
    expected = json.loads(cli("--params", str(params), *args))
    got = tiltnoise.Model(tiltnoise.Params.from_toml(params)).fit(
        free=["asymmetry.tm_com_x_m"], visibility=vis, bound_sigmas=3.0)
    assert got.parameters == expected["parameters"]
    assert got.visibilities == expected["visibilities"]
    assert got.modes == expected["modes"] == []
    assert got.chi2 == expected["chi2"] and got.dof == expected["dof"]
    assert got.measured_origin == expected["measured_origin"]
    # The offset is found, on the side the signs of the ratios say.
    offset = next(p for p in got.parameters if p["key"] == "asymmetry.tm_com_x_m")
    assert offset["fitted"] != 0.0


def test_fit_errors(model, tmp_path):
    with pytest.raises(ValueError, match="unknown parameter key `length.hh`"):
        model.fit(free=["length.hh"])
    bad = tmp_path / "modes.csv"
    bad.write_text("mode,frequency_hz\n9,1.0\n")
    with pytest.raises(tiltnoise.InputFileError, match="modes.csv"):
        model.fit(measured=bad)
    vis = tmp_path / "vis.csv"
    vis.write_text("mode,observable,reference,ratio\n6,Y,Q,1e-3\n")
    with pytest.raises(tiltnoise.InputFileError, match="vis.csv"):
        model.fit(visibility=vis)


def test_repeated_calls_on_other_grids_give_a_new_models_values():
    # A model keeps its frequency buffer between calls: grids of other lengths and kinds
    # (shorter, longer, unsorted with 0 Hz, a number, a list) give the values a new model gives.
    model = tiltnoise.Model()
    long = np.logspace(-5, 2, 20_000)
    grids = [long, long[:7], np.array([5.0, 0.0, 1e-3, 0.2]), 0.01, [1e-4, 3.0], long]
    for f in grids:
        got = model.transfer(f)
        want = tiltnoise.Model().transfer(f)
        assert got.shape == want.shape
        assert np.array_equal(got.view(np.float64), want.view(np.float64)), f


def test_threads_sharing_models_get_their_own_grids():
    # Each calling thread keeps its own frequency buffer: threads calling the same models on
    # grids of different lengths at once get the values of a single call.
    import threading

    f = np.logspace(-5, 2, 30_000)
    want = tiltnoise.Model().transfer(f)
    models = [tiltnoise.Model(), tiltnoise.Model()]
    wrong = []

    def work(i):
        for k in range(10):
            g = f if (i + k) % 2 == 0 else f[:777]
            if not np.array_equal(models[i % 2].transfer(g), want[: len(g)]):
                wrong.append((i, k))

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert wrong == []


def test_the_pendulum_as_built_equals_the_command_line(cli):
    """An [asymmetry] offset through Params: the rest configuration, the mode labels, overlaps
    and amplitude ratios are the command line's (the test mass's centre of mass 1 mm off along
    x tilts it by atan(1 mm / (Z_b + delta_b)) and lights nu_6 in Z)."""
    p = tiltnoise.Params().set("asymmetry.tm_com_x_m", 1e-3)
    model = tiltnoise.Model(p)
    expected = json.loads(cli("--set", "asymmetry.tm_com_x_m=1e-3", "modes", "--format", "json"))
    q0 = model.matrices()["q0"]
    coords = model.matrices()["coordinates"]
    assert [q0[coords.index(c)] for c in coords] == [
        expected["rest_configuration"][c] for c in coords
    ]
    assert q0[coords.index("eta_b")] == pytest.approx(1.3157887e-3, rel=1e-7)
    for m, e in zip(model.modes(), expected["modes"]):
        assert (m.index, m.block, m.overlap) == (e["index"], e["block"], e["overlap"])
        assert m.ratio == e["ratio"] and m.seen_above_ratio == e["seen_above_ratio"]
    nu6 = next(m for m in model.modes() if m.index == 6)
    assert nu6.block == "coupled" and "Z" in nu6.seen_above_ratio


def test_auto_next_to_a_mode_says_what_to_do_in_each_spelling(model, cli_error):
    """The planner's refusal comes from one job under both front ends, each naming its own
    options: `--method polezero` and `--freq` on the command line, `method=polezero` and
    `freq_hz` here."""
    with pytest.raises(ValueError) as e:
        model.transfer(0.415, inputs="eta_t", outputs="X")
    assert str(e.value).endswith("(method=polezero, or another freq_hz)")
    message = cli_error("tf", "--freq", "0.415", "--input", "eta_t", "--observables", "X")
    assert message.endswith("(--method polezero, or another --freq)")
    assert message.split(" (--method")[0] == str(e.value).split(" (method=")[0]


def test_methods_equals_the_command_lines(model, cli):
    """`Model.methods` runs the command line's `methods` job: the same matrix, pick and
    accuracy (the times per point are measured anew)."""
    expected = json.loads(cli("methods", "--freq", "1e-3:30:10", "--format", "json"))
    got = model.methods(np.logspace(-3, 1, 30))
    assert got["auto"] == expected["auto"]
    assert got["target_rel_err"] == expected["target_rel_err"]
    assert got["matrix"] == "7x3 tilt matrix"
    for g, x in zip(got["methods"], expected["methods"], strict=True):
        assert g["name"] == x["name"]
        assert g["unusable"] == x["unusable"]
        assert g["exact_zeros"] == x["exact_zeros"]
    with pytest.raises(ValueError, match="freq_hz"):
        model.methods([1e-3, 0.0])
