"""Determinism gate: the exact results of the model, pinned.

Every case below computes a fingerprint, the exact values (float64 bits, as ``float.hex``) of what
the model produces, and compares it with its pin in ``tests/data/determinism/fingerprints.json``:

- ``development/<genome>``: the embryo (cell positions, radii, orientations, GRN outputs, oscillator
  parameters, division steps, viability) of every gate genome under the default config (the
  control genome under configs/chemotaxis.toml);
- ``body/<graph>``: the spring-mass bodies built from the viable embryos (springs, rest lengths,
  regions, rest areas, skin) with each body graph;
- ``evaluation/<scene>``: ``animat.evaluate`` of the gate genomes in every scene the project ships
  (the default config, configs/*.toml at their own swim length, the replication runs' own configs)
  and in variants of the physics, the body graph, the objective and active control; per genome,
  fitness, viability, displacement, max speed, min area ratio, actuation work, source progress,
  collisions, drag limiter, ground contacts and GRN updates one by one, and a digest of every
  diagnostic of the EvaluationResult (EVALUATION_FIELDS);
- ``ga/<name>``: short GA runs (``animat.evolve``): every history column but the wall time, the
  final population's fitness and genomes; each also runs with 1 and 2 threads, which must agree.

Arrays and the diagnostics are pinned by a digest (the first 64 bits of the sha256 of their
little-endian bytes, with dtype and shape). A failure names the case and every value that changed,
pinned and now (hex and decimal), and for a changed evaluation every diagnostic's current value.

A pin changes only with a deliberate change of results (a model fix, a new default); a refactor,
an optimisation or an API addition must leave every pin as it is. To update the pins after such a
change, rewrite the whole file and review its diff::

    PYTHONPATH=$PWD/python .venv/bin/python tests/python/test_determinism_gate.py --write

``ANIMAT_PRINT_FINGERPRINTS=1 pytest -s tests/python/test_determinism_gate.py`` prints each case's
current values (in the file's format) whether or not they match. A commit that changes a pin
changes results: its message says which pins and why.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import tarfile
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Tuple

import numpy as np
import pytest

import animat

REPO = Path(__file__).resolve().parents[2]
PINS = REPO / "tests" / "data" / "determinism" / "fingerprints.json"
PRINT = os.environ.get("ANIMAT_PRINT_FINGERPRINTS", "") not in ("", "0")


# --- canonical values ---------------------------------------------------------------------------
def digest(data: bytes) -> str:
    """The first 64 bits of the sha256 of ``data``, in hex: a gate, not a signature."""
    return hashlib.sha256(data).hexdigest()[:16]


def _digest(array: np.ndarray) -> str:
    a = np.ascontiguousarray(array)
    a = a.astype(a.dtype.newbyteorder("<"), copy=False)
    return f"{a.dtype.str}{list(a.shape)} sha256:{digest(a.tobytes())}"


def canon(value: Any) -> Any:
    """A JSON value that is equal for equal results only: floats by their bits (float.hex), arrays by
    dtype, shape and the sha256 of their bytes, lists of arrays (regions, loops) with their lengths."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value).hex()
    if isinstance(value, str):
        return value
    if isinstance(value, (list, tuple)) and all(isinstance(v, str) for v in value):
        return list(value)
    if isinstance(value, (list, tuple)) and any(isinstance(v, np.ndarray) for v in value):
        lengths = np.array([len(v) for v in value], dtype=np.int64)
        flat = np.concatenate([np.asarray(v, dtype=np.int64) for v in value]) if value else np.zeros(0, np.int64)
        return _digest(np.concatenate([lengths, flat]))
    array = np.asarray(value)
    if array.dtype.kind in "iu" and array.size <= 4:
        return [int(v) for v in array.ravel()]
    if array.dtype.kind == "f" and array.size <= 4:
        return [float(v).hex() for v in array.ravel()]
    if array.dtype.kind in "fiub":
        return _digest(array)
    raise TypeError(f"no canonical form for {type(value).__name__}")


