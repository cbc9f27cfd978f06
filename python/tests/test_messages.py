"""The same mistake gives the same message from Python as from the command line: both call the
library's checks, which name the option as each front end spells it (`--input` / `inputs`,
`--segment-duration 14400` / `segment_duration=14400`). Each case runs the command line, maps its
option names to the keywords, and compares the whole message."""

import numpy as np
import pytest

import tiltnoise
from conftest import LAB_TILT, REPO

SPECTRA = REPO / "tilt_data" / "peterson_tilt_asd.csv"


def as_keywords(message, *pairs):
    for flag, keyword in pairs:
        message = message.replace(flag, keyword)
    return message


def python_message(call):
    with pytest.raises(ValueError) as e:
        call()
    return str(e.value)


@pytest.fixture(scope="module")
def model():
    return tiltnoise.Model()


@pytest.mark.parametrize(
    "cli_args, call, pairs",
    [
        (["tf", "--input", "F_c.x"], lambda m: m.transfer(1e-3, inputs="F_c.x"),
         [("--input", "inputs")]),
        (["tf", "--input", "tilt,eta_t"], lambda m: m.transfer(1e-3, inputs="tilt,eta_t"),
         [("--input", "inputs")]),
        (["tf", "--input", "F_b.x,,M_b.z"], lambda m: m.transfer(1e-3, inputs="F_b.x,,M_b.z"),
         [("--input", "inputs")]),
        (["tf", "--observables", "x"], lambda m: m.transfer(1e-3, outputs=["x"]),
         [("--observables", "outputs")]),
        (["tf", "--observables", "phi,phi"],
         lambda m: m.transfer(1e-3, outputs=["phi", "phi"]),
         [("--observables", "outputs")]),
        (["simulate", "--duration", "10", "--nperseg", "128"],
         lambda m: m.simulate(10, nperseg=128),
         [("--duration", "duration"), ("--step", "step"), ("--nperseg", "nperseg")]),
        (["simulate", "--step", "0"], lambda m: m.simulate(step=0.0), [("--step", "step")]),
        (["simulate", "--init", "phi_c=1"], lambda m: m.simulate(init={"phi_c": 1}),
         [("--init", "init")]),
        (["simulate", "--init-rate", "delta_b=inf"],
         lambda m: m.simulate(init_rate="delta_b=inf"), [("--init-rate", "init_rate")]),
        (["simulate", "--init", "phi_b=0"], lambda m: m.simulate(init={"phi_b": 0.0}),
         [("--init-rate", "init_rate"), ("--init", "init")]),
        (["simulate", "--kick-x", "0"], lambda m: m.simulate(kick_x=0.0),
         [("--kick-x", "kick_x")]),
        (["simulate", "--mode-energy", "-1"], lambda m: m.simulate(mode_energy=-1.0),
         [("--mode-energy", "mode_energy")]),
        (["simulate", "--readout", "theta=-1"],
         lambda m: m.simulate(readout={"theta": -1.0}), [("--readout", "readout")]),
    ],
)
def test_model_messages_equal_the_command_lines(model, cli_error, cli_args, call, pairs):
    assert python_message(lambda: call(model)) == as_keywords(cli_error(*cli_args), *pairs)


@pytest.mark.parametrize(
    "cli_args, kwargs, pairs",
    [
        (["--tilt", LAB_TILT, "--readout", "q=1e-9"], dict(readout={"q": 1e-9}),
         [("--readout", "readout")]),
        (["--tilt", LAB_TILT, "--percentiles", "10,90"], dict(percentiles=(10, 90)),
         [("--segment-duration 14400", "segment_duration=14400"),
          ("--nperseg 4096", "nperseg=4096"),
          ("--segment-duration", "segment_duration"), ("--percentiles", "percentiles")]),
        (["--tilt", SPECTRA, "--overlap", "0.25"], dict(overlap=0.25),
         [("--overlap", "overlap"), ("--freq", "freq")]),
        (["--tilt", SPECTRA, "--gaps", "interpolate"], dict(gaps="interpolate"),
         [("--gaps", "gaps"), ("--freq", "freq")]),
        (["--tilt", LAB_TILT, "--freq", "1e-3:10:1e-1"], dict(freq="1e-3:10:1e-1"),
         [("--freq", "freq"), ("--nperseg", "nperseg")]),
    ],
)
def test_budget_messages_equal_the_command_lines(cli_error, cli_args, kwargs, pairs):
    path = cli_args[1]
    got = python_message(lambda: tiltnoise.budget_from_file(path, **kwargs))
    assert got == as_keywords(cli_error("budget", *cli_args), *pairs)


def test_readout_of_an_observable_not_budgeted(cli_error):
    # Both front ends budget any observable, and say how to add one.
    message = python_message(
        lambda: tiltnoise.budget_from_file(LAB_TILT, readout={"theta": 1e-9}))
    expected = as_keywords(
        cli_error("budget", "--tilt", LAB_TILT, "--readout", "theta=1e-9"),
        ("--readout", "readout"), ("--observables", "observables"))
    assert message == expected
    assert message == ("readout theta=1e-9: theta is not budgeted; allowed: X, phi, phi_a "
                       "(add it with observables)")


def test_percentile_order_message_names_the_value():
    x = np.zeros(10_000)
    message = python_message(lambda: tiltnoise.budget(
        {"eta_t": x}, 1.0, segment_duration=2000, percentiles=(90, 10)))
    assert message == ("percentiles (90, 10): expected (LOWER, UPPER) with "
                       "0 <= LOWER < UPPER <= 100")


@pytest.mark.parametrize(
    "call, start",
    [
        (lambda: tiltnoise.Params().set("length.hh", 1.0), "Params.set length.hh=1.0: "),
        (lambda: tiltnoise.budget({"eta_t": np.zeros(10_000)}, 1.0, percentiles=(10, 90)),
         "percentiles applies to the per-segment band and needs segment_duration (e.g. "
         "segment_duration=14400 with nperseg=4096"),
    ],
)
def test_messages_spell_options_as_python_does(call, start):
    # The library names the option by its key; Python spells it as a keyword (or the method
    # that takes it), never as a command-line flag.
    message = python_message(call)
    assert message.startswith(start) and "--" not in message, message
