"""tiltnoise.Params: Table I, TOML, overrides, and errors that name the key."""

import pickle

import pytest

import tiltnoise


def test_default_is_the_command_lines_table_i(cli):
    assert tiltnoise.Params().to_toml() == cli("params")


def test_set_returns_a_new_validated_set_and_leaves_self_alone(cli):
    p = tiltnoise.Params()
    q = p.set("length.h_m", 1.5)
    assert q.get("length.h_m") == 1.5 and p.get("length.h_m") == 2.0
    assert q != p and p == tiltnoise.Params()
    assert q.to_toml() == cli("--set", "length.h_m=1.5", "params")
    assert q.update({"length.h_m": 2.0}) == p
    assert repr(q) == "Params(Table I with length.h_m=1.5)"


def test_toml_round_trip_text_path_and_pickle(tmp_path):
    p = tiltnoise.Params().update({"loss.torsion_b_rad": 1e-3, "inertia.a23_kg_m2": -8e-3})
    assert tiltnoise.Params.from_toml(p.to_toml()) == p
    f = tmp_path / "pendulum.toml"
    f.write_text(p.to_toml())
    assert tiltnoise.Params.from_toml(f) == p
    assert tiltnoise.Params.from_toml(str(f)) == p
    assert pickle.loads(pickle.dumps(p)) == p


def test_keys_list_key_value_unit_and_rule():
    keys = tiltnoise.Params().keys()
    assert keys[0] == ("mass.m_a_kg", 1.2, "kg", "finite and > 0")
    by_key = {k: (v, unit, rule) for k, v, unit, rule in keys}
    assert by_key["length.h_m"][:2] == (2.0, "m")
    assert set(tiltnoise.Params().to_dict()) == set(by_key)


@pytest.mark.parametrize(
    "key, value, words",
    [
        ("length.h_m", -1.0, ["length.h_m", "-1 m", "> 0"]),
        ("inertia.b33_kg_m2", -1e-5, ["inertia.b33_kg_m2", "kg m^2", "> 0"]),
        ("loss.torsion_b_rad", 1.5, ["loss.torsion_b_rad", "< 1"]),
        ("length.hh", 1.0, ["unknown key `length.hh`", "length.h_m"]),
        ("mass.m_b_kg", float("nan"), ["mass.m_b_kg", "NaN"]),
    ],
)
def test_bad_values_raise_value_error_naming_the_key(key, value, words):
    with pytest.raises(ValueError) as e:
        tiltnoise.Params().set(key, value)
    for w in words:
        assert w in str(e.value)


def test_file_errors_are_os_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="cannot read parameter file"):
        tiltnoise.Params.from_toml(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text(tiltnoise.Params().to_toml().replace("m_b_kg = 0.11", "m_c_kg = 0.11"))
    with pytest.raises(tiltnoise.InputFileError, match="m_c_kg") as e:
        tiltnoise.Params.from_toml(bad)
    assert isinstance(e.value, OSError) and str(bad) in str(e.value)
    with pytest.raises(ValueError, match="m_c_kg"):
        tiltnoise.Params.from_toml(bad.read_text())


def test_unstable_pendulum_is_refused_by_the_model():
    with pytest.raises(ValueError, match="phi_a"):
        tiltnoise.Model(tiltnoise.Params().set("torsion.k_a_n_m_per_rad", 1e-30))