def _readable(value: Any) -> str:
    if isinstance(value, str) and (value.startswith(("0x", "-0x")) or value in ("inf", "-inf", "nan")):
        return f"{value} ({float.fromhex(value)!r})"
    if isinstance(value, list) and value and all(isinstance(v, str) and v.startswith(("0x", "-0x")) for v in value):
        return "[" + ", ".join(_readable(v) for v in value) + "]"
    return json.dumps(value)


def differences(pinned: Any, current: Any, path: str) -> List[str]:
    """One line per value that differs: where, pinned and now."""
    if isinstance(pinned, dict) and isinstance(current, dict):
        lines: List[str] = []
        for key in sorted(set(pinned) | set(current)):
            where = f"{path}.{key}" if path else key
            if key not in current:
                lines.append(f"  {where}: pinned {_readable(pinned[key])}, now missing")
            elif key not in pinned:
                lines.append(f"  {where}: not pinned, now {_readable(current[key])}")
            else:
                lines.extend(differences(pinned[key], current[key], where))
        return lines
    if pinned != current:
        return [f"  {path}: pinned {_readable(pinned)}, now {_readable(current)}"]
    return []


# --- the genomes --------------------------------------------------------------------------------
def _evolved(name: str) -> animat.Genome:
    data = json.loads((REPO / "tests" / "data" / "evolved" / f"{name}.json").read_text())
    return animat.Genome.from_json(json.dumps(data["genome"]))


def _replication_record(run: str) -> Dict[str, Any]:
    """The last lineage entry of a committed replication run: its best genome and stored fitness."""
    with tarfile.open(REPO / "tests" / "data" / "replication" / run / "best.tar.gz") as tar:
        last = sorted(n for n in tar.getnames() if n.endswith(".json"))[-1]
        member = tar.extractfile(last)
        assert member is not None
        return json.loads(member.read())


def _replication_best(run: str) -> animat.Genome:
    return animat.Genome.from_json(json.dumps(_replication_record(run)["genome"]))


def _chemotaxis_config() -> animat.Config:
    return animat.load_config(REPO / "configs" / "chemotaxis.toml")


# Viable bests of several environments, random genomes that fail development in two different ways,
# a random viable one (the paper's channels) and one with the active-control channels. The
# chemotaxis best is a copy of data/control/chemotaxis_amplitude_seed2_best_genome.json, so that
# the gate's inputs stay under tests/.
GENOMES: Dict[str, Callable[[], animat.Genome]] = {
    "smooth_f6_dn0.5": lambda: _evolved("smooth_f6_dn0.5"),
    "colliding_f12_dn0.5": lambda: _evolved("colliding_f12_dn0.5"),
    "exploit_old_physics_dn10": lambda: _evolved("exploit_old_physics_dn10"),
    "replication_dn2_best": lambda: _replication_best("dn2_run_0"),
    "replication_dn10_best": lambda: _replication_best("dn10_run_0"),
    "chemotaxis_amplitude_best": lambda: animat.Genome.load(
        REPO / "tests" / "data" / "determinism" / "chemotaxis_amplitude_best.json"
    ),
    "random_seed0_no_grn_path": lambda: animat.Genome.random(0),
    "random_seed1_no_division": lambda: animat.Genome.random(1),
    "random_viable_seed3": lambda: animat.Genome.random_viable(3)[0],
    "random_viable_seed5_control": lambda: animat.Genome.random_viable(5, _chemotaxis_config())[0],
}

_genome_cache: Dict[str, animat.Genome] = {}


def genome(name: str) -> animat.Genome:
    if name not in _genome_cache:
        _genome_cache[name] = GENOMES[name]()
    return _genome_cache[name]


# --- the scenes ---------------------------------------------------------------------------------
def _config(base: Optional[str], overrides: Dict[str, Any]) -> animat.Config:
    config = animat.Config() if base is None else animat.load_config(REPO / base)
    for key, value in overrides.items():
        config[key] = value
    return config


