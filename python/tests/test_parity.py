"""Every command of the command line has its Python call, and every command that saves files
has a Python result that saves them: the commands are read from the binary's own help, so a
command added without its Python counterpart fails here."""

import re

import pytest

import tiltnoise

# Command -> its Python call (a dotted name in the tiltnoise package).
PYTHON_CALL = {
    "params": "Params.to_toml",
    "modes": "Model.modes",
    "tf": "Model.transfer_function",
    "budget": "budget_from_file",
    "coherence": "coherence",
    "simulate": "Model.simulate",
    "subtract": "subtract",
    "fit": "Model.fit",
    "visibility": "visibility",
    "mc": "Model.monte_carlo",
    "methods": "Model.methods",
}

# Command with `--save` -> the Python call that writes its files (a dotted name).
PYTHON_SAVE = {
    "budget": "Budget.save",
    "coherence": "Coherence.save",
    "simulate": "Simulation.save",
    "subtract": "Subtraction.save",
    "fit": "Fit.save",
    "visibility": "Visibilities.save",
    "mc": "MonteCarlo.save",
    "tf": "TransferFunction.save",
    "methods": "Model.save_methods",
}


def _commands(cli):
    """The subcommands `tiltnoise --help` lists (clap's `Commands:` section), `help` left out."""
    text = cli("--help")
    section = text.split("Commands:\n", 1)[1].split("\n\n", 1)[0]
    names = [m.group(1) for m in re.finditer(r"^  (\S+)", section, re.MULTILINE)]
    assert names, text
    return [n for n in names if n != "help"]


def _resolve(dotted):
    obj = tiltnoise
    for part in dotted.split("."):
        obj = getattr(obj, part)
    return obj


def test_every_command_has_a_python_call(cli):
    commands = _commands(cli)
    missing = sorted(set(commands) - set(PYTHON_CALL))
    assert not missing, f"commands without a Python call in PYTHON_CALL: {missing}"
    stale = sorted(set(PYTHON_CALL) - set(commands))
    assert not stale, f"PYTHON_CALL names commands the command line no longer has: {stale}"


@pytest.mark.parametrize("command", sorted(PYTHON_CALL))
def test_the_python_call_exists(command):
    assert callable(_resolve(PYTHON_CALL[command])), PYTHON_CALL[command]


def test_every_command_that_saves_has_a_python_save(cli):
    saving = {c for c in _commands(cli) if "--save" in cli(c, "--help")}
    assert saving == set(PYTHON_SAVE), sorted(saving ^ set(PYTHON_SAVE))
    for command, name in PYTHON_SAVE.items():
        assert callable(_resolve(name)), f"{name} ({command})"
