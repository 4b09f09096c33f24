"""Does a screen best's fitness converge as the step shrinks? Each final best kept by the calibration
screen (studies/regime/screen/<run>/, its config.toml and best_genome.json) is swum again with its own
config at physics.substeps 1, 2, 4, 16 and 32 (dt to dt/32, the same simulated time), and every
fitness is compared with the one at dt/32. A smooth swim's error shrinks steadily; a chaotic one
wanders (docs/regime.md, "The gap is not the step's").

    PYTHONPATH=build/python .venv/bin/python studies/regime/step_ladder.py \\
        --only 'dn*_c0.25_k100_seed*' 'dn*_tips2_c0.25_k100_seed*' 'dn*_c0.25_k100_f12_seed*'

Writes studies/regime/results/step_ladder.csv (one row per best: run, fitness at each step, error
at each step against dt/32) and prints a markdown table.

``--data DIR --out CSV`` swims the final bests of a packed study instead (data/<study>/<env>/run_<i>:
config.toml and the last entry of best.tar.gz), one row per run named ENV/run_I:

    PYTHONPATH=build/python .venv/bin/python studies/regime/step_ladder.py \\
        --data data/replication_regime --out studies/regime/results/step_ladder_replication_regime.csv \\
        [--jobs 2] [--modes]

``--modes`` also replays each best at every step and classifies its swim as the replication report
does (``animat.classify_locomotion``, its stroke path), adding columns mode_s1 ... mode_s32: whether
a best's mode survives refinement when its distance does not.
"""

from __future__ import annotations

import argparse
import csv
import fnmatch
import json
import sys
import tarfile
from functools import partial
from multiprocessing import Pool
from pathlib import Path
from typing import Optional

import animat
from animat import locomotion as L

ROOT = Path(__file__).resolve().parents[2]
SCREEN = ROOT / "studies" / "regime" / "screen"
OUT = ROOT / "studies" / "regime" / "results" / "step_ladder.csv"
SUBSTEPS = (1, 2, 4, 16, 32)


def final_best(run: Path, generation: Optional[int] = None) -> dict:
    """The last lineage entry of a packed run's best.tar.gz: its final best, or with ``generation``
    its best at that generation (the last entry at or before it)."""
    with tarfile.open(run / "best.tar.gz") as tar:
        names = sorted(m for m in tar.getnames() if m.endswith(".json"))
        if generation is not None:
            names = [m for m in names if int(Path(m).stem.split("_")[-1]) <= generation]
        if not names:
            raise SystemExit(f"{run}: no best at or before generation {generation}")
        member = tar.extractfile(names[-1])
        assert member is not None
        return json.loads(member.read())


def ladder(folder: Path, modes: bool = False) -> tuple:
    """The best's fitness at each of SUBSTEPS (its config otherwise), and with ``modes`` its main
    locomotion mode at each (else an empty list)."""
    if (folder / "best.tar.gz").is_file():
        entry = final_best(folder)
    else:
        entry = json.loads((folder / "best_genome.json").read_text())
    genome = animat.Genome.from_json(json.dumps(entry["genome"]))
    fits, found = [], []
    for s in SUBSTEPS:
        config = animat.load_config(str(folder / "config.toml"))
        config.physics.substeps = config.physics.substeps * s
        fits.append(float(animat.evaluate(genome, config).fitness))
        if modes:
            found.append(L.classify_locomotion(animat.replay(genome, config)).mode)
    return fits, found


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=(__doc__ or "").split("\n\n")[0])
    p.add_argument("--only", nargs="+", metavar="GLOB", help="screen runs to swim (folder names)")
    p.add_argument("--data", type=Path, help="a packed study: swim its runs' final bests instead")
    p.add_argument("--out", type=Path, default=OUT)
    p.add_argument("--jobs", type=int, default=1, help="bests swum at once (default 1)")
    p.add_argument("--modes", action="store_true", help="also classify each swim's mode at every step")
    args = p.parse_args(argv)
    if args.jobs < 1:
        p.error(f"--jobs: must be >= 1, got {args.jobs}")
    if (args.data is None) == (args.only is None):
        p.error("give --only GLOB... (screen runs) or --data DIR (a packed study)")
    if args.data is not None and args.out == OUT:
        p.error("--data needs its own --out (the default is the screen's table)")
    if args.data is not None:
        runs = sorted(r for r in args.data.glob("*/run_*") if (r / "best.tar.gz").is_file())
    else:
        runs = [
            f
            for f in sorted(SCREEN.iterdir())
            if (f / "best_genome.json").is_file() and any(fnmatch.fnmatch(f.name, g) for g in args.only)
        ]
    if not runs:
        print(f"step_ladder: no kept run matches {args.only}", file=sys.stderr)
        return 1
    header = ["run"] + [f"fitness_s{s}" for s in SUBSTEPS] + [f"error_s{s}" for s in SUBSTEPS[:-1]]
    if args.modes:
        header += [f"mode_s{s}" for s in SUBSTEPS]
    lines = [
        "| run | " + " | ".join(f"dt/{s}" if s > 1 else "dt" for s in SUBSTEPS[:-1]) + " | fitness at dt/32 |",
        "| --- | " + " | ".join("---" for _ in SUBSTEPS) + " |",
    ]
    if args.modes:  # one more column: the mode, or the mode at each step where they differ
        lines = [lines[0] + " mode (dt ... dt/32) |", lines[1] + " --- |"]
    rows = []
    with Pool(args.jobs) as pool:
        results = pool.map(partial(ladder, modes=args.modes), runs, chunksize=1)
    for f, (fit, found) in zip(runs, results):
        ref = fit[-1]
        err = [x / ref - 1 for x in fit[:-1]]
        name = f"{f.parent.name}/{f.name}" if args.data is not None else f.name
        rows.append([name] + [f"{x:.9g}" for x in fit] + [f"{e:.6g}" for e in err] + found)
        mode = (" " + (found[0] if len(set(found)) == 1 else ", ".join(found)) + " |") if found else ""
        lines.append(f"| {name} | " + " | ".join(f"{e:+.2%}" for e in err) + f" | {ref:.2f} |{mode}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(header)
        w.writerows(rows)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