_CHEMOTAXIS_SHORT = {"evaluation.steps": 1000}
_ACTIVE = {"genome.extra_inputs": "chemical,strain", "genome.extra_outputs": "actuation", "control.mode": "grn"}

ALL = tuple(GENOMES)
SWIMMERS = ("smooth_f6_dn0.5", "colliding_f12_dn0.5", "replication_dn2_best", "replication_dn10_best")
CONTROLLED = ("chemotaxis_amplitude_best", "random_viable_seed5_control", "replication_dn2_best")

# name -> (config file or None for the default, overrides, genomes). The shipped scenes keep their own
# swim length (a full swim costs a few tens of milliseconds) and swim every gate genome; each variant
# changes one part of the model and swims the genomes that exercise it.
SCENES: Dict[str, Tuple[Optional[str], Dict[str, Any], Tuple[str, ...]]] = {
    "default": (None, {}, ALL),
    "paper_dn0.5": ("configs/paper_dn0.5.toml", {}, ALL),
    "paper_dn2": ("configs/paper_dn2.toml", {}, ALL),
    "paper_dn10": ("configs/paper_dn10.toml", {}, ALL),
    "paper_dn0.2_64cells": ("configs/paper_dn0.2_64cells.toml", {}, ALL),
    "crawl": ("configs/crawl.toml", {}, ALL),
    # the crawl world's impulse floor and one swim per genome
    "crawl_impulse_one_swim": (
        "configs/crawl.toml",
        {"scene.ground_contact": "impulse", "evaluation.repeats": 1},
        ALL,
    ),
    "walk": ("configs/walk.toml", {}, ALL),
    "regime_dn0.5": ("configs/regime_dn0.5.toml", {}, ALL),
    "regime_dn2": ("configs/regime_dn2.toml", {}, ALL),
    "regime_dn10": ("configs/regime_dn10.toml", {}, ALL),
    "regime_dn0.2_64cells": ("configs/regime_dn0.2_64cells.toml", {}, ALL),
    "chemotaxis": ("configs/chemotaxis.toml", _CHEMOTAXIS_SHORT, ALL),
    "replication_dn2_run": ("tests/data/replication/dn2_run_0/config.toml", {}, ALL),
    "replication_dn10_run": ("tests/data/replication/dn10_run_0/config.toml", {}, ALL),
    # the scene the colliding genomes were evolved in: fast oscillators, many collisions
    "collisions_f12_dn0.5": (
        None,
        {
            "scene.drag_normal": 0.5,
            "development.frequency_max": 12.0,
            "scene.pressure": 100.0,
            "scene.pressure_area_floor": 0.1,
        },
        ALL,
    ),
    "integrator_box2d": (None, {"physics.integrator": "box2d"}, SWIMMERS),
    "drag_stable": ("configs/paper_dn10.toml", {"physics.drag_scheme": "stable"}, SWIMMERS),
    "drag_implicit_forces_start": (
        None,
        {"physics.drag_scheme": "implicit", "physics.velocity_forces": "start"},
        SWIMMERS,
    ),
    "drag_explicit_substeps4": (
        "configs/paper_dn0.5.toml",
        {"physics.drag_scheme": "explicit", "physics.substeps": 4},
        SWIMMERS,
    ),
    "graph_alpha_shape_skin_collisions": (
        None,
        {"body.graph": "alpha_shape", "scene.collision_edges": "skin", "development.frequency_max": 12.0},
        SWIMMERS,
    ),
    "graph_distance": (None, {"body.graph": "distance"}, SWIMMERS),
    "objective_distance_per_size": (None, {"evaluation.objective": "distance_per_size"}, SWIMMERS),
    "objective_speed_toward": (
        None,
        {"evaluation.objective": "speed_toward", "evaluation.direction": [0.6, -0.8]},
        SWIMMERS,
    ),
    "objective_distance_minus_energy": (None, {"evaluation.objective": "distance_minus_energy"}, SWIMMERS),
    "objective_distance_per_energy": (
        "configs/paper_dn0.5.toml",
        {"evaluation.objective": "distance_per_energy"},
        SWIMMERS,
    ),
    "chemotaxis_direct": ("configs/chemotaxis.toml", {**_CHEMOTAXIS_SHORT, "control.actuation": "direct"}, CONTROLLED),
    "chemotaxis_plane_no_signal_push": (
        "configs/chemotaxis.toml",
        {
            **_CHEMOTAXIS_SHORT,
            "scene.chemical": "plane",
            "control.signal_rate": 0.0,
            "evaluation.push_step": 500,
            "evaluation.push_impulse": [1.0, 0.5],
            "evaluation.push_cells": "front",
        },
        CONTROLLED,
    ),
    "grn_direct": (None, {**_ACTIVE, "control.actuation": "direct"}, CONTROLLED),
}

