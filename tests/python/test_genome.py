"""animat.Genome / animat.Rng / animat.affinity through Python: arrays and dtypes, parsing,
JSON round trips and bad JSON, operators and their determinism with int seeds and with animat.Rng."""

import json
import math
import pathlib
import struct

import numpy as np
import pytest

import animat

BAD = pathlib.Path(__file__).resolve().parent.parent / "bad_inputs"

P, G, M, I, O = 0, 1, 2, 3, 4  # ElementType values


def make(types, channels=None, signs=None, coords=None):
    n = len(types)
    types = np.asarray(types, dtype=np.int64)
    channels = np.zeros(n, dtype=np.int64) if channels is None else np.asarray(channels, dtype=np.int64)
    signs = np.ones(n, dtype=np.int64) if signs is None else np.asarray(signs, dtype=np.int64)
    if coords is None:
        coords = np.stack([np.arange(n, dtype=float), 0.5 * np.arange(n, dtype=float)], axis=1).reshape(n, 2)
    return animat.Genome.from_arrays(types, signs, channels, np.ascontiguousarray(coords, dtype=np.float64))


def bits(x):
    return struct.unpack("<Q", struct.pack("<d", x))[0]


# ---------------------------------------------------------------------------------------------------
# Rng


def test_rng_reference_vector_and_seeding():
    r = animat.Rng()
    r.state = [1, 2, 3, 4]
    assert [r.next() for _ in range(4)] == [11520, 0, 1509978240, 1215971899390074240]
    # SplitMix64-seeded xoshiro256** from 42 (a published cross-implementation value).
    r = animat.Rng(42)
    assert [r.next() for _ in range(3)] == [1546998764402558742, 6990951692964543102, 12544586762248559009]
    r = animat.Rng(2012)
    assert [r.next() for _ in range(3)] == [93034279098887433, 9394198562260374711, 3182120309764486837]
    d = animat.Rng.derive(7, 3, 11)
    assert d.next() == 4231993347001105474


def test_rng_determinism_and_derive():
    a, b, c = animat.Rng(5), animat.Rng(5), animat.Rng(6)
    xs = [a.next() for _ in range(50)]
    assert xs == [b.next() for _ in range(50)]
    assert xs != [c.next() for _ in range(50)]
    assert a == b
    firsts = {animat.Rng.derive(1, g, i).next() for g in range(10) for i in range(10)}
    assert len(firsts) == 100
    assert animat.Rng.derive(1, 2, 3) == animat.Rng.derive(1, 2, 3)
    assert not (animat.Rng.derive(1, 2, 3) == animat.Rng.derive(1, 3, 2))
    u = [animat.Rng(3).uniform() for _ in range(3)]
    assert u[0] == u[1] == u[2] and 0.0 <= u[0] < 1.0
    r = animat.Rng(9)
    assert all(-3 <= r.integer(-3, 3) <= 3 for _ in range(200))
    assert math.isfinite(r.normal())


# ---------------------------------------------------------------------------------------------------
# Affinity


def test_affinity_values():
    assert animat.affinity(0.0) == 10.0
    assert animat.affinity(2.0) == 0.0
    assert animat.affinity(5.0) == 0.0
    assert animat.affinity(1.0) == pytest.approx(10 * (math.exp(-1) - math.exp(-2)) / (1 - math.exp(-2)), abs=1e-12)
    d = np.linspace(0, 2, 1001)[:-1]
    a = np.array([animat.affinity(float(x)) for x in d])
    assert np.all(np.diff(a) < 0) and np.all(a > 0)


def test_affinity_respects_config():
    c = animat.Config()
    c["genome.affinity_cutoff"] = 1.0
    assert animat.affinity(1.5) > 0.0
    assert animat.affinity(1.5, c) == 0.0
    assert animat.affinity(1.0, c) == 0.0
    c["genome.affinity_decay"] = 3.0
    tail = math.exp(-3.0)
    assert animat.affinity(0.4, c) == pytest.approx(10 * (math.exp(-1.2) - tail) / (1 - tail), abs=1e-12)


def test_affinity_is_exactly_ten_at_zero_for_every_config():
    c = animat.Config()
    wrong = []
    for decay in (0.1, 0.5, 1.0, 1.5, 2.5, 3.0):
        for cutoff in (0.5, 1.0, 2.0, 2.5, 3.0, 5.0):
            c["genome.affinity_decay"] = decay
            c["genome.affinity_cutoff"] = cutoff
            if animat.affinity(0.0, c) != 10.0:
                wrong.append((decay, cutoff, animat.affinity(0.0, c)))
    assert wrong == []


