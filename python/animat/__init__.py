"""animat: co-evolution of morphology and control of soft-bodied multicellular animats.

The compiled core (``animat._core``) holds the model; this package exports it with a typed layer
organised by task:

- the pipeline: :class:`Config`, :class:`Genome` (``Genome.random_viable``), :func:`develop`,
  :func:`build_body`, :class:`Simulation`, :func:`evaluate`;
- evolution: :func:`evolve` (the engine of ``animat_evolve``), :class:`GA` (ask/tell), your own
  :class:`Objective`, :class:`History`;
- quality diversity: :class:`MapElites` (ask/tell) over a :class:`GridArchive` or :class:`CVTArchive`
  of :data:`DESCRIPTORS` (body and motion), :func:`run_map_elites` (a run directory); :mod:`animat.qd`;
- several objectives: :class:`Nsga2` (NSGA-II, ask/tell) over :data:`CRITERIA` (distance against
  actuation work, ...), the Pareto front, :func:`run_nsga2` (a run directory); :mod:`animat.moo`;
- control: :class:`SwimEnv` (Gymnasium API, registered as ``"animat/Swim-v0"``; ``pip install animat[control]``);
- analysis: :class:`Run` reads a run directory; :func:`replay` returns a :class:`Trajectory`;
  :mod:`animat.plot` draws the paper's figures; :mod:`animat.locomotion` classifies how a swimmer
  moves; :func:`animate` renders GIF/MP4;
- ``animat evolve|show|animate|info|experiment|map-elites|nsga2`` (or ``python -m animat``) does it from the shell.

Every value type pickles and copies. ``animat.plot`` imports matplotlib on first use only.
"""

from typing import TYPE_CHECKING

from . import _core, moo, qd
from ._core import (
    OBJECTIVES,
    Body,
    Config,
    ConfigSection,
    DevelopmentTrace,
    ElementType,
    Embryo,
    EnergyAccount,
    EvaluationRecord,
    EvaluationResult,
    ExternalActuation,
    Fitness,
    GenerationStats,
    Genome,
    Grn,
    GrnControl,
    Individual,
    InputChannel,
    ObjectiveSpec,
    OutputChannel,
    Rng,
    Scene,
    Simulation,
    SwimResult,
)
from .animation import animate, mp4_available
from .control import SWIM_ENV_ID, SWIM_ENV_OBJECTIVES, SwimEnv, gymnasium_available
from .evolution import (
    GA,
    EvolutionResult,
    History,
    Objective,
    evaluate,
    evaluate_population,
    evolve,
    record_evaluation,
    to_fitness,
)
from .experiment import run_experiment, run_study
from .locomotion import (
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
from .moo import CRITERIA, Criterion, Nsga2, Solution, run_nsga2
from .pipeline import build_body, config_path, develop, documented, load_config, paper_configs, swim
from .qd import (
    DESCRIPTORS,
    QD_HISTORY_DTYPE,
    CVTArchive,
    Descriptor,
    Elite,
    GridArchive,
    MapElites,
    run_map_elites,
)
from .run import (
    GENEALOGY_DTYPE,
    HISTORY_DTYPE,
    MORPHOLOGY_TOLERANCE,
    PROTECTED_GENEALOGY_DTYPE,
    PROTECTED_HISTORY_DTYPE,
    LineageEntry,
    Run,
    Snapshot,
    morphology_distance,
    read_genealogy,
    read_history,
)
from .trajectory import (
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

# getattr: the generated _core stub does not declare __version__ (a module attribute), so pyright would.
__version__: str = getattr(_core, "__version__")  # noqa: B009

# The compiled functions, as Python functions (help() shows their documentation).
actuation_start_time = documented(_core.actuation_start_time)
actuation_term = documented(_core.actuation_term)
affinity = documented(_core.affinity)
body_length = documented(_core.body_length)
delaunay_edges = documented(_core.delaunay_edges)
gabriel_graph = documented(_core.gabriel_graph)
objectives = documented(_core.objectives)
objective_value = documented(_core.objective_value)
grn_swim = documented(_core.grn_swim)
morphology_kind = documented(_core.morphology_kind)
polygon_area = documented(_core.polygon_area)
set_log_level = documented(_core.set_log_level)
tournament_probability = documented(_core.tournament_probability)
reference_config = documented(_core.reference_config)
reference_disagrees = documented(_core.reference_disagrees)
warm_up_box2d = documented(_core.warm_up_box2d)

if TYPE_CHECKING:  # animat.plot is imported lazily at run time (it pulls in matplotlib)
    from . import plot as plot

__all__ = [
    # the pipeline
    "Config",
    "ConfigSection",
    "Genome",
    "Rng",
    "ElementType",
    "InputChannel",
    "OutputChannel",
    "Grn",
    "affinity",
    "develop",
    "Embryo",
    "DevelopmentTrace",
    "build_body",
    "Body",
    "gabriel_graph",
    "delaunay_edges",
    "polygon_area",
    "body_length",
    "morphology_kind",
    "Scene",
    "Simulation",
    "ExternalActuation",
    "GrnControl",
    "swim",
    "SwimResult",
    "evaluate",
    "EvaluationResult",
    "EnergyAccount",
    "EvaluationRecord",
    "record_evaluation",
    "actuation_start_time",
    "actuation_term",
    "warm_up_box2d",
    "load_config",
    "config_path",
    "paper_configs",
    "set_log_level",
    "__version__",
    # evolution
    "evolve",
    "EvolutionResult",
    "GA",
    "Objective",
    "OBJECTIVES",
    "ObjectiveSpec",
    "objectives",
    "objective_value",
    "Fitness",
    "Individual",
    "GenerationStats",
    "History",
    "evaluate_population",
    "to_fitness",
    "tournament_probability",
    "reference_config",
    "reference_disagrees",
    "run_experiment",
    "run_study",
    # quality diversity
    "qd",
    "MapElites",
    "GridArchive",
    "CVTArchive",
    "Descriptor",
    "DESCRIPTORS",
    "Elite",
    "QD_HISTORY_DTYPE",
    "run_map_elites",
    # several objectives
    "moo",
    "Nsga2",
    "Criterion",
    "CRITERIA",
    "Solution",
    "run_nsga2",
    # control
    "SwimEnv",
    "SWIM_ENV_ID",
    "SWIM_ENV_OBJECTIVES",
    "gymnasium_available",
    "grn_swim",
    # analysis
    "Run",
    "LineageEntry",
    "Snapshot",
    "HISTORY_DTYPE",
    "PROTECTED_HISTORY_DTYPE",
    "read_history",
    "read_genealogy",
    "GENEALOGY_DTYPE",
    "PROTECTED_GENEALOGY_DTYPE",
    "morphology_distance",
    "MORPHOLOGY_TOLERANCE",
    "Trajectory",
    "replay",
    "actuation_terms",
    "actuation_rates",
    "EXPANDING",
    "CONTRACTING",
    "NEUTRAL",
    "STATE_NAMES",
    "DEFAULT_NEUTRAL",
    "animate",
    "mp4_available",
    "LocomotionMode",
    "classify_locomotion",
    "best_statistics",
    "grow_output",
    "last_morphology_change",
    "morphology_changes",
    "oscillator_spread",
    "phase_spread",
    "tries_per_viable",
    "plot",
]


def __getattr__(name: str):
    # animat.plot is imported lazily: it pulls in matplotlib.
    if name == "plot":
        import importlib

        return importlib.import_module(".plot", __name__)
    raise AttributeError(f"module 'animat' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | {"plot"})
