"""Load time of an ``animat explore`` page in headless Chromium: a synthetic 1,000-generation study.

    PYTHONPATH=build/python .venv/bin/python bench/explore_load.py [--runs 4] [--generations 1000] [--repeat 5]

Each run of the study is a real (tiny) run, evolved here with the default config (the paper's 32 cells,
4000 swim steps), whose history.csv is then replaced by ``--generations`` synthetic rows (a rising
best, a noisy mean, invalid swims and unconfirmed bests now and then), whose lineage gets 80 entries
(the same genome) and which gets a genealogy.csv of 100 individuals per generation. The page is built
as ``animat explore STUDY --out FILE`` builds it and opened ``--repeat`` times from the file in
Chromium (Debian's ``/usr/bin/chromium`` driven by playwright, as tests/python/test_explore.py does).

Prints the machine, the page size, the build time and the load time: from the start of the navigation
to the page's ``animatExplore.ready`` (``performance.now()`` when the script has drawn everything: the
curves, the first swim frame, the phase map, the lineage and the genealogy), median and maximum. The
target is under 2 s.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

import animat
from animat import explore

HEADER = ",".join(animat.HISTORY_DTYPE.names or ())


def synthetic_study(root: Path, runs: int, generations: int, population: int = 100) -> Path:
    """``root/study/env_<e>/run_<i>``: real tiny runs with synthetic long histories (see the module docstring)."""
    base = root / "base"
    config = animat.Config()
    config["evolution.population"] = 6
    animat.evolve(config, out=str(base), generations=1, quiet=True)
    best = json.loads(sorted((base / "best").glob("gen_*.json"))[-1].read_text())
    study = root / "study"
    for k in range(runs):
        rng = np.random.default_rng(k)
        run = study / f"env_{k % 2}" / f"run_{k // 2}"
        shutil.copytree(base, run)
        shutil.rmtree(run / "best")
        (run / "best").mkdir()
        cfg = animat.load_config(run / "config.toml")
        cfg["evolution.seed"] = k  # the runs of a study differ by their seed
        (run / "config.toml").write_text(cfg.to_toml())
        g = np.arange(generations)
        best_f = np.maximum.accumulate(np.cumsum(rng.exponential(0.05, generations) * (rng.random(generations) < 0.08)))
        reference = best_f * np.where(rng.random(generations) < 0.02, 0.9, 1.0)
        mean = best_f * rng.uniform(0.2, 0.4, generations)
        rows = []
        for i in g:
            values = {
                "generation": i,
                "best": repr(float(best_f[i])),
                "mean": repr(float(mean[i])),
                "median": repr(float(mean[i])),
                "viable_fraction": f"{rng.uniform(0.6, 1):.3f}",
                "best_cells": 32,
                "evaluations": (i + 1) * 100,
                "swims": population,
                "best_reference": repr(float(reference[i])),
                "invalid": int(rng.random() < 0.05),
                "drag_limited": 0,
                "wall_seconds": f"{i * 3.1:.1f}",
            }
            rows.append(",".join(str(values[name]) for name in HEADER.split(",")))
        (run / "history.csv").write_text(HEADER + "\n" + "\n".join(rows) + "\n")
        changes = np.unique(np.linspace(0, generations - 1, 80).astype(int))
        ids = {}
        for c in changes:
            ids[int(c)] = int(c) * population
            (run / "best" / f"gen_{c:06d}.json").write_text(
                json.dumps({**best, "generation": int(c), "fitness": float(best_f[c]), "id": ids[int(c)]})
            )
        lines = ["generation,id,parent_a,parent_b,fitness,cells"]
        for gen in range(generations):
            for j in range(population):
                i = gen * population + j
                if gen == 0:
                    a = b = -1
                else:
                    a = (gen - 1) * population + int(rng.integers(population))
                    b = (gen - 1) * population + int(rng.integers(population)) if rng.random() < 0.2 else -1
                lines.append(f"{gen},{i},{a},{b},{float(mean[gen]):.6g},32")
        (run / "genealogy.csv").write_text("\n".join(lines) + "\n")
    return study


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", type=int, default=4)
    p.add_argument("--generations", type=int, default=1000)
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--chromium", default=os.environ.get("ANIMAT_CHROMIUM", "/usr/bin/chromium"))
    p.add_argument("--keep", type=Path, help="also copy the page here")
    args = p.parse_args()
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as tmp:
        study = synthetic_study(Path(tmp), args.runs, args.generations)
        t0 = time.perf_counter()
        page = explore.write_page([study], Path(tmp) / "explore.html")
        build = time.perf_counter() - t0
        size = page.stat().st_size
        if args.keep:
            shutil.copy(page, args.keep)
        loads, walls = [], []
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=args.chromium)
            for _ in range(args.repeat):
                tab = browser.new_page(viewport={"width": 1200, "height": 900})
                t = time.perf_counter()
                tab.goto(page.as_uri())
                tab.wait_for_function("window.animatExplore && window.animatExplore.ready")
                walls.append(time.perf_counter() - t)
                loads.append(tab.evaluate("animatExplore.loadMs") / 1000)
                errors = tab.evaluate("animatExplore.errors")
                assert not errors, errors
                tab.close()
            version = browser.version
            browser.close()
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; animat "
        f"{animat.__version__}; Chromium {version}"
    )
    print(f"study: {args.runs} runs x {args.generations} generations (genealogy: 100 per generation)")
    print(f"page: {size / 1e3:.0f} kB, built in {build:.1f} s")
    print(
        f"load (navigation start to ready): median {statistics.median(loads):.3f} s, max {max(loads):.3f} s "
        f"over {args.repeat}; goto + ready as seen by playwright: median {statistics.median(walls):.3f} s"
    )


if __name__ == "__main__":
    main()