# ---------------------------------------------------------------------------------------------------
# Genome arrays and parsing


def test_random_genome_arrays_dtypes_and_layout():
    g = animat.Genome.random(1)
    n = len(g)
    assert n == 30
    assert g.dimensions == 2
    assert g.types.dtype == np.int64 and g.types.shape == (n,)
    assert g.signs.dtype == np.int64 and g.signs.shape == (n,)
    assert g.channels.dtype == np.int64 and g.channels.shape == (n,)
    assert g.coords.dtype == np.float64 and g.coords.shape == (n, 2)
    assert set(np.unique(g.signs)) <= {-1, 1}
    assert np.all((g.coords >= 0) & (g.coords < 10))
    assert sorted(g.channels[g.types == I]) == [0, 1, 2, 3]
    assert sorted(g.channels[g.types == O]) == [0, 1, 2, 3, 4, 5]
    units = g.units()
    assert len(units) == 10
    for promoters, genes in units:
        assert len(promoters) == 1 and len(genes) == 1
        assert g.types[promoters[0]] == P and g.types[genes[0]] in (G, M)
    # Arrays are copies: writing to them does not change the genome.
    c = g.coords
    c[0, 0] = 123.0
    assert g.coords[0, 0] != 123.0
    assert animat.ElementType.output.value == O and animat.OutputChannel.phase.value == 5
    assert animat.InputChannel.maternal2.value == 3


def test_random_genome_respects_config():
    c = animat.Config({"genome": {"dimensions": 3, "initial_units": 4, "morphogen_gene_probability": 1.0}})
    g = animat.Genome.random(7, c)
    assert len(g) == 18 and g.coords.shape == (18, 3)
    assert not np.any(g.types == G)


def test_equal_genomes_hash_equal_so_sets_and_dicts_merge_them():
    a, b, c = animat.Genome.random(3), animat.Genome.random(3), animat.Genome.random(4)
    assert a is not b and a == b and hash(a) == hash(b)
    assert a != c and hash(a) != hash(c)
    assert len({a, b, c}) == 2
    assert {a: 1}[animat.Genome.from_json(b.to_json())] == 1
    m = a.mutate(5)
    assert hash(a) == hash(b)  # mutate returns a new genome; a is unchanged
    assert (m == a) == (hash(m) == hash(a))


def test_random_genome_determinism():
    assert animat.Genome.random(123) == animat.Genome.random(123)
    assert animat.Genome.random(123) != animat.Genome.random(124)
    r1, r2 = animat.Rng(5), animat.Rng(5)
    a = animat.Genome.random(r1)
    assert a == animat.Genome.random(r2)
    assert r1 == r2 and not (r1 == animat.Rng(5)), "a passed Rng is advanced"
    assert animat.Genome.random(r1) != a
    with pytest.raises(ValueError, match="non-negative"):
        animat.Genome.random(-1)


@pytest.mark.parametrize(
    "types, expected",
    [
        ([], []),
        ([P], []),
        ([P, P, P], []),
        ([G], []),
        ([G, M, G], []),
        ([P, G], [([0], [1])]),
        ([P, P, G, G, P, G], [([0, 1], [2, 3]), ([4], [5])]),
        ([G, P, G], [([1], [2])]),
        ([P, P], []),
        ([P, G, P, P], [([0], [1])]),
        ([P, G, M, G], [([0], [1, 2, 3])]),
        ([P, I, G], []),
        ([P, O, G], []),
        ([P, P, I, P, G], [([3], [4])]),
        ([P, G, O, G, P, G], [([0], [1]), ([4], [5])]),
        ([I, O, P, I, G, O, P, G, I, P, O, G, O], [([6], [7])]),
        ([I, I, O], []),
    ],
)
def test_units_of_hand_built_genomes(types, expected):
    channels = [0] * len(types)
    g = make(types, channels) if types else animat.Genome()
    assert g.units() == expected


