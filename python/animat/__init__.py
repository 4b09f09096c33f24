"""animat: co-evolution of morphology and control of soft-bodied multicellular animats.

The compiled core (``animat._core``) holds the model; this package re-exports it and adds
analysis, plotting and animation in pure Python:

- :class:`Run` reads a run directory (config, history, lineage of best genomes);
- :func:`replay` swims a genome or body again and returns a :class:`Trajectory` (positions,
  centre of mass, eq. 2 actuation state of every cell and spring);
- :mod:`animat.plot` draws the paper's figures (development, construction, motion cycle, phase
  map, fitness history), each returning a matplotlib Figure;
- :mod:`animat.locomotion` classifies how a swimmer moves (:func:`classify_locomotion`) and measures
  the paper's claims about the best individuals (grow output, oscillator spread, tries per viable
  random individual, last morphological change);
- :func:`animate` renders a trajectory to GIF (or MP4 where ffmpeg exists);
- ``python -m animat show|animate|info RUN_DIR`` does it from the shell.

``animat.plot`` and ``animat.animate`` import matplotlib on first use only.
"""
from ._core import *  # noqa: F401,F403
from ._core import __version__  # noqa: F401
from .animation import animate, mp4_available  # noqa: F401
from .locomotion import (  # noqa: F401
    LocomotionMode,
    best_statistics,
    classify_locomotion,
    grow_output,
    last_morphology_change,
    morphology_changes,
    oscillator_spread,
    phase_spread,
    tries_per_viable,
)
from .run import HISTORY_DTYPE, MORPHOLOGY_TOLERANCE, LineageEntry, Run, morphology_distance, read_history  # noqa: F401
from .trajectory import (  # noqa: F401
    CONTRACTING,
    DEFAULT_NEUTRAL,
    EXPANDING,
    NEUTRAL,
    STATE_NAMES,
    Trajectory,
    actuation_rates,
    actuation_terms,
    replay,
)


def __getattr__(name):
    # animat.plot is imported lazily: it pulls in matplotlib.
    if name == "plot":
        import importlib

        return importlib.import_module(".plot", __name__)
    raise AttributeError(f"module 'animat' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | {"plot"})
from .experiment import run_experiment, run_study  # noqa: E402,F401
