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

# Command with `--save` -> the class of its Python result, whose `save` writes the files.
PYTHON_SAVE = {
    "budget": "Budget",
    "coherence": "Coherence",
    "simulate": "Simulation",
    "subtract": "Subtraction",
    "fit": "Fit",
    "visibility": "Visibilities",
    "mc": "MonteCarlo",
}

# Commands whose `--save` Python does not have yet, each with what Python offers instead.
NO_PYTHON_SAVE = {
    "tf": "TransferFunction.to_gwpy()/to_pandas() hold the values; no HDF5/CSV/figure writer",
    "methods": "Model.methods returns the JSON report as a dict; no chart writer",
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
    unknown = sorted(saving - set(PYTHON_SAVE) - set(NO_PYTHON_SAVE))
    assert not unknown, f"commands with --save and no Python save: {unknown}"
    assert set(PYTHON_SAVE) <= saving, sorted(set(PYTHON_SAVE) - saving)
    for command, cls in PYTHON_SAVE.items():
        assert callable(getattr(_resolve(cls), "save", None)), f"{cls}.save ({command})"
    # A gap closed is taken off the list, so that the list says what is still missing.
    for command in NO_PYTHON_SAVE:
        assert command in saving, command
        result = {"tf": "TransferFunction", "methods": None}[command]
        assert result is None or not hasattr(_resolve(result), "save"), command
