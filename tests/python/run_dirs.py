"""Helpers for tests that compare search run directories (animat_evolve's format, written by
animat_evolve, run_map_elites and run_nsga2 alike): the same run written twice differs only in the
wall-clock seconds the engine records."""

import json


def without_wall(out):
    """history.csv's rows and the checkpoint's payload without their wall-clock seconds."""
    rows = [line.rsplit(",", 1)[0] for line in (out / "history.csv").read_text().splitlines()]
    payload = json.loads(json.loads((out / "checkpoint.json").read_text())["payload"])
    payload.pop("wall_seconds")
    for row in payload["history"]:
        row.pop("wall_seconds")
    return rows, payload
