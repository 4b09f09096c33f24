"""MAP-Elites and NSGA-II from the shell and over MPI (docs/python.md §7e): ``animat map-elites`` and
``animat nsga2`` write the run directory the library writes, resume it with the same command, and refuse
bad options with a message naming them and no file written; ``run_map_elites(..., mpi=True)`` and
``run_nsga2(..., mpi=True)`` on 2 ranks write the very files of the threaded run; an error on a rank
stops every rank with a message.

The MPI tests need mpirun and mpi4py; scripts/test.sh sets ANIMAT_TEST_MPI=1: then a missing one fails
instead of skipping. Every run here is tiny (batches of 6, 200-step swims, 3 generations).
"""

import importlib.util
import os
import pickle
import shutil
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from run_dirs import without_wall

import animat
from animat import cli
from animat.pool import _shares

MPIRUN = shutil.which("mpirun")
HAS_MPI4PY = importlib.util.find_spec("mpi4py") is not None
if os.environ.get("ANIMAT_TEST_MPI") == "1":
    assert MPIRUN, "ANIMAT_TEST_MPI=1 but mpirun is not installed (scripts/setup.sh installs openmpi-bin)"
    assert HAS_MPI4PY, "ANIMAT_TEST_MPI=1 but mpi4py is not installed (requirements-dev.txt)"
needs_mpi = pytest.mark.skipif(not MPIRUN or not HAS_MPI4PY, reason="needs mpirun and mpi4py")

ENV = dict(os.environ, PYTHONPATH=str(Path(animat.__file__).resolve().parents[1]))  # the package tested here
# mpirun refuses root without --allow-run-as-root (CI and containers run as root); localhost only, and
# no CMA: containers may forbid ptrace.
MPIRUN_OPTIONS = ["--oversubscribe", "--bind-to", "none", "--allow-run-as-root", "--mca", "btl", "self,vader"]
MPIRUN_OPTIONS += ["--mca", "btl_vader_single_copy_mechanism", "none"]
SETS = ["--set", "evaluation.steps=200", "--set", "evaluation.reference_substeps=2"]
SMALL = ["paper_dn2", *SETS, "--threads", "1", "--quiet"]
ME = ["--descriptors", "cells,frequency", "--bins", "8,5", "--batch", "6"]
NSGA = ["--objectives", "distance,actuation_work_positive", "--population", "6"]


def small_config():
    c = animat.load_config("paper_dn2")
    c.apply_overrides(SETS[1::2])
    return c


def library_map_elites(out, generations=3):
    archive = animat.GridArchive(["cells", "frequency"], (8, 5))
    return animat.run_map_elites(small_config(), out, generations, archive, batch=6, threads=1)


def library_nsga2(out, generations=3):
    objectives = [("distance", "max"), ("actuation_work_positive", "min")]
    return animat.run_nsga2(small_config(), objectives, out, generations, population=6, threads=1)


def files(run: Path):
    """Every file of a run directory, by relative path, as bytes; history.csv and checkpoint.json
    without the wall-clock seconds the engine records, which differ run to run, and without the
    resume.log of a resumed run."""
    out = {str(p.relative_to(run)): p.read_bytes() for p in sorted(run.rglob("*")) if p.is_file()}
    if "checkpoint.json" in out:
        rows, payload = without_wall(run)
        out["history.csv"], out["checkpoint.json"] = repr(rows).encode(), repr(payload).encode()
    out.pop("resume.log", None)
    return out


def mpirun(*args, ranks=2, timeout=120):
    cmd = [MPIRUN, *MPIRUN_OPTIONS, "-np", str(ranks), sys.executable, *args]
    return subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=timeout)


# --- the results travel exactly -------------------------------------------------------------------


