"""Shared test setup: the study modules are importable by their bare names.

Study code lives under studies/ and is not part of the installed package (python/animat). The tests
of those modules import them as the study scripts do, from their own folders: ``replication_store``
and ``replication_stats`` (studies/replication), ``known_swimmers`` (studies/locomotion),
``results_table`` (studies).
"""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
STUDY_DIRS = (ROOT / "studies", ROOT / "studies" / "replication", ROOT / "studies" / "locomotion")

for _d in STUDY_DIRS:
    if str(_d) not in sys.path:
        sys.path.insert(0, str(_d))
