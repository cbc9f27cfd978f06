"""TransferFunction.save and Model.save_methods: the files of the command line's `tf --save`
and `methods --save` from Python, through the same job functions."""

import re
import struct

import numpy as np
import pytest

import tiltnoise

from conftest import without_command_line

# A grid that both front ends read to the same bits: repr() round-trips every float.
FREQS = np.logspace(-3, 1, 60)
FIGURES = ("png", "svg")


def _assert_same_figure(mine, theirs):
    """Python's SVG and the command line's are the same, but for the caption of a figure that
    leaves computed observables out: it names the option that chooses the panels as the front
    end that drew it spells it (`observables`, `--plot-observables`), and wraps accordingly.
    That caption is drawn last."""
    caption = "Not drawn (in the files)"
    if caption not in theirs:
        assert mine == theirs
        return
    head, tail = mine.split(caption, 1)
    their_head, their_tail = theirs.split(caption, 1)
    assert head == their_head

    def words(svg):
        return " ".join(re.sub(r"<[^>]*>", " ", svg).split())

    assert words(tail).replace("; observables chooses", "; --plot-observables chooses") == (
        words(their_tail))


def _freq_file(tmp_path):
    path = tmp_path / "freqs.txt"
    path.write_text("".join(f"{float(f)!r}\n" for f in FREQS))
    return path


def _cli_tf(cli, tmp_path, saves, *options):
    args = ["tf", "--freq-file", _freq_file(tmp_path), *options]
    cli(*args, *[a for p in saves for a in ("--save", p)])


@pytest.mark.parametrize(
    "request_kwargs, options",
    [
        ({}, []),
        ({"inputs": ["eta_t", "M_b.z"], "outputs": ["X", "phi"]},
         ["--input", "eta_t,M_b.z", "--observables", "X,phi"]),
    ],
    ids=["figure5", "named"],
)
def test_tf_save_writes_the_command_lines_files(cli, tmp_path, request_kwargs, options):
    theirs = {ext: tmp_path / f"cli.{ext}" for ext in ("csv", *FIGURES)}
    _cli_tf(cli, tmp_path, theirs.values(), *options)
    tf = tiltnoise.Model().transfer_function(FREQS, **request_kwargs)
    for ext, path in theirs.items():
        mine = tmp_path / f"mine.{ext}"
        tf.save(mine)
        if ext == "csv":
            assert without_command_line(mine.read_text()) == without_command_line(
                path.read_text())
        elif ext == "svg":
            _assert_same_figure(mine.read_text(), path.read_text())
        elif "outputs" in request_kwargs:  # every observable drawn: no caption naming one
            assert mine.read_bytes() == path.read_bytes(), ext
        else:
            assert _png_size(mine.read_bytes()) == _png_size(path.read_bytes())


def test_tf_save_draws_the_chosen_observables_with_phase(cli, tmp_path):
    theirs = tmp_path / "cli.svg"
    _cli_tf(cli, tmp_path, [theirs], "--observables", "X,Y,phi", "--plot-observables", "Y",
            "--phase")
    tf = tiltnoise.Model().transfer_function(FREQS, outputs="X,Y,phi")
    mine = tmp_path / "mine.svg"
    tf.save(mine, observables=["Y"], phase=True)
    _assert_same_figure(mine.read_text(), theirs.read_text())


def test_tf_save_hdf5_equals_the_command_lines(cli, tmp_path):
    h5py = pytest.importorskip("h5py")
    theirs, mine = tmp_path / "cli.h5", tmp_path / "mine.h5"
    _cli_tf(cli, tmp_path, [theirs], "--input", "ground")
    tf = tiltnoise.Model().transfer_function(FREQS, inputs="ground")
    tf.save(mine)
    with h5py.File(theirs, "r") as a, h5py.File(mine, "r") as b:
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert names
        for name in names:
            np.testing.assert_array_equal(a[name][()], b[name][()], err_msg=name)
        assert set(a.attrs) == set(b.attrs)
        for key in a.attrs:
            if key != "created_by":
                np.testing.assert_array_equal(a.attrs[key], b.attrs[key], err_msg=key)


def test_tf_save_after_pickling_and_refusals(tmp_path):
    import pickle

    tf = tiltnoise.Model().transfer_function(FREQS[:5], outputs="X")
    back = pickle.loads(pickle.dumps(tf))
    assert back == tf
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    tf.save(a)
    back.save(b)
    assert a.read_text() == b.read_text()
    with pytest.raises(ValueError, match="phi"):
        tf.save(tmp_path / "c.png", observables=["phi"])
    with pytest.raises(ValueError):
        tf.save(tmp_path / "c.txt")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "b.csv"]
    by_hand = tiltnoise.TransferFunction(tf.freq_hz, tf.values, tf.inputs, tf.outputs,
                                         tf.input_units, tf.output_units)
    with pytest.raises(TypeError, match="Model.transfer_function"):
        by_hand.save(tmp_path / "d.csv")


def _words(svg_text):
    """The SVG's text elements that are not numbers: the title, the axis labels, the methods'
    names (the tick labels and the points' places follow the measured times, which differ
    from run to run)."""
    texts = (t.strip() for t in re.findall(r"<text[^>]*>([^<]*)</text>", svg_text))
    return sorted(re.sub(r"[0-9.]+ ns", "TIME ns", t) for t in texts
                  if re.search(r"[A-Za-z]{2}", t))


def _png_size(data):
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def test_save_methods_draws_the_command_lines_chart(cli, tmp_path):
    theirs = {ext: tmp_path / f"cli.{ext}" for ext in FIGURES}
    cli("methods", "--freq", "1e-2:2:1", "--input", "eta_t",
        *[a for p in theirs.values() for a in ("--save", p)])
    model = tiltnoise.Model()
    mine = {ext: tmp_path / f"mine.{ext}" for ext in FIGURES}
    for path in mine.values():
        model.save_methods(path, [1e-2, 1.0], inputs="eta_t")
    words = _words(mine["svg"].read_text())
    assert "Speed against accuracy, 7x1 matrix from eta_t, 2 points, 1e-2 to 1e0 Hz" in words
    assert words == _words(theirs["svg"].read_text())
    assert _png_size(mine["png"].read_bytes()) == _png_size(theirs["png"].read_bytes())
    with pytest.raises(ValueError):
        model.save_methods(tmp_path / "m.csv", [1e-2, 1.0])
    assert not (tmp_path / "m.csv").exists()