def test_from_arrays_validates():
    with pytest.raises(ValueError, match="sign"):
        make([P, G], signs=[1, 0])
    # Channels 4-6 (inputs) and 6-7 (outputs) are the channels beyond the paper (docs/model.md).
    with pytest.raises(ValueError, match=r"channel 7 out of range \[0, 7\)"):
        make([I], channels=[7])
    with pytest.raises(ValueError, match=r"channel 8 out of range \[0, 8\)"):
        make([O], channels=[8])
    assert make([I, O], channels=[int(animat.InputChannel.chemical), int(animat.OutputChannel.actuation)]) is not None
    with pytest.raises(ValueError, match="unknown type 9"):
        make([9])
    with pytest.raises(ValueError, match="must be finite"):
        make([P], coords=[[np.nan, 0.0]])
    with pytest.raises(ValueError, match="same length"):
        animat.Genome.from_arrays(np.array([0, 1]), np.array([1]), np.array([0, 0]), np.zeros((2, 2)))


# ---------------------------------------------------------------------------------------------------
# JSON


def test_json_round_trip_bit_exact(tmp_path):
    awkward = [0.1, 1e-300, -0.0, 5e-324, 1.7976931348623157e308, 1.0 / 3.0, math.pi, 2.0**53 + 2, -2.5e-8, 0.0]
    coords = np.array(awkward, dtype=np.float64).reshape(5, 2)
    g = make([P, G, M, I, O], channels=[0, 0, 0, 2, 5], signs=[1, -1, 1, -1, 1], coords=coords)
    for indent in (None, 0, 2):
        text = g.to_json(indent)
        back = animat.Genome.from_json(text)
        assert back == g
        assert [bits(x) for x in back.coords.ravel()] == [bits(x) for x in awkward]
    assert math.copysign(1.0, animat.Genome.from_json(g.to_json()).coords[1, 0]) == -1.0
    doc = json.loads(g.to_json())
    assert doc["format"] == "animat.genome" and doc["version"] == 1 and doc["dimensions"] == 2
    assert doc["elements"][3]["channel"] == "maternal1"
    assert doc["elements"][4]["channel"] == "phase"
    assert "channel" not in doc["elements"][0]
    p = tmp_path / "g.json"
    g.save(str(p))
    assert animat.Genome.load(str(p)) == g
    with pytest.raises(OSError):
        animat.Genome.load(str(tmp_path / "missing.json"))


def test_json_round_trip_random_and_mutated():
    c = animat.Config({"mutation": {"move_rate": 1.0}})
    for seed in range(20):
        g = animat.Genome.random(seed).mutate(seed, c)
        back = animat.Genome.from_json(g.to_json())
        assert back == g
        assert np.array_equal(back.coords.view(np.uint64), g.coords.view(np.uint64))


BAD_JSON = [
    ("genome_truncated.json", ["not valid JSON"]),
    ("genome_binary.json", ["not valid JSON"]),
    ("genome_empty_file.json", ["not valid JSON"]),
    ("genome_nan_literal.json", ["not valid JSON"]),
    ("genome_infinity_literal.json", ["not valid JSON"]),
    ("genome_overflow.json", ["1e999"]),
    ("genome_unknown_type.json", ["element 1", 'unknown type "enhancer"']),
    ("genome_input_channel_out_of_range.json", ["element 0", 'channel "maternal7"']),
    ("genome_output_channel_number.json", ["element 0", "channel 6"]),
    ("genome_missing_coords.json", ["element 0", 'missing key "coords"']),
    ("genome_missing_elements.json", ['missing key "elements"']),
    ("genome_wrong_version.json", ['"version" 2']),
    ("genome_version_wraps_to_1.json", ['"version" 4294967297']),
    ("genome_wrong_format.json", ['"animat.chromosome"']),
    ("genome_sign_zero.json", ["element 0", "sign is 0"]),
    ("genome_sign_wraps_to_minus_1.json", ["element 0", "sign is 18446744073709551615"]),
    ("genome_coords_wrong_length.json", ["element 0", "coords must be an array of 2 numbers"]),
    ("genome_dimensions_zero.json", ['"dimensions" is 0']),
    ("genome_channel_on_promoter.json", ["promoter has no channel"]),
    ("genome_not_an_object.json", ["expected a JSON object"]),
]


@pytest.mark.parametrize("name, fragments", BAD_JSON, ids=[c[0] for c in BAD_JSON])
def test_bad_genome_files(name, fragments):
    path = BAD / name
    assert path.exists()
    with pytest.raises(ValueError) as e:
        animat.Genome.load(str(path))
    msg = str(e.value)
    assert str(path) in msg, msg
    for f in fragments:
        assert f in msg, msg
    # The same text through from_json names "<string>".
    with pytest.raises(ValueError) as e2:
        animat.Genome.from_json(path.read_bytes().decode("utf-8", errors="replace"))
    assert "<string>" in str(e2.value)


