"""animat.Config through Python: defaults, the dict view, attribute sections, TOML round
trips, and bad values / bad TOML as ValueError with messages naming file, line, key and expectation."""

import copy
import math
import pathlib

import numpy as np
import pytest

import animat

BAD = pathlib.Path(__file__).resolve().parent.parent / "bad_inputs"


def test_default_validates_and_has_paper_values():
    c = animat.Config()
    c.validate()
    assert c["grn.dt"] == 0.05
    assert c["genome.dimensions"] == 2
    assert c["genome.initial_units"] == 10
    assert c.grn.dt == 0.05
    assert c == animat.Config()
    assert c.hash() == animat.Config().hash()


def test_keys_len_iter_contains():
    c = animat.Config()
    keys = c.keys()
    assert len(keys) == len(set(keys)) == len(c)
    assert list(iter(c)) == keys
    for k in ("genome.dimensions", "grn.dt", "evolution.population", "scene.drag_normal", "physics.drag_scheme"):
        assert k in c
        assert k in keys
    assert "grn.dtt" not in c
    assert "grn" not in c


def test_item_get_set_with_types():
    c = animat.Config()
    c["evolution.population"] = 64
    assert c["evolution.population"] == 64 and isinstance(c["evolution.population"], int)
    c["scene.drag_normal"] = 3  # an int for a float key
    assert c["scene.drag_normal"] == 3.0 and isinstance(c["scene.drag_normal"], float)
    c["grn.dt"] = np.float64(0.025)
    assert c["grn.dt"] == 0.025
    c["evolution.population"] = np.int64(70)
    assert c["evolution.population"] == 70
    c["physics.drag_scheme"] = "explicit"
    assert c["physics.drag_scheme"] == "explicit"
    c["scene.effects"] = ["springs", "drag"]
    assert c["scene.effects"] == ["springs", "drag"]


@pytest.mark.parametrize(
    "key, value, fragments",
    [
        ("evolution.population", 2.5, ["evolution.population", "wrong type", "expected an integer"]),
        ("evolution.population", True, ["evolution.population", "wrong type"]),
        ("evolution.population", 0, ["evolution.population = 0", "out of range", "[2, 100000]"]),
        ("evolution.population", -5, ["evolution.population = -5", "out of range"]),
        ("grn.dt", 0.0, ["grn.dt", "out of range", "(0, 1]"]),
        ("grn.dt", -0.05, ["grn.dt", "(0, 1]"]),
        ("grn.dt", float("nan"), ["grn.dt", "finite"]),
        ("grn.dt", float("inf"), ["grn.dt", "finite"]),
        ("grn.dt", "0.05", ["grn.dt", "wrong type", "expected a number"]),
        ("physics.drag_scheme", "magic", ["physics.drag_scheme", "expected one of", "explicit", "stable"]),
        ("scene.effects", ["springs", "buoyancy"], ["scene.effects", "buoyancy"]),
        ("evolution.populaton", 5, ["unknown config key 'evolution.populaton'", "did you mean 'evolution.population'"]),
    ],
)
def test_bad_item_values_raise_value_error_naming_the_key(key, value, fragments):
    c = animat.Config()
    before = c.to_toml()
    with pytest.raises(ValueError) as e:
        c[key] = value
    for f in fragments:
        assert f in str(e.value), str(e.value)
    assert c.to_toml() == before, "a rejected value must not change the config"


def test_unknown_key_read():
    with pytest.raises(ValueError, match="unknown config key 'grn.dtt'"):
        animat.Config()["grn.dtt"]


def test_attribute_sections_are_live_views():
    c = animat.Config()
    assert c.scene.drag_normal == c["scene.drag_normal"]
    c.scene.drag_normal = 7.5
    assert c["scene.drag_normal"] == 7.5
    c["evolution.population"] = 40
    assert c.evolution.population == 40
    assert "drag_normal" in dir(c.scene)
    assert "dt" in dir(c.grn)
    with pytest.raises(ValueError, match="scene.drag_normal"):
        c.scene.drag_normal = -1.0
    assert c.scene.drag_normal == 7.5
    # The view stays valid while only the view is held.
    grn = animat.Config().grn
    assert grn.dt == 0.05


def test_attribute_section_missing_attribute_follows_python_protocol():
    # __getattr__ must raise AttributeError for a missing name, so that hasattr() and
    # getattr(obj, name, default) work.
    c = animat.Config()
    assert hasattr(c.scene, "drag_normal")
    assert not hasattr(c.scene, "no_such_key")
    assert getattr(c.grn, "no_such_key", "fallback") == "fallback"


def test_to_dict_nested_and_typed():
    d = animat.Config().to_dict()
    assert list(d) == [
        "genome",
        "mutation",
        "grn",
        "development",
        "body",
        "scene",
        "physics",
        "evaluation",
        "evolution",
        "control",
        "search",
    ]
    assert d["search"]["descriptors"] == ["elongation", "protrusions"]
    assert d["grn"]["dt"] == 0.05 and isinstance(d["grn"]["dt"], float)
    assert isinstance(d["evolution"]["population"], int)
    assert isinstance(d["physics"]["drag_scheme"], str)
    assert isinstance(d["scene"]["effects"], list)
    assert sum(len(v) for v in d.values()) == len(animat.Config().keys())


def test_construct_from_nested_and_flat_dicts():
    nested = animat.Config({"evolution": {"population": 50}, "grn": {"dt": 0.1}})
    flat = animat.Config({"evolution.population": 50, "grn.dt": 0.1})
    also = animat.Config.from_dict({"evolution": {"population": 50}, "grn.dt": 0.1})
    assert nested == flat == also
    assert nested["evolution.population"] == 50
    assert nested != animat.Config()
    # Full dict round trip.
    c = animat.Config()
    c["scene.drag_normal"] = 0.2
    assert animat.Config(c.to_dict()) == c


