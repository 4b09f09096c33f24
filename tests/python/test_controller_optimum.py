"""studies/regime/controller_optimum.py: the controller search's parameterisation is the symmetric
control it claims, and a committed best controller swims the distance its CSV records."""

import csv
import json
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "regime"))
import controller_optimum as co  # noqa: E402

RESULTS = ROOT / "studies" / "regime" / "results"


@pytest.mark.parametrize("name", list(co.BODIES))
def test_mirror_groups_pair_every_cell_with_its_mirror_image(name):
    body = co.BODIES[name]()
    groups = co.mirror_groups(body.positions)
    cells = sorted(k for g in groups for k in g)
    assert cells == list(range(body.cells))  # every cell in exactly one group
    for g in groups:
        assert len(g) in (1, 2)
        if len(g) == 2:
            (xi, yi), (xj, yj) = body.positions[g[0]], body.positions[g[1]]
            assert abs(xi - xj) < 0.2 and abs(yi + yj) < 0.2 and abs(yi) > 0.1
        else:  # alone only on the axis
            assert abs(body.positions[g[0]][1]) < 0.1


def test_controls_map_the_search_vector_to_the_config_ranges():
    config = co.config_for("dn0.5", 1)
    groups = [[0, 1], [2]]
    x = np.array([0.5, 0.25, 1.25, 2.0, -0.5])  # f, (a, phase) of group 0, of group 1
    amp, freq, phase = co.controls(x, groups, 3, config)
    fmin, fmax = config["development.frequency_min"], config["development.frequency_max"]
    amax = config["development.amplitude_max"]
    assert freq.tolist() == [fmin + 0.5 * (fmax - fmin)] * 3
    assert amp.tolist() == [0.25 * amax, 0.25 * amax, amax]  # amplitude clipped to [0, amplitude_max]
    assert phase == pytest.approx([0.25 * math.tau, 0.25 * math.tau, 0.5 * math.tau])  # phase in turns, wrapped


def test_a_committed_best_controller_swims_its_recorded_distance():
    with open(RESULTS / "controller_optimum_mirror.csv") as fh:
        rows = {(r["environment"], r["body"], r["seed"]): r for r in csv.DictReader(fh)}
    controllers = json.loads((RESULTS / "controller_optimum_mirror.json").read_text())
    row = rows[("dn0.5", "blob", "2")]
    c = controllers["dn0.5/blob/mirror pairs/seed2"]
    base = co.BODIES["blob"]()
    swimmer = replace(
        base, amplitude=np.array(c["amplitude"]), frequency=np.array(c["frequency"]), phase=np.array(c["phase"])
    )
    assert co.distance(swimmer, co.config_for("dn0.5", 16)) == pytest.approx(float(row["distance_s16"]), rel=1e-5)
