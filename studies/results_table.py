"""The one way a study writes its result rows: a CSV whose floats keep six significant digits, so a
rerun on another machine diffs only where a number really moved. The tables in docs/ are rebuilt
from these files.
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Iterable, Mapping, Optional, Sequence


def write_rows(path: Path, rows: Sequence[Mapping[str, object]], columns: Optional[Iterable[str]] = None) -> None:
    """Write ``rows`` to ``path`` (its folder is made). ``columns`` defaults to every key in the order
    first seen; keys starting with ``_`` are the script's own bookkeeping and are not written."""
    path = Path(path)
    if columns is None:
        columns = dict.fromkeys(k for row in rows for k in row)
    fields = [k for k in columns if not k.startswith("_")]
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, lineterminator="\n")
        w.writeheader()
        for row in rows:
            w.writerow(
                {k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items() if not k.startswith("_")}
            )