def test_update_and_dict_errors():
    c = animat.Config()
    c.update({"grn": {"dt": 0.02}, "evolution.seed": 9})
    assert c.grn.dt == 0.02 and c.evolution.seed == 9
    with pytest.raises(ValueError, match="genome.dimensons"):
        animat.Config({"genome": {"dimensons": 3}})
    with pytest.raises(ValueError, match="evolution.elites = 100 must be smaller than evolution.population"):
        animat.Config({"evolution": {"elites": 100}})


def test_copy_is_independent():
    a = animat.Config()
    for b in (a.copy(), copy.copy(a), copy.deepcopy(a)):
        b["evolution.population"] = 12
        assert a["evolution.population"] == 100
        assert b != a


def test_doc_names_range():
    assert "(0, 1]" in animat.Config().doc("grn.dt")
    assert "[2, 100000]" in animat.Config().doc("evolution.population")
    with pytest.raises(ValueError):
        animat.Config().doc("grn.nope")


def test_toml_round_trip_default_and_non_default(tmp_path):
    c = animat.Config()
    assert animat.Config.from_toml(c.to_toml()) == c
    c["grn.dt"] = 0.1 + 0.2  # 0.30000000000000004
    c["scene.drag_normal"] = 1.0 / 3.0
    c["development.adhesion_range"] = 5e-324  # a tiny value (genome.affinity_decay is >= 1e-6 now)
    c["evolution.seed"] = 2**62
    c["physics.drag_scheme"] = "explicit"
    c["scene.effects"] = []
    back = animat.Config.from_toml(c.to_toml(), "x.toml")
    assert back == c
    for k in c.keys():
        assert back[k] == c[k], k
    assert back["grn.dt"] == 0.30000000000000004
    assert back["scene.drag_normal"] == 1.0 / 3.0
    p = tmp_path / "c.toml"
    p.write_text(c.to_toml())
    assert animat.load_config(str(p)) == c
    assert animat.load_config(p) == c


def test_from_toml_partial_keeps_defaults():
    c = animat.Config.from_toml("[evolution]\npopulation = 57\n")
    expected = animat.Config()
    expected["evolution.population"] = 57
    assert c == expected


def test_load_config_missing_file_is_oserror_naming_it(tmp_path):
    p = tmp_path / "missing.toml"
    with pytest.raises(OSError) as e:
        animat.load_config(str(p))
    assert str(p) in str(e.value)


BAD_TOML = [
    ("config_unknown_key.toml", 6, ["unknown key 'evolution.populaton'", "did you mean 'population'"]),
    ("config_unknown_section.toml", 5, ["unknown section [evolutoin]", "did you mean 'evolution'"]),
    ("config_wrong_type.toml", 6, ['evolution.population = "many"', "wrong type", "expected an integer"]),
    ("config_float_for_integer.toml", 6, ["evolution.population = 10.5", "expected an integer"]),
    ("config_population_zero.toml", 6, ["evolution.population = 0", "out of range", "[2, 100000]"]),
    ("config_population_negative.toml", 6, ["evolution.population = -5", "out of range"]),
    ("config_dt_zero.toml", 6, ["grn.dt = 0.0", "out of range", "(0, 1]"]),
    ("config_dt_negative.toml", 6, ["grn.dt = -0.05", "(0, 1]"]),
    ("config_dt_nan.toml", 6, ["grn.dt = nan", "must be finite"]),
    ("config_dt_inf.toml", 6, ["grn.dt = inf", "must be finite"]),
    ("config_integer_overflow.toml", 6, ["evolution.population = 10000000000", "integer range"]),
    ("config_malformed.toml", 5, ["malformed TOML"]),
    ("config_section_not_table.toml", 3, ["'grn' must be a table"]),
    ("config_bad_choice.toml", 6, ['physics.drag_scheme = "magic"', "expected one of"]),
    ("config_bad_list_entry.toml", 6, ["scene.effects", '"buoyancy"']),
    ("config_elites_not_below_population.toml", 0, ["evolution.elites = 10", "evolution.population = 10"]),
    ("config_duplicate_key.toml", 7, ["malformed TOML", "dt"]),
]


@pytest.mark.parametrize("name, line, fragments", BAD_TOML, ids=[c[0] for c in BAD_TOML])
def test_bad_toml_files(name, line, fragments):
    path = BAD / name
    assert path.exists()
    with pytest.raises(ValueError) as e:
        animat.load_config(str(path))
    msg = str(e.value)
    assert (f"{path}:{line}" if line else str(path)) in msg, msg
    for f in fragments:
        assert f in msg, msg


def test_bad_toml_string_names_source_and_line():
    with pytest.raises(ValueError) as e:
        animat.Config.from_toml("[grn]\n\ndt = -1\n", "my.toml")
    assert "my.toml:3" in str(e.value) and "grn.dt = -1" in str(e.value) and "(0, 1]" in str(e.value)
    with pytest.raises(ValueError, match=r"x\.toml:1.*malformed TOML"):
        animat.Config.from_toml("[grn\n", "x.toml")


def test_set_log_level():
    animat.set_log_level("warn")
    with pytest.raises(ValueError, match="loud"):
        animat.set_log_level("loud")
    animat.set_log_level("info")


def test_hash_tracks_values():
    a, b = animat.Config(), animat.Config()
    b["scene.drag_normal"] = math.nextafter(b["scene.drag_normal"], 100.0)
    assert a.hash() != b.hash()
    assert a != b