def exact(x, depth=0):
    """A value with every float as its bytes (NaN equal to NaN), every public field of an object."""
    if isinstance(x, float):
        return struct.pack("<d", x)
    if isinstance(x, (bool, int, str, type(None))):
        return x
    if isinstance(x, np.ndarray):
        return (x.dtype.str, x.shape, x.tobytes())
    if isinstance(x, (list, tuple)):
        return tuple(exact(v, depth + 1) for v in x)
    assert depth < 4, x
    fields = [n for n in dir(x) if not n.startswith("_") and not callable(getattr(x, n))]
    assert fields, x
    return (type(x).__name__, tuple((n, exact(getattr(x, n), depth + 1)) for n in fields))


def test_genomes_results_and_fitness_pickle_exactly():
    config = small_config()
    genomes = [animat.Genome.random_viable(animat.Rng.derive(4, 0, i), config)[0] for i in range(3)]
    genomes.append(next(g for g in map(animat.Genome.random, range(50)) if not animat.develop(g, config).viable))
    for g in genomes:
        again = pickle.loads(pickle.dumps(g))
        assert again == g and again.to_json() == g.to_json()
        result = animat.evaluate(g, config)
        assert exact(pickle.loads(pickle.dumps(result))) == exact(result)
        fitness = animat.evaluate_population([g], config, 1)[0]
        assert exact(pickle.loads(pickle.dumps(fitness))) == exact(fitness)
    assert exact(animat.evaluate(genomes[0], config).energy)  # a nested value, compared field by field


def test_a_batch_is_cut_into_contiguous_shares_in_order():
    items = list(range(7))
    assert _shares(items, 3) == [[0, 1, 2], [3, 4], [5, 6]]
    assert _shares(items[:2], 3) == [[0], [1], []]
    for n in range(6):
        for ranks in (1, 2, 4):
            shares = _shares(list(range(n)), ranks)
            assert len(shares) == ranks and [x for s in shares for x in s] == list(range(n))


# --- the commands ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "command, extra, library",
    [("map-elites", ME, library_map_elites), ("nsga2", NSGA, library_nsga2)],
)
def test_the_command_writes_the_library_run_and_resumes_it(tmp_path, capsys, command, extra, library):
    straight = tmp_path / "library"
    library(straight)
    out = tmp_path / "shell"
    assert cli.main([command, *SMALL, "--out", str(out), "--generations", "1", *extra]) == 0
    assert "generation 1, 12 evaluations;" in capsys.readouterr().out
    assert cli.main([command, *SMALL, "--out", str(out), "--generations", "3", *extra]) == 0
    assert "generation 3, 24 evaluations (resumed)" in capsys.readouterr().out
    mine, theirs = files(out), files(straight)
    snapshots = "archive" if command == "map-elites" else "front"
    assert f"{snapshots}/gen_000001.csv" in mine  # the last generation of the first session
    del mine[f"{snapshots}/gen_000001.csv"]
    theirs.pop(f"{snapshots}/gen_000001.csv", None)
    assert mine == theirs
    # Left out, the archive or objectives and the batch or population are the run's.
    assert cli.main([command, *SMALL, "--out", str(out), "--generations", "4"]) == 0
    assert "generation 4, 30 evaluations (resumed)" in capsys.readouterr().out


