"""MAP-Elites and NSGA-II run by animat_evolve over MPI ranks (search.hpp): the same run on one
process and on 2 ranks x 1-2 threads, bit for bit but for the wall-clock seconds.

Needs ANIMAT_EVOLVE_EXE and mpirun (as tests/python/test_mpi.py; ANIMAT_TEST_MPI=1 makes their
absence a failure)."""

import os
import shutil
import subprocess

import pytest
from run_dirs import without_wall

EXE = os.environ.get("ANIMAT_EVOLVE_EXE")
MPIRUN = shutil.which("mpirun")

if os.environ.get("ANIMAT_TEST_MPI") == "1":
    assert EXE and os.path.exists(EXE), "ANIMAT_TEST_MPI=1 but ANIMAT_EVOLVE_EXE is not set"
    assert MPIRUN, "ANIMAT_TEST_MPI=1 but mpirun is not installed (scripts/setup.sh installs openmpi-bin)"
pytestmark = pytest.mark.skipif(
    not EXE or not os.path.exists(EXE) or not MPIRUN, reason="needs ANIMAT_EVOLVE_EXE and mpirun"
)

# mpirun refuses root without these (CI and containers run as root); localhost only, no CMA.
ENV = dict(
    os.environ,
    OMPI_ALLOW_RUN_AS_ROOT="1",
    OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
    OMPI_MCA_btl="self,vader",
    OMPI_MCA_btl_vader_single_copy_mechanism="none",
)
SEARCHES = {
    "map_elites": ["--set", 'search.descriptors=["cells","fitness"]', "--set", "search.bins=[8,5]"],
    "nsga2": ["--set", 'search.objectives=["distance:max","actuation_work_absolute:min"]'],
}


def search(out, algorithm, ranks=None, threads=1):
    cmd = [EXE, "--set", f"search.algorithm={algorithm}", *SEARCHES[algorithm]]
    cmd += ["--set", "evolution.population=8", "--set", "search.batch=8", "--set", "evaluation.steps=200"]
    cmd += ["--generations", "3", "--seed", "3", "--threads", str(threads), "--out", str(out), "--quiet"]
    if ranks:
        cmd = [MPIRUN, "-np", str(ranks), "--oversubscribe", *cmd]
    done = subprocess.run(cmd, env=ENV, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("algorithm", sorted(SEARCHES))
def test_a_search_is_the_same_on_any_number_of_ranks_and_threads(tmp_path, algorithm):
    search(tmp_path / "one", algorithm)
    rows, payload = without_wall(tmp_path / "one")
    assert len(rows) == 5  # the header, generations 0-3
    for ranks, threads in ((2, 1), (2, 2)):
        out = tmp_path / f"ranks{ranks}_threads{threads}"
        search(out, algorithm, ranks=ranks, threads=threads)
        assert without_wall(out) == (rows, payload), (ranks, threads)