# Every diagnostic of an evaluation (pinned through one digest), and those pinned one by one.
EVALUATION_FIELDS = (
    "fitness",
    "source_progress",
    "viable",
    "stable",
    "valid",
    "cell_count",
    "displacement",
    "spring_count",
    "region_count",
    "skin_edge_count",
    "development_steps",
    "swim_steps",
    "simulated_time",
    "max_speed",
    "max_step_displacement",
    "max_stretch",
    "min_stretch",
    "max_kinetic_energy",
    "final_kinetic_energy",
    "max_kinetic_energy_per_cell",
    "min_area_ratio",
    "inverted_region_steps",
    "skin_crossing_steps",
    "first_invalid_step",
    "collisions",
    "collisions_inelastic",
    "collisions_unresolved",
    "drag_limited",
    "settle_steps",
    "ground_contacts",
    "ground_slips",
    "airborne_steps",
    "actuation_work",
    "actuation_work_positive",
    "actuation_work_absolute",
    "cell_work_positive",
    "cell_work_absolute",
    "grn_updates",
    "displacement_at_push",
)
EVALUATION_PINNED = (
    "fitness",
    "viable",
    "displacement",
    "max_speed",
    "min_area_ratio",
    "actuation_work",
    "source_progress",
    "collisions",
    "drag_limited",
    "ground_contacts",
    "grn_updates",
)

# the full diagnostics of the last computation of each case, for the failure message
_diagnostics: Dict[str, Dict[str, Any]] = {}


def evaluation_case(scene: str) -> Dict[str, Any]:
    base, overrides, genomes = SCENES[scene]
    config = _config(base, overrides)
    out: Dict[str, Any] = {}
    for name in genomes:
        result = animat.evaluate(genome(name), config)
        every = {field: canon(getattr(result, field)) for field in EVALUATION_FIELDS}
        _diagnostics[f"evaluation/{scene}/{name}"] = every
        out[name] = {field: every[field] for field in EVALUATION_PINNED}
        out[name]["diagnostics"] = digest(json.dumps(every, sort_keys=True).encode())
    return out


# --- development and body -----------------------------------------------------------------------
EMBRYO_FIELDS = (
    "cell_count",
    "viable",
    "steps_run",
    "division_steps",
    "positions",
    "radii",
    "orientations",
    "outputs",
    "amplitude",
    "frequency",
    "phase",
    "stiffness",
)
# (the positions and oscillators of a body are the embryo's, pinned by the development cases)
BODY_FIELDS = ("spring_count", "region_count", "springs", "rest_lengths", "regions", "rest_areas", "skin", "skin_loops")


def development_case(name: str) -> Dict[str, Any]:
    config = _chemotaxis_config() if name.endswith("_control") else animat.Config()
    embryo = animat.develop(genome(name), config)
    return {
        field: canon(np.asarray(getattr(embryo, field)) if field == "division_steps" else getattr(embryo, field))
        for field in EMBRYO_FIELDS
    }


