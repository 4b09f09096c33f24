"""The pipeline genome -> embryo -> body -> swim as typed Python functions (thin wrappers over
``animat._core`` with the documentation ``help()`` shows), and the paper's configs."""

from __future__ import annotations

import functools
import os
from pathlib import Path
from typing import Any, Callable, List, Optional, TypeVar, Union, cast

from . import _core

__all__ = ["develop", "build_body", "swim", "load_config", "config_path", "paper_configs"]

_CONFIG_DIR = Path(__file__).resolve().parent / "configs"

_F = TypeVar("_F", bound=Callable[..., Any])


def documented(function: _F, module: str = "animat") -> _F:
    """A Python function that calls the compiled ``function``, so that ``help()`` shows its signature
    and documentation (a nanobind function shows as an object), and pickling finds it in ``module``."""

    @functools.wraps(function)
    def call(*args: Any, **kwargs: Any) -> Any:
        return function(*args, **kwargs)

    call.__module__ = module
    return cast(_F, call)


def develop(genome: Any, config: Any = None) -> Any:
    """Grow an embryo from one cell (paper §2.2, Fig. 2) and return an :class:`animat.Embryo`.

    Uses the [genome], [grn] and [development] sections of ``config`` (an :class:`animat.Config`;
    None = defaults). Deterministic: the same genome and config give bit-identical results. Set
    ``config["development.trace_every"] = k`` to record a trace. ``embryo.viable`` and
    ``embryo.reasons`` give the paper's viability verdict. Raises ValueError for an invalid config,
    RuntimeError if the simulation leaves its valid domain.
    """
    return _core.develop(genome, config)


def build_body(
    embryo_or_positions: Any, *args: Any, config: Any = None, allow_nonviable: bool = False, **kwargs: Any
) -> Any:
    """Build the spring-mass :class:`animat.Body` (paper §3, Fig. 3) of an :class:`animat.Embryo`,
    or of cell centres: ``build_body(positions, amplitude=None, frequency=None, phase=None)``.

    Springs are the Gabriel edges of the cell centres, regions the bounded faces, the skin the outer
    boundary. A non-viable embryo (e.g. the single cell of most random genomes) raises ValueError
    unless ``allow_nonviable=True``: draw one with :meth:`animat.Genome.random_viable`. Raises
    ValueError for bad points (wrong shape, NaN, duplicates).
    """
    if isinstance(embryo_or_positions, _core.Embryo):
        if args or kwargs:
            raise TypeError("build_body(embryo, config=None, allow_nonviable=False): no other arguments")
        return _core.build_body(embryo_or_positions, config, allow_nonviable)
    return _core.build_body(embryo_or_positions, *args, config=config, **kwargs)


def swim(
    body: Any, scene: Any = None, config: Any = None, steps: Optional[int] = None, settle_steps: Optional[int] = None
) -> Any:
    """Swim a body for ``steps`` control steps (default ``config.evaluation.steps``) and return an
    :class:`animat.SwimResult` (distance, displacement, stability and diagnostics). Never raises for
    an unstable swim: it returns ``stable=False`` and distance 0. ``settle_steps`` (default
    ``config.evaluation.settle_steps``) control steps are simulated first with actuation off (the
    crawl world, docs/worlds.md); the distance is measured from there."""
    return _core.swim(body, scene, config, steps, settle_steps=settle_steps)


def load_config(path: Union[str, os.PathLike[str]]) -> Any:
    """Load a TOML config file into an :class:`animat.Config`, or a config shipped with the package by
    name (``"paper_dn10"``, :func:`paper_configs`; a file of that name wins). ValueError naming the
    file, line and key for a bad one."""
    text = str(path)
    if not os.path.exists(text) and os.sep not in text:
        name = text[: -len(".toml")] if text.endswith(".toml") else text
        if name in paper_configs():
            return _core.load_config(str(config_path(name)))
        raise FileNotFoundError(
            f"{text}: no such file, and no packaged config of that name (packaged: {', '.join(paper_configs())})"
        )
    return _core.load_config(text)


def paper_configs() -> List[str]:
    """Names of the configs shipped with the package (``paper_dn10`` ..., ``crawl``, ``chemotaxis``)."""
    return sorted(p.stem for p in _CONFIG_DIR.glob("*.toml"))


def config_path(name: str) -> Path:
    """Path of a config shipped with the package: the paper's four environments, e.g.
    ``animat.load_config(animat.config_path("paper_dn10"))``. ValueError listing the names for an
    unknown one."""
    path = _CONFIG_DIR / (name if name.endswith(".toml") else name + ".toml")
    if not path.is_file():
        raise ValueError(f"config_path: no config named {name!r}; shipped: {', '.join(paper_configs()) or 'none'}")
    return path