def test_from_json_too_many_elements():
    text = json.dumps({"format": "animat.genome", "version": 1, "dimensions": 2, "elements": [0] * 2_000_000})
    with pytest.raises(ValueError, match="2000000 elements exceed genome.max_elements"):
        animat.Genome.from_json(text)


# ---------------------------------------------------------------------------------------------------
# Operators


def test_mutate_returns_new_genome_and_is_deterministic_with_int_seeds():
    g = animat.Genome.random(3)
    snapshot = g.to_json()
    c = animat.Config({"mutation": {"type_rate": 0.2, "sign_rate": 0.2, "move_rate": 0.5}})
    a, b, other = g.mutate(11, c), g.mutate(11, c), g.mutate(12, c)
    assert g.to_json() == snapshot, "mutate must not change the parent"
    assert a == b
    assert a.to_json() == b.to_json()
    assert a != other
    assert a != g


def test_mutate_with_rng_advances_it():
    g = animat.Genome.random(3)
    c = animat.Config({"mutation": {"move_rate": 0.5}})
    r1, r2 = animat.Rng(77), animat.Rng(77)
    a1, a2 = g.mutate(r1, c), g.mutate(r1, c)
    assert a1 != a2, "a second call with the same Rng object draws new numbers"
    assert g.mutate(r2, c) == a1 and g.mutate(r2, c) == a2
    assert r1 == r2


def test_mutate_rates_from_config():
    g = animat.Genome.random(8)
    zero = animat.Config(
        {"mutation": {"type_rate": 0.0, "sign_rate": 0.0, "move_rate": 0.0, "duplicate_rate": 0.0, "delete_rate": 0.0}}
    )
    assert g.mutate(1, zero) == g
    flip = animat.Config(
        {"mutation": {"type_rate": 0.0, "sign_rate": 1.0, "move_rate": 0.0, "duplicate_rate": 0.0, "delete_rate": 0.0}}
    )
    assert np.array_equal(g.mutate(1, flip).signs, -g.signs)
    retype = animat.Config(
        {"mutation": {"type_rate": 1.0, "sign_rate": 0.0, "move_rate": 0.0, "duplicate_rate": 0.0, "delete_rate": 0.0}}
    )
    m = g.mutate(1, retype)
    assert np.all(m.types != g.types)
    assert np.array_equal(m.coords, g.coords)


def test_mutate_keeps_valid_and_respects_max_elements():
    c = animat.Config(
        {
            "genome": {"max_elements": 40},
            "mutation": {
                "type_rate": 0.1,
                "sign_rate": 0.1,
                "move_rate": 0.5,
                "move_sigma": 2.0,
                "duplicate_rate": 1.0,
                "delete_rate": 0.0,
                "max_series_length": 8,
            },
        }
    )
    for seed in range(20):
        g = animat.Genome.random(seed)
        for gen in range(40):
            g = g.mutate(animat.Rng.derive(seed, gen, 0), c)
            assert len(g) <= 40
            # Valid: the JSON round trip re-validates.
            assert animat.Genome.from_json(g.to_json()) == g


def test_crossover_identical_parents_and_determinism():
    g = animat.Genome.random(4)
    for seed in range(30):
        for points in (1, 2, 5):
            assert g.crossover(g, seed, points) == g
    a, b = animat.Genome.random(1), animat.Genome.random(2)
    assert a.crossover(b, 9) == a.crossover(b, 9)
    r1, r2 = animat.Rng(3), animat.Rng(3)
    assert a.crossover(b, r1, 3) == a.crossover(b, r2, 3)
    assert r1 == r2 and not (r1 == animat.Rng(3))


def test_crossover_of_different_lengths_is_built_from_parent_segments():
    short = animat.Genome.random(1, animat.Config({"genome": {"initial_units": 3}}))
    long = animat.Genome.random(2, animat.Config({"genome": {"initial_units": 25}}))
    for seed in range(100):
        for a, b in ((short, long), (long, short)):
            child = a.crossover(b, seed, 1 + seed % 3)
            assert len(child) in (len(a), len(b))
            assert animat.Genome.from_json(child.to_json()) == child
            ca, cb = a.coords, b.coords
            for i, row in enumerate(child.coords):
                from_a = i < len(a) and np.array_equal(row, ca[i])
                from_b = i < len(b) and np.array_equal(row, cb[i])
                assert from_a or from_b, (seed, i)