def test_the_commands_print_a_line_per_generation(tmp_path, capsys):
    assert cli.main(["map-elites", *SMALL[:-1], "--out", str(tmp_path / "me"), "--generations", "1", *ME]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("generation    0: ") and "coverage" in lines[0] and len(lines) == 3
    assert cli.main(["nsga2", *SMALL[:-1], "--out", str(tmp_path / "ns"), "--generations", "0", *NSGA]) == 0
    line = capsys.readouterr().out.splitlines()[0]
    assert line.startswith("generation    0: front ") and "best_distance" in line


@pytest.mark.parametrize(
    "command, options, message",
    [
        ("map-elites", ["--descriptors", "cells,wiggle"], "--descriptors 'cells,wiggle': no name 'wiggle'"),
        ("map-elites", ["--descriptors", "cells,cells"], "--descriptors 'cells,cells': a name appears twice"),
        ("map-elites", ["--bins", "8,5,3"], "--bins '8,5,3': one count >= 1 for every descriptor"),
        ("map-elites", ["--bins", "0"], "--bins '0': one count >= 1"),
        ("map-elites", ["--bins", "eight"], "--bins 'eight': counts are integers"),
        ("map-elites", ["--batch", "0"], "--batch must be >= 1, got 0"),
        ("map-elites", ["--archive-every", "0"], "--archive-every must be >= 1, got 0"),
        ("map-elites", ["--threads", "-1"], "--threads must be >= 0, got -1"),
        ("nsga2", ["--objectives", "distance,speed"], "--objectives 'distance,speed': no name 'speed'"),
        ("nsga2", ["--objectives", "distance,max_speed"], "max_speed has no default sense: write max_speed:max"),
        ("nsga2", ["--objectives", "distance:up"], "distance has sense 'up'"),
        ("nsga2", ["--population", "0"], "--population must be >= 1, got 0"),
        ("nsga2", ["--front-every", "0"], "--front-every must be >= 1, got 0"),
        ("nsga2", ["--generations", "-2"], "--generations must be >= 0, got -2"),
        ("nsga2", ["--set", "evolution.bogus=1"], "--set evolution.bogus=1: unknown key 'evolution.bogus'"),
    ],
)
def test_a_bad_option_is_refused_naming_it_and_writes_nothing(tmp_path, capsys, command, options, message):
    out = tmp_path / "run"
    assert cli.main([command, *SMALL, "--out", str(out), "--generations", "1", *options]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"animat {command}: error: ") and message in err, err
    assert not out.exists()


def test_a_config_without_a_generation_cap_needs_generations(tmp_path, capsys):
    out = tmp_path / "run"
    assert cli.main(["map-elites", *SMALL, "--out", str(out)]) == 1
    assert "--generations is needed: the config's evolution.generations is 0" in capsys.readouterr().err
    assert cli.main(["map-elites", *SMALL, "--out", str(out), "--set", "evolution.generations=1", *ME]) == 0
    assert animat.MapElites.load(out).generation == 1


@pytest.mark.parametrize(
    "command, extra, change, message",
    [
        ("map-elites", ME, ["--bins", "8,6"], "search.bins = [8.0, 6.0] is not the run's [8.0, 5.0]"),
        ("map-elites", ME, ["--batch", "7"], "batch 7 is not the run's 6"),
        ("map-elites", ME, ["--seed", "9"], "seed 9 is not the run's 1"),
        ("map-elites", ME, ["--set", "evaluation.steps=300"], "the config differs from the checkpoint's"),
        ("nsga2", NSGA, ["--population", "7"], "population 7 is not the run's 6"),
        ("nsga2", NSGA, ["--objectives", "distance"], "are not the checkpoint's"),
    ],
)
def test_a_resume_that_would_change_the_run_is_refused_and_touches_nothing(
    tmp_path, capsys, command, extra, change, message
):
    out = tmp_path / "run"
    assert cli.main([command, *SMALL, "--out", str(out), "--generations", "1", *extra]) == 0
    before = files(out)
    assert cli.main([command, *SMALL, "--out", str(out), "--generations", "2", *extra, *change]) == 1
    assert message in capsys.readouterr().err
    assert files(out) == before
    # The other search's command on this directory is refused too.
    other = "nsga2" if command == "map-elites" else "map-elites"
    assert cli.main([other, *SMALL, "--out", str(out), "--generations", "2"]) == 1
    assert f"the run directory holds a {command.replace('-', '_')} run" in capsys.readouterr().err
    assert files(out) == before


# --- from the config: search.algorithm and `animat evolve` ---------------------------------------


def search_config(tmp_path, command, **keys):
    """A config file of paper_dn2 at SETS whose [search] section defines the run."""
    c = small_config()
    if command == "map-elites":
        search = dict(algorithm="map_elites", descriptors=["cells", "frequency"], bins=[8.0, 5.0], batch=6)
    else:
        search = dict(algorithm="nsga2", objectives=["distance", "actuation_work_positive:min"])
        c["evolution.population"] = 6
    for key, value in {**search, **keys}.items():
        c[f"search.{key}"] = value
    path = tmp_path / f"{command}.toml"
    path.write_text(c.to_toml())
    return path


@pytest.mark.parametrize("command", ["map-elites", "nsga2"])
def test_animat_evolve_runs_the_configs_search_and_resumes_it(tmp_path, capsys, command):
    config = search_config(tmp_path, command)
    straight = tmp_path / "library"
    if command == "map-elites":  # the archive and batch given: the same run
        library_map_elites(straight)
    else:
        objectives = [("distance", "max"), ("actuation_work_positive", "min")]
        animat.run_nsga2(animat.load_config(str(config)), objectives, straight, 3, threads=1)
    out = tmp_path / "evolve"
    base = ["evolve", "--threads", "1", "--quiet"]
    assert cli.main([*base, "--config", str(config), "--out", str(out), "--generations", "1"]) == 0
    assert "generation 1, 12 evaluations;" in capsys.readouterr().out
    # The run directory says which search it is: --resume needs nothing else.
    assert cli.main([*base, "--resume", str(out), "--generations", "3"]) == 0
    assert "generation 3, 24 evaluations (resumed)" in capsys.readouterr().out
    mine, theirs = files(out), files(straight)
    if command == "map-elites":  # archive_every 10: the first session's last generation is extra
        del mine["archive/gen_000001.csv"]
    assert mine == theirs


EXE = os.environ.get("ANIMAT_EVOLVE_EXE")


@pytest.mark.skipif(not EXE or not os.path.exists(EXE), reason="needs ANIMAT_EVOLVE_EXE")
@pytest.mark.parametrize("command", ["map-elites", "nsga2"])
def test_animat_evolves_search_run_opens_as_the_library_run(tmp_path, command):
    # animat_evolve writes no snapshot files: Run reads the last archive or front from its checkpoint.
    engine, library = tmp_path / "engine", tmp_path / "library"
    cmd = [EXE, "--config", str(search_config(tmp_path, command)), "--out", str(engine), "--generations", "3"]
    done = subprocess.run([*cmd, "--threads", "1", "--quiet"], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    (library_map_elites if command == "map-elites" else library_nsga2)(library)
    mine, theirs = animat.Run(engine), animat.Run(library)
    assert mine.search == theirs.search
    # one format: the same columns (the wall-clock seconds differ run to run)
    assert mine.history.dtype == theirs.history.dtype
    names = [n for n in theirs.history.dtype.names if n != "wall_seconds"]
    assert [tuple(row[n] for n in names) for row in mine.history] == [
        tuple(row[n] for n in names) for row in theirs.history
    ]
    a, b = mine.snapshot(), theirs.snapshot()
    assert (a.kind, a.generation, a.path) == (b.kind, 3, engine / "checkpoint.json")
    assert (a.genomes, a.objectives, a.descriptors) == (b.genomes, b.objectives, b.descriptors)
    assert list(a.columns) == list(b.columns)
    for name, column in b.columns.items():
        np.testing.assert_array_equal(a.columns[name], column, err_msg=name)
    assert mine.best().genome.to_json() == theirs.best().genome.to_json()
    assert cli.main(["explore", str(engine), "--out", str(tmp_path / "page.html")]) == 0


@pytest.mark.skipif(not EXE or not os.path.exists(EXE), reason="needs ANIMAT_EVOLVE_EXE")
@pytest.mark.parametrize("command", ["map-elites", "nsga2"])
def test_animat_evolve_and_the_library_resume_each_others_runs(tmp_path, command):
    # One run directory format: a library run continued by animat_evolve, then by the library
    # again, is the uninterrupted library run (the wall-clock seconds aside).
    library = library_map_elites if command == "map-elites" else library_nsga2
    straight, shared = tmp_path / "straight", tmp_path / "shared"
    library(straight, generations=4)
    library(shared, generations=2)
    cmd = [EXE, "--resume", str(shared), "--generations", "3", "--threads", "1", "--quiet"]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert without_wall(shared)[0] == without_wall(straight)[0][:5]  # the header, generations 0-3
    if command == "map-elites":
        animat.run_map_elites(small_config(), shared, 4, resume=True, threads=1)
    else:
        animat.run_nsga2(small_config(), None, shared, 4, resume=True, threads=1)
    assert without_wall(shared) == without_wall(straight)
    snapshot = ("archive" if command == "map-elites" else "front") + "/gen_000004.csv"
    for name in ("config.toml", snapshot):
        assert (shared / name).read_bytes() == (straight / name).read_bytes(), name
    # and animat_evolve's own run, continued by the library, is animat_evolve's uninterrupted one
    engine, resumed = tmp_path / "engine", tmp_path / "resumed"
    config = search_config(tmp_path, command)
    for out, generations in ((engine, "3"), (resumed, "2")):
        cmd = [EXE, "--config", str(config), "--out", str(out), "--generations", generations, "--threads", "1"]
        assert subprocess.run([*cmd, "--quiet"], capture_output=True, timeout=600).returncode == 0
    if command == "map-elites":
        animat.run_map_elites(None, resumed, 3, resume=True)
    else:
        animat.run_nsga2(None, None, resumed, 3, resume=True)
    # the same state; the library's checkpoint also lists the values it supplied (the table's)
    rows, payload = without_wall(resumed)
    for member in payload.get("elites", payload.get("population")):
        member.pop("supplied", None)
    assert (rows, payload) == without_wall(engine)


def test_the_library_run_records_its_search_in_config_toml(tmp_path):
    library_map_elites(tmp_path / "me", generations=0)
    c = animat.load_config(str(tmp_path / "me" / "config.toml"))
    assert c["search.algorithm"] == "map_elites" and c["search.descriptors"] == ["cells", "frequency"]
    assert c["search.bins"] == [8.0, 5.0] and c["search.batch"] == 6
    library_nsga2(tmp_path / "ns", generations=0)
    c = animat.load_config(str(tmp_path / "ns" / "config.toml"))
    assert c["search.algorithm"] == "nsga2"
    assert c["search.objectives"] == ["distance:max", "actuation_work_positive:min"]


@pytest.mark.parametrize(
    "command, key, value, message",
    [
        ("map-elites", "descriptors", ["cells", "wiggle"], 'search.descriptors = ["cells", "wiggle"]: no descriptor'),
        ("nsga2", "objectives", ["distance", "max_speed"], "max_speed has no default sense: write max_speed:max"),
        ("nsga2", "objectives", ["distance:up"], "search.objectives = [\"distance:up\"]: distance has sense 'up'"),
    ],
)
def test_a_bad_search_key_is_refused_naming_the_file_and_writes_nothing(tmp_path, capsys, command, key, value, message):
    config = search_config(tmp_path, command, **{key: value})
    out = tmp_path / "run"
    assert cli.main(["evolve", "--config", str(config), "--out", str(out), "--generations", "1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"animat evolve: error: {config}: ") and message in err, err
    assert not out.exists()


def test_the_ga_refuses_a_config_of_another_search(tmp_path):
    config = small_config()
    config["search.algorithm"] = "map_elites"
    with pytest.raises(Exception, match='search.algorithm = "map_elites": this runs the GA'):
        animat.evolve(config, out=str(tmp_path / "ga"), generations=1)
    assert not (tmp_path / "ga").exists()


# --- over MPI -------------------------------------------------------------------------------------


@needs_mpi
@pytest.mark.parametrize(
    "command, extra, library",
    [("map-elites", ME, library_map_elites), ("nsga2", NSGA, library_nsga2)],
)
def test_two_ranks_write_the_threaded_run_bit_for_bit_and_resume_it(tmp_path, command, extra, library):
    straight = tmp_path / "threads"
    library(straight)
    out = tmp_path / "ranks"
    base = ["-m", "animat", command, *SMALL, "--out", str(out), *extra, "--mpi"]
    first = mpirun(*base, "--generations", "2")
    assert first.returncode == 0, first.stdout + first.stderr
    assert first.stdout.count(f"{out}: generation 2") == 1  # rank 0 reports, the others are quiet
    again = mpirun(*base, "--generations", "3")
    assert again.returncode == 0, again.stdout + again.stderr
    mine, theirs = files(out), files(straight)
    if command == "map-elites":  # archive_every 10: the first session's last generation is extra
        del mine["archive/gen_000002.csv"]
    assert mine == theirs


@needs_mpi
def test_animat_evolve_under_mpirun_runs_the_configs_search_on_the_ranks(tmp_path):
    # As animat_evolve: under mpirun the ranks swim without --mpi.
    straight = tmp_path / "threads"
    library_map_elites(straight)
    out = tmp_path / "ranks"
    config = search_config(tmp_path, "map-elites")
    run = mpirun(
        "-m", "animat", "evolve", "--config", str(config), "--out", str(out), "--generations", "3", "--threads", "1"
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert run.stdout.count(f"{out}: generation 3") == 1  # rank 0 reports, the others are quiet
    assert files(out) == files(straight)


@needs_mpi
def test_the_library_over_mpi_returns_the_run_on_every_rank(tmp_path):
    script = tmp_path / "search.py"
    script.write_text(
        "import sys, animat\n"
        "c = animat.load_config('paper_dn2')\n"
        "c.apply_overrides(['evaluation.steps=200', 'evaluation.reference_substeps=2'])\n"
        "nsga = animat.run_nsga2(c, ['distance', 'actuation_work_positive'], sys.argv[1], 2, population=6,\n"
        "                        threads=1, mpi=True)\n"
        "rank = sys.argv[2] + '/rank_' + __import__('os').environ['OMPI_COMM_WORLD_RANK']\n"
        "open(rank, 'w').write(repr(([s.objectives for s in nsga.front()], nsga.generation)))\n"
    )
    r = mpirun(str(script), str(tmp_path / "run"), str(tmp_path), ranks=3)
    assert r.returncode == 0, r.stdout + r.stderr
    returned = {(tmp_path / f"rank_{k}").read_text() for k in range(3)}  # what each rank's call returned
    assert len(returned) == 1 and returned.pop().endswith("], 2)")
    library_nsga2(tmp_path / "threads", 2)
    assert files(tmp_path / "run") == files(tmp_path / "threads")


@needs_mpi
def test_an_error_on_a_rank_stops_every_rank_with_its_message(tmp_path):
    script = tmp_path / "fussy.py"
    script.write_text(
        "import os, sys, animat\n"
        "def fussy(record):\n"
        "    if os.environ.get('OMPI_COMM_WORLD_RANK') == '1':\n"
        "        raise ValueError('no swim on rank 1')\n"
        "    return 1.0\n"
        "c = animat.load_config('paper_dn2')\n"
        "c.apply_overrides(['evaluation.steps=200', 'evaluation.reference_check=off'])\n"
        "animat.run_map_elites(c, sys.argv[1], 2, animat.GridArchive(['cells'], 4), batch=4, threads=1,\n"
        "                      objective=animat.Objective(fussy, name='fussy'), mpi=True)\n"
    )
    r = mpirun(str(script), str(tmp_path / "run"), timeout=60)
    assert r.returncode != 0
    assert "RuntimeError: run_map_elites: the evaluation failed on MPI rank 1: ValueError:" in r.stderr, r.stderr
    assert "no swim on rank 1" in r.stderr


@needs_mpi
def test_a_refusal_on_rank_0_stops_the_other_ranks_and_ranks_need_mpi(tmp_path):
    out = tmp_path / "run"
    assert cli.main(["map-elites", *SMALL, "--out", str(out), "--generations", "1", *ME]) == 0
    before = files(out)
    r = mpirun("-m", "animat", "map-elites", *SMALL, "--out", str(out), "--generations", "2", *ME[:-1], "7", "--mpi")
    assert r.returncode != 0
    assert r.stderr.count("animat map-elites: error: run_map_elites: batch 7 is not the run's 6") == 1, r.stderr
    r = mpirun("-m", "animat", "map-elites", *SMALL, "--out", str(out), "--generations", "2", *ME)
    assert r.returncode != 0 and "started as one of 2 MPI ranks without --mpi" in r.stderr
    assert files(out) == before
