"""animat.MapElites is a wrapper over the engine's search (animat._core.SearchEngine): what the
engine refuses, the wrapper refuses, naming the value, key or file, and a refusal changes nothing
(the search's state, the run directory's files); animat.Nsga2's checkpoints and sizes are checked
too. A cheap deterministic stub stands in for the swims."""

import fcntl
import hashlib
import json
import math
import os
import socket

import numpy as np
import pytest

import animat
from animat import qd


def stub(genome):
    """A Fitness that depends on the genome only: a quarter not viable, the rest spread over the cells
    and fitness descriptors."""
    h = int(hashlib.sha256(genome.to_json().encode()).hexdigest()[:15], 16)
    if h % 4 == 0:
        return animat.Fitness(0.0, False, True, 0)
    return animat.Fitness((h >> 8) % 5000 / 100.0, True, True, 1 + (h >> 24) % 64)


def small_config():
    config = animat.Config()
    config["evaluation.steps"] = 200
    config["evaluation.reference_check"] = "off"
    config["evolution.threads"] = 1
    return config


def new_search(generations=2):
    me = animat.MapElites(small_config(), animat.GridArchive(["cells", "fitness"], bins=(8, 5)), batch=12, seed=3)
    while me.generation < generations - 1:
        me.tell([stub(g) for g in me.ask()])
    return me


def state_of(me):
    elites = [(e.index, e.genome.to_json(), e.fitness, e.descriptors, e.generation) for e in me.archive.elites()]
    return me.checkpoint()["engine"], me.generation, me.history.tolist(), elites


# --- tell -----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "told, error, message",
    [
        (1e308, ValueError, r"value 0 .*fitness 1e\+308 is beyond \+-4\.49\d*e\+306, where the QD-score of 40 cells"),
        # Built in the test: a Fitness among the collected parameters outlives animat._core at exit,
        # which nanobind reports as a leaked instance.
        (lambda: animat.Fitness(1e308, True, True, 3), ValueError, r"value 0 .*fitness 1e\+308 is beyond"),
        (-1.0, ValueError, r"value 0 .*fitness -1 \(a fitness must be finite and >= 0"),
        ("3.0", TypeError, r"value 0 \('3\.0'\) is a string"),
        (math.inf, ValueError, r"value 0 \(inf\): a fitness must be finite"),
    ],
)
def test_a_refused_tell_changes_nothing(told, error, message):
    told = told() if callable(told) else told
    me = new_search()
    before = state_of(me)
    genomes = me.ask()
    with pytest.raises(error, match=message):
        me.tell([told] * len(genomes))
    assert state_of(me) == before
    assert [g.to_json() for g in me.ask()] == [g.to_json() for g in genomes]  # still pending
    me.tell([stub(g) for g in genomes])
    assert me.generation == before[1] + 1


def test_a_descriptor_returning_inf_is_refused_by_name():
    def reach(genome, config=None, evaluation=None):
        return math.inf

    me = animat.MapElites(small_config(), animat.GridArchive([(reach, 0.0, 1.0), "cells"], bins=(4, 8)), batch=12)
    genomes = me.ask()
    with pytest.raises(ValueError, match=r"descriptor reach = inf"):
        me.tell([stub(g) for g in genomes])
    assert me.generation == -1 and len(me.archive) == 0 and len(me.history) == 0


# --- checkpoints ----------------------------------------------------------------------------------


def fnv1a(text):
    h = 0xCBF29CE484222325
    for b in text.encode("utf-8"):
        h = ((h ^ b) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return f"{h:016x}"


def resealed(state, edit):
    """The checkpoint with the engine's payload edited by ``edit`` and both checksums made to match:
    a hand edit that only the engine's consistency checks can find."""
    outer = json.loads(state["engine"])
    assert outer["checksum"] == fnv1a(outer["payload"])  # the engine's seal, recomputed here
    payload = json.loads(outer["payload"])
    edit(payload)
    body = json.dumps(payload, separators=(",", ":"))
    state = dict(state, engine=json.dumps({"checksum": fnv1a(body), "payload": body}, separators=(",", ":")))
    state["checksum"] = qd._checksum(state)
    return state


def drop_history_row(p):
    del p["history"][1]


def edit_generation(p):
    p["generation"] += 1


def fitness_times_ten(p):
    p["elites"][0]["result"]["fitness"] *= 10


@pytest.mark.parametrize("edit", [edit_generation, drop_history_row, fitness_times_ten])
def test_a_hand_edited_checkpoint_is_refused_naming_the_file(tmp_path, edit):
    me = new_search(3)
    path = me.save(tmp_path / "search.json")
    assert animat.MapElites.load(path).history.tolist() == me.history.tolist()
    path.write_text(json.dumps(resealed(me.checkpoint(), edit)))
    text = path.read_text()
    with pytest.raises(ValueError, match=rf"^{path}: "):
        animat.MapElites.load(path)
    assert path.read_text() == text


def test_a_checkpoint_of_another_kind_is_refused_naming_the_file(tmp_path):
    path = tmp_path / "search.json"
    for text in ("[1, 2]", '{"format": "animat.map_elites/1"}', "{not json"):
        path.write_text(text)
        with pytest.raises(ValueError, match=rf"^{path}: "):
            animat.MapElites.load(path)


# --- the run directory ----------------------------------------------------------------------------


def files_of(out):
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file()}


