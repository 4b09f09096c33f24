"""Where the swims of MAP-Elites and NSGA-II run: threads in this process, or the ranks of an MPI job.

A search (:class:`animat.MapElites`, :class:`animat.Nsga2`) evaluates a batch of genomes under a config
with a **swim function**, ``swim(genomes, config, **options) -> results`` (one result per genome, in
order), a pure function of its arguments: MAP-Elites' is :func:`animat.evaluate_population` (OpenMP
threads; with ``describe=names`` it also computes those descriptors of :data:`animat.DESCRIPTORS`
from the bodies its evaluations built, see :mod:`animat.qd`), NSGA-II's :func:`evaluate_results`
(``animat.evaluate`` on Python threads). Each uses the config's ``evolution.threads``.

Over MPI (``run_map_elites(..., mpi=True)``, ``run_nsga2(..., mpi=True)``, ``animat map-elites|nsga2
... --mpi``), every rank calls the same function with the same arguments. Rank 0 runs the search (asks,
tells, writes the run directory) and gives each batch to an :class:`MpiPool`: the batch is cut into one
contiguous share per rank (rank 0 swims one too), the shares are sent as pickles (genomes, the config,
the options, the results: each pickles exactly), every rank swims its share with the same swim
function and options, and the results come back in the order asked. So a run is bit-identical for any number of ranks. The other
ranks wait in :func:`serve` until rank 0 ends the run: they then return its final checkpoint, or raise
:class:`MpiAbort` when rank 0 stopped on an error. An exception while a rank swims is sent to rank 0,
which raises it (naming the rank) and stops every rank.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

from . import _core

__all__ = ["MpiAbort", "MpiPool", "Swim", "evaluate_results", "serve"]

#: A swim function: ``swim(genomes, config, **options) -> results``, one per genome, in order (the
#: options, such as MAP-Elites' ``describe``, go to every rank as they are).
Swim = Callable[..., List[Any]]


def evaluate_results(genomes: Sequence[Any], config: Any) -> List[Any]:
    """An :class:`animat.EvaluationResult` per genome, in order: ``animat.evaluate`` (the GIL released
    while it swims) on the config's ``evolution.threads`` Python threads (0 = all cores). Each is a
    function of its genome and the config alone, so the list is the same for any thread count."""
    threads = int(config["evolution.threads"])
    n = threads if threads > 0 else (os.cpu_count() or 1)
    if n == 1 or len(genomes) <= 1:
        return [_core.evaluate(g, config) for g in genomes]
    _core.warm_up_box2d()
    with ThreadPoolExecutor(max_workers=min(n, len(genomes))) as pool:
        return list(pool.map(lambda g: _core.evaluate(g, config), genomes))


class MpiAbort(RuntimeError):
    """Raised on the ranks other than 0 when rank 0 stopped the run on an error (rank 0 raises the
    error itself)."""


# The messages rank 0 scatters, one per rank: ("swim", config, share, options), ("stop", checkpoint) or
# ("abort", message). A rank answers a swim with ("ok", results) or ("error", message).
_Reply = Tuple[str, Any]


def _swim_share(swim: Swim, genomes: List[Any], config: Any, options: Dict[str, Any]) -> _Reply:
    try:
        return ("ok", swim(genomes, config, **options))
    except Exception as e:  # noqa: BLE001 - sent to rank 0, which raises it
        return ("error", f"{type(e).__name__}: {e}")


def _shares(items: List[Any], ranks: int) -> List[List[Any]]:
    """``items`` cut into ``ranks`` contiguous shares, the first ``len(items) % ranks`` one longer."""
    size, extra = divmod(len(items), ranks)
    out, start = [], 0
    for r in range(ranks):
        end = start + size + (1 if r < extra else 0)
        out.append(items[start:end])
        start = end
    return out


class MpiPool:
    """Rank 0's side of the pool: ``pool(genomes, config, **options)`` swims a batch over every rank of
    ``comm`` with ``swim`` (rank 0 takes a share) and returns the results in order; :meth:`stop` (or
    :meth:`abort`) ends :func:`serve` on the other ranks. ``what`` names the run in error messages."""

    def __init__(self, comm: Any, swim: Swim, what: str) -> None:
        if comm.Get_rank() != 0:
            raise RuntimeError(f"{what}: the MPI pool runs on rank 0 (rank {comm.Get_rank()} serves it)")
        self.comm = comm
        self.swim = swim
        self.what = what
        self.ranks = int(comm.Get_size())
        self._open = True

    def __call__(self, genomes: Sequence[Any], config: Any, **options: Any) -> List[Any]:
        if not self._open:
            raise RuntimeError(f"{self.what}: the MPI pool is stopped")
        shares = _shares(list(genomes), self.ranks)
        mine = self.comm.scatter([("swim", config, share, options) for share in shares], root=0)
        replies = self.comm.gather(_swim_share(self.swim, mine[2], config, options), root=0)
        failed = [f"rank {r}: {reply[1]}" for r, reply in enumerate(replies) if reply[0] != "ok"]
        if failed:
            raise RuntimeError(f"{self.what}: the evaluation failed on MPI {'; '.join(failed)}")
        return [result for _, results in replies for result in results]

    def _end(self, message: Tuple[str, Any]) -> None:
        if self._open:
            self._open = False
            self.comm.scatter([message] * self.ranks, root=0)

    def stop(self, checkpoint: Any) -> None:
        """End the run on every rank: :func:`serve` returns ``checkpoint`` there."""
        self._end(("stop", checkpoint))

    def abort(self, error: BaseException) -> None:
        """End the run on every rank after an error on rank 0: :func:`serve` raises :class:`MpiAbort`."""
        first = str(error).splitlines()[0] if str(error) else ""
        self._end(("abort", f"{type(error).__name__}: {first}" if first else type(error).__name__))


def serve(comm: Any, swim: Swim, what: str) -> Any:
    """The other ranks' side of the pool: swim every share rank 0 sends with ``swim`` until it ends
    the run; returns the checkpoint rank 0 stopped with, or raises :class:`MpiAbort`."""
    rank = comm.Get_rank()
    while True:
        message: Optional[Tuple[Any, ...]] = comm.scatter(None, root=0)
        assert message is not None
        if message[0] == "swim":
            comm.gather(_swim_share(swim, message[2], message[1], message[3]), root=0)
        elif message[0] == "stop":
            return message[1]
        else:
            raise MpiAbort(f"{what}: rank 0 stopped the run ({message[1]}); rank {rank} stops with it")
