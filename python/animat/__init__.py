"""animat: co-evolution of morphology and control of soft-bodied multicellular animats.

The compiled core (``animat._core``) holds the model; this package re-exports it and adds
analysis, plotting and animation in pure Python.
"""
from ._core import *  # noqa: F401,F403
from ._core import __version__  # noqa: F401