def run(out, generations, **options):
    return animat.run_map_elites(
        small_config(), out, generations, animat.GridArchive(["cells", "fitness"], (8, 5)), batch=6, **options
    )


def test_a_run_directory_has_one_writer(tmp_path, capsys):
    from animat import cli

    out = tmp_path / "run"
    run(out, 0)
    before = files_of(out)
    assert ".lock" not in before  # released at the end of the run
    lock = os.open(out / ".lock", os.O_RDWR | os.O_CREAT)  # another writer holds it, as the engine does
    fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    os.write(lock, f"pid {os.getpid()}\nhost {socket.gethostname()}\n".encode())
    try:
        with pytest.raises(
            BlockingIOError, match=r"in use by another animat process \(pid \d+ on host .*Nothing was written"
        ):
            run(out, 1, resume=True)
        with pytest.raises(BlockingIOError):
            run(out, 1, overwrite=True)
        assert cli.main(["evolve", "--resume", str(out), "--generations", "1", "--quiet"]) == 2
        assert f"in use by another animat process (pid {os.getpid()} on host" in capsys.readouterr().err
        assert {k: v for k, v in files_of(out).items() if k != ".lock"} == before
    finally:
        os.close(lock)
    (out / ".lock").unlink()
    assert run(out, 1, resume=True).generation == 1


def test_a_resume_with_changed_search_keys_is_refused_naming_the_key(tmp_path):
    out = tmp_path / "run"
    config = small_config()
    config["search.algorithm"] = "map_elites"
    config["search.descriptors"] = ["cells", "fitness"]
    config["search.bins"] = [4.0]
    animat.run_map_elites(config, out, 0, batch=6)
    before = files_of(out)
    animat.run_map_elites(config, out, 0, resume=True)  # the same config resumes
    changed = config.copy()
    changed["search.bins"] = [6.0]
    with pytest.raises(ValueError, match=r"run/config.toml: search.bins = \[6.0\] is not the run\'s \[4.0\]"):
        animat.run_map_elites(changed, out, 1, resume=True)
    assert files_of(out) == before


@pytest.mark.parametrize("overwrite", [False, True])
def test_an_archive_too_large_is_refused_before_any_file_is_written(tmp_path, overwrite):
    out = tmp_path / "run"
    if overwrite:
        run(out, 0)
    before = files_of(out) if overwrite else None
    config = small_config()
    config["search.algorithm"] = "map_elites"
    config["search.descriptors"] = ["cells", "fitness", "elongation", "frequency"]
    config["search.bins"] = [100000.0]
    with pytest.raises(ValueError, match=r"search\.bins = \[100000, 100000, 100000, 100000\] .* at most 1000000"):
        animat.run_map_elites(config, out, 1, overwrite=overwrite)
    assert (files_of(out) if overwrite else out.exists()) == (before if overwrite else False)


def test_a_cvt_archive_too_large_is_refused_naming_the_value():
    with pytest.raises(ValueError, match=r"CVTArchive: cells = 100000 is more than 10000"):
        animat.CVTArchive(["elongation", "frequency"], cells=100000)
    with pytest.raises(ValueError, match=r"samples = 2000000 with cells = 2000 makes 4e\+09 distances"):
        animat.CVTArchive(["elongation", "frequency"], cells=2000, samples=2_000_000)


def test_a_python_objective_is_told_to_the_engine_and_may_be_negative():
    objective = animat.Objective(lambda record: -2.0, name="below_zero")
    me = animat.MapElites(small_config(), animat.GridArchive(["cells"], 4), batch=6, objective=objective)
    genomes = me.ask()
    row = me.tell([-2.0] * len(genomes), descriptors=[[10.0]] * len(genomes))
    assert (row.elites, row.best, me.archive.best().fitness) == (1, -2.0, -2.0)