def body_case(graph: str) -> Dict[str, Any]:
    config = animat.Config()
    config["body.graph"] = graph
    out: Dict[str, Any] = {}
    for name in GENOMES:
        embryo = animat.develop(genome(name), config)
        if not embryo.viable:
            continue
        body = animat.build_body(embryo, config=config)
        out[name] = {field: canon(getattr(body, field)) for field in BODY_FIELDS}
    return out


# --- short GA runs ------------------------------------------------------------------------------
GA_RUNS: Dict[str, Tuple[Optional[str], Dict[str, Any]]] = {
    "default": (
        None,
        {"evolution.population": 10, "evolution.generations": 3, "evaluation.steps": 1000, "evolution.seed": 11},
    ),
    "islands_dn0.5": (
        "configs/paper_dn0.5.toml",
        {
            "evolution.population": 12,
            "evolution.generations": 3,
            "evaluation.steps": 1000,
            "evolution.seed": 5,
            "evolution.islands": 2,
            "evolution.migration_interval": 1,
        },
    ),
    "chemotaxis": (
        "configs/chemotaxis.toml",
        {"evolution.population": 8, "evolution.generations": 2, "evaluation.steps": 1000, "evolution.seed": 4},
    ),
}


def ga_fingerprint(name: str, threads: int) -> Dict[str, Any]:
    base, overrides = GA_RUNS[name]
    result = animat.evolve(_config(base, overrides), threads=threads, quiet=True)
    history = result.history
    columns = [c for c in history.dtype.names or () if c != "wall_seconds"]
    out: Dict[str, Any] = {"stop_reason": result.stop_reason}
    for row in history:
        out[f"generation_{int(row['generation'])}"] = {c: canon(row[c].item()) for c in columns}
    out["population_fitness"] = canon(np.array([i.fitness.fitness for i in result.population]))
    out["population_genomes"] = digest("\n".join(i.genome.to_json() for i in result.population).encode())
    out["best_genome"] = digest(result.best.genome.to_json().encode())
    return out


_ga_cache: Dict[Tuple[str, int], Dict[str, Any]] = {}


def ga_case(name: str, threads: int = 1) -> Dict[str, Any]:
    if (name, threads) not in _ga_cache:
        _ga_cache[(name, threads)] = ga_fingerprint(name, threads)
    return _ga_cache[(name, threads)]


# --- the cases ----------------------------------------------------------------------------------
CASES: Dict[str, Callable[[], Dict[str, Any]]] = {}
for _name in GENOMES:
    CASES[f"development/{_name}"] = (lambda n: lambda: development_case(n))(_name)
for _graph in ("gabriel", "distance", "alpha_shape"):
    CASES[f"body/{_graph}"] = (lambda g: lambda: body_case(g))(_graph)
for _scene in SCENES:
    CASES[f"evaluation/{_scene}"] = (lambda s: lambda: evaluation_case(s))(_scene)
for _run in GA_RUNS:
    CASES[f"ga/{_run}"] = (lambda r: lambda: ga_case(r))(_run)


def _load_pins() -> Dict[str, Any]:
    return json.loads(PINS.read_text()) if PINS.is_file() else {}


def _dump(values: Dict[str, Any]) -> str:
    """JSON with one line per genome (or field) of each case, so that a diff shows what changed."""
    cases = []
    for case in sorted(values):
        items = sorted(values[case].items())
        body = ",\n".join(f"  {json.dumps(key)}: {json.dumps(value, sort_keys=True)}" for key, value in items)
        cases.append(f" {json.dumps(case)}: {{\n{body}\n }}")
    return "{\n" + ",\n".join(cases) + "\n}"