def test_the_exploit_guard_scores_a_python_objective_at_the_reference_step():
    def rightward(record):
        return float(record.com[-1, 0] - record.com[0, 0])

    objective = animat.Objective(rightward, every=50)
    config = small_config()
    config["evaluation.reference_check"] = "record"
    me = animat.MapElites(config, animat.GridArchive(["cells"], 4), batch=6, objective=objective)
    me.step()
    me.step()
    reference = animat.reference_config(me.config)
    reference["evaluation.objective"] = "python:rightward"
    elites = me.archive.elites()
    assert elites and me.history[-1].reference_evaluations >= len(elites)
    for e in elites:  # each elite's reference: the objective of its swim at the reference step
        (want,) = animat.evaluate_population([e.genome], reference, 1, objective=objective)
        assert e.reference == want.fitness
        (own,) = animat.evaluate_population([e.genome], me.config, 1, objective=objective)
        assert e.fitness == own.fitness != e.reference


def test_an_nsga2_population_too_large_is_refused_before_any_file_is_written(tmp_path, capsys):
    from animat import cli

    out = tmp_path / "run"
    argv = [
        "nsga2",
        "paper_dn2",
        "--out",
        str(out),
        "--generations",
        "1",
        "--objectives",
        "distance,actuation_work_positive",
    ]
    assert cli.main([*argv, "--population", "10000000"]) == 1
    assert "population (evolution.population) = 10000000: it must be 1 to 10000" in capsys.readouterr().err
    assert not out.exists()


# --- NSGA-II checkpoints --------------------------------------------------------------------------


def new_nsga2(generations=3):
    criteria = [("distance", "max"), ("actuation_work_positive", "min")]
    nsga = animat.Nsga2(small_config(), criteria, population=12, seed=5)
    while nsga.generation < generations - 1:
        told = [stub(g) for g in nsga.ask()]
        nsga.tell([[f.fitness, f.fitness / 2] if f.viable else None for f in told])
    return nsga


def times_ten(p):
    member = next(m for m in p["population"] if "supplied" in m)
    member["supplied"][0] *= 10


def one_generation_more(p):
    p["generation"] += 1


def history_row_dropped(p):
    del p["history"][1]


@pytest.mark.parametrize("edit", [times_ten, one_generation_more, history_row_dropped])
def test_an_edited_nsga2_checkpoint_is_refused_naming_the_file(tmp_path, edit):
    nsga = new_nsga2()
    path = nsga.save(tmp_path / "nsga.json")
    assert animat.Nsga2.load(path).history.tolist() == nsga.history.tolist()
    # an edit under the outer checksum, and one resealed so that only the engine's checks can find it
    outer = nsga.checkpoint()
    payload = json.loads(json.loads(outer["engine"])["payload"])
    edit(payload)
    outer["engine"] = json.dumps({"checksum": "0" * 16, "payload": json.dumps(payload)})
    path.write_text(json.dumps(outer))
    with pytest.raises(ValueError, match=rf"^{path}: its checksum does not match its content"):
        animat.Nsga2.load(path)
    path.write_text(json.dumps(resealed(nsga.checkpoint(), edit)))
    with pytest.raises(ValueError, match=rf"^{path}: "):
        animat.Nsga2.load(path)


@pytest.mark.parametrize("search", ["map_elites", "nsga2"])
def test_a_one_digit_corruption_is_refused_naming_the_file(tmp_path, search):
    kind, made = (animat.MapElites, new_search(3)) if search == "map_elites" else (animat.Nsga2, new_nsga2())
    path = made.save(tmp_path / "search.json")
    text = path.read_text()
    digits = [i for i, c in enumerate(text) if c.isdigit()]
    for i in digits[:: max(1, len(digits) // 40)]:
        path.write_text(text[:i] + str((int(text[i]) + 1) % 10) + text[i + 1 :])
        with pytest.raises(ValueError, match=rf"^{path}: "):
            kind.load(path)


def test_a_cvt_archive_is_the_engines_with_the_archives_centroids():
    archive = animat.CVTArchive(["elongation", "frequency"], 12, seed=1, samples=200)
    me = animat.MapElites(small_config(), archive, batch=12, seed=3)
    me.step()
    me.step()
    engine = me._engine.archive
    assert (engine["kind"], engine["cells"], engine["descriptors"]) == ("cvt", 12, ["elongation", "frequency"])
    assert np.array_equal(np.array(engine["centroids"]), archive._unit)
    elites = me.archive.elites()
    assert elites
    for e in elites:  # the engine's cell is the archive's nearest centroid
        assert e.index == archive.index_of(e.descriptors)