@pytest.mark.parametrize("case", list(CASES))
def test_fingerprint(case: str) -> None:
    current = CASES[case]()
    if PRINT:
        print(_dump({case: current}))
    pins = _load_pins()
    if case not in pins:
        pytest.fail(
            f"determinism gate: {case} has no pin in {PINS.relative_to(REPO)}; its current values:\n"
            f"{_dump({case: current})}",
            pytrace=False,
        )
    lines = differences(pins[case], current, "")
    for name, values in current.items():
        every = _diagnostics.get(f"{case}/{name}")
        if every is not None and pins[case].get(name) != values:  # the digest hides which one changed
            lines.append(
                f"  {name}, every diagnostic now: "
                + ", ".join(f"{key}={_readable(value)}" for key, value in every.items())
            )
    if lines:
        pytest.fail(
            f"determinism gate: the results of {case} changed. A pin changes only with a deliberate change "
            "of results, explained in the commit (module docstring).\n" + "\n".join(lines),
            pytrace=False,
        )


def test_every_pin_has_a_case() -> None:
    stale = sorted(set(_load_pins()) - set(CASES))
    assert not stale, f"pins in {PINS.relative_to(REPO)} without a case (remove them): {stale}"


@pytest.mark.parametrize("run", list(GA_RUNS))
def test_ga_is_identical_with_two_threads(run: str) -> None:
    one, two = ga_case(run, 1), ga_case(run, 2)
    lines = differences(one, two, "")
    if lines:
        pytest.fail(
            f"ga/{run}: 2 threads differ from 1 thread (pinned: 1 thread; now: 2 threads):\n" + "\n".join(lines),
            pytrace=False,
        )


def test_the_gate_exercises_the_model() -> None:
    # The pins guard something only if the cases reach the model's paths: bests that swim, genomes
    # that fail development, collisions, ground contact, GRN control, the drag limiter, a push.
    pins = _load_pins()
    default = pins["evaluation/default"]
    assert sum(v["viable"] for v in default.values()) >= 7
    assert sum(not v["viable"] for v in default.values()) == 2
    assert sum(float.fromhex(default[name]["fitness"]) > 1.0 for name in SWIMMERS) >= 3
    assert pins["evaluation/collisions_f12_dn0.5"]["colliding_f12_dn0.5"]["collisions"] > 100
    for crawl in ("crawl", "crawl_impulse_one_swim"):
        assert all(v["ground_contacts"] > 0 for v in pins[f"evaluation/{crawl}"].values() if v["viable"])
    chemotaxis = pins["evaluation/chemotaxis"]["chemotaxis_amplitude_best"]
    assert chemotaxis["grn_updates"] > 0 and float.fromhex(chemotaxis["source_progress"]) > 0.1
    assert pins["evaluation/drag_stable"]["replication_dn10_best"]["drag_limited"] > 0
    assert len({v["fitness"] for v in pins["evaluation/grn_direct"].values()}) == len(CONTROLLED)
    assert pins["ga/default"]["generation_3"]["best"] != pins["ga/default"]["generation_0"]["best"]


def test_the_pins_agree_with_the_committed_runs() -> None:
    # The replication runs stored their bests' fitness when they were evolved: the pins of those
    # genomes in their own runs' configs are those very numbers.
    pins = _load_pins()
    for run, scene, name in (
        ("dn2_run_0", "replication_dn2_run", "replication_dn2_best"),
        ("dn10_run_0", "replication_dn10_run", "replication_dn10_best"),
    ):
        stored = float(_replication_record(run)["fitness"])
        assert pins[f"evaluation/{scene}"][name]["fitness"] == stored.hex(), (run, stored)


def main(argv: List[str]) -> int:
    if argv != ["--write"]:
        print(__doc__)
        return 2
    values = {case: compute() for case, compute in CASES.items()}
    for run in GA_RUNS:
        assert not differences(ga_case(run, 1), ga_case(run, 2), ""), f"ga/{run}: threads disagree; nothing written"
    PINS.parent.mkdir(parents=True, exist_ok=True)
    PINS.write_text(_dump(values) + "\n")
    print(f"wrote {len(values)} pins to {PINS}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
