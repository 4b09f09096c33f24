"""Classifies evolved bests with the classifier's stroke path (its default, docs/locomotion.md):
``animat.classify_locomotion(genome, config, stroke=True)`` next to the earlier rules
(``stroke=False``; the CSV's ``default_label``, the classifier's default before the stroke path), for

- ``replication``: the final best of every run of the replication study kept in ``data/replication``
  (``<env>/run_<i>/``: its ``config.toml`` and the last ``best/gen_*.json`` of ``best.tar.gz``, the
  best that replication_report.py classifies);
- ``screen``: every final best kept by the calibration screen, ``studies/regime/screen/<run>/`` with a
  ``best_genome.json`` (and its ``config.toml``): the folders that hold one when this runs;
- ``search``: every run kept by the search comparison, ``studies/search/kept/<run>/``: the fittest of
  its ``class_bests.json`` (each morphology class's best of the archive, which every viable, valid swim
  of the run was offered to), i.e. the run's best archived swim.

Every best is developed and swum once with its own config (``evaluation.steps``), as
``classify_locomotion(genome, config)`` does; nothing is evolved, and the classifier is deterministic
(its permutation test has a fixed seed). Writes one row per best to
``studies/regime/results/stroke_modes.csv`` and prints markdown tables: the replication's modes per
environment next to the paper's counts with Fisher's exact test (Freeman–Halton) of mode against drag,
the screen's modes per grid point and the search runs' modes. A mixed best ("undulation +
protrusions") counts under its main mode (the first of its label), as replication_report.py counts
mixed strategies; the rows "any protrusions" and "any undulation" count it under each of its modes::

    OMP_NUM_THREADS=1 PYTHONPATH=build/python .venv/bin/python studies/regime/stroke_modes.py
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
import tarfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple

import animat
from animat import locomotion as L

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "studies" / "replication"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
from summarize_screen import drag_of, point_of, repeats_of  # noqa: E402

import replication_stats as RS  # noqa: E402

REPLICATION = ROOT / "data" / "replication"
SCREEN = ROOT / "studies" / "regime" / "screen"
SEARCH = ROOT / "studies" / "search" / "kept"
OUT_CSV = ROOT / "studies" / "regime" / "results" / "stroke_modes.csv"
SOURCES = ("replication", "screen", "search")

#: The replication's environments in the order of replication_report.py (ENV_ORDER).
ENV_ORDER = ["dn0.5", "dn2", "dn10", "dn0.2_64cells"]
#: The paper's main counts per environment (of 10 runs), as replication_report.py's PAPER_COUNTS: mixed
#: strategies under their main mode where the paper says which, None where its words give no main-mode
#: count (at d_N = 2 its 2 protrusion swimmers are mixed into undulation; at d_N = 0.2 it reports only
#: protrusions and tails). Its counts of bests with protrusions at all (main or mixed) are in PAPER_ANY.
PAPER_COUNTS: Dict[str, Dict[str, Optional[int]]] = {
    "dn0.5": {"undulation": 0, "synchronous contraction": 1, "protrusions": 9, "tail": 0},
    "dn2": {"undulation": 4, "synchronous contraction": 6, "protrusions": None, "tail": 0},
    "dn10": {"undulation": 5, "synchronous contraction": 2, "protrusions": 4, "tail": 0},
    "dn0.2_64cells": {"undulation": None, "synchronous contraction": None, "protrusions": 9, "tail": 1},
}
#: The paper's bests using a mode at all (alone or mixed), from its words (paper §6).
PAPER_ANY: Dict[str, Dict[str, Optional[int]]] = {
    "dn0.5": {"protrusions": 9, "undulation": 1},  # "nine out of 10"; "only one mixed strategy involved ... undulation"
    "dn2": {"protrusions": 2, "undulation": 4},  # "in two out of 10"; "four out of 10 used undulation"
    "dn10": {"protrusions": 4, "undulation": 5},  # "in four out of 10"; "half of the best individuals"
    "dn0.2_64cells": {"protrusions": 9, "undulation": None},  # "nine out of 10 best individuals used protrusions"
}
ANY_MODES = ("protrusions", "undulation")


@dataclass
class Best:
    """One evolved best to classify, with where it comes from."""

    source: str  # "replication", "screen" or "search"
    run: str  # e.g. "dn0.5/run_3", the screen's or the search's folder name
    environment: str
    growth: str  # "paper" or "tips<N>" (development.division_max_contacts)
    damping: float
    stiffness: float
    frequency_max: float
    repeats: str  # "1" or "K mean" / "K min"
    seed: int
    fitness: float
    genome: Any  # animat.Genome
    config: Any  # animat.Config


def growth_of(config) -> str:
    contacts = config.development.division_max_contacts
    return f"tips{contacts}" if contacts > 0 else "paper"


def _best(source: str, run: str, env: str, seed: int, fitness: float, genome_json: dict, config) -> Best:
    return Best(
        source=source,
        run=run,
        environment=env,
        growth=growth_of(config),
        damping=float(config.scene.spring_damping),
        stiffness=float(config.scene.spring_stiffness),
        frequency_max=float(config.development.frequency_max),
        repeats=repeats_of(config),
        seed=seed,
        fitness=float(fitness),
        genome=animat.Genome.from_json(json.dumps(genome_json)),
        config=config,
    )


def _env_key(name: str) -> Tuple[int, str]:
    return (ENV_ORDER.index(name), "") if name in ENV_ORDER else (len(ENV_ORDER), name)


def replication_best(run_dir: Path) -> Best:
    """The final best of a packed replication run (``data/replication/<env>/run_<i>``): the last
    ``best/gen_*.json`` of its ``best.tar.gz``, with its ``config.toml``."""
    config = animat.load_config(str(run_dir / "config.toml"))
    with tarfile.open(run_dir / "best.tar.gz") as tar:
        names = sorted(n for n in tar.getnames() if Path(n).name.startswith("gen_") and n.endswith(".json"))
        if not names:
            raise ValueError(f"{run_dir / 'best.tar.gz'}: no best/gen_*.json")
        member = tar.extractfile(names[-1])
        assert member is not None
        entry = json.loads(member.read())
    env = run_dir.parent.name
    return _best(
        "replication",
        f"{env}/{run_dir.name}",
        env,
        int(config["evolution.seed"]),
        entry["fitness"],
        entry["genome"],
        config,
    )


def replication_bests(root: Path = REPLICATION) -> List[Best]:
    out = []
    if not root.is_dir():
        return out
    for env in sorted((d for d in root.iterdir() if d.is_dir()), key=lambda d: _env_key(d.name)):
        runs = [p for p in env.glob("run_*") if p.name[4:].isdigit() and (p / "best.tar.gz").is_file()]
        out += [replication_best(p) for p in sorted(runs, key=lambda p: int(p.name[4:]))]
    return out


def screen_best(folder: Path) -> Best:
    """The final best kept by the calibration screen in ``folder`` (best_genome.json, config.toml)."""
    config = animat.load_config(str(folder / "config.toml"))
    entry = json.loads((folder / "best_genome.json").read_text())
    env, _growth, _guard, _substeps, _repeats, _c, _k, _f, seed = point_of(folder, config)
    return _best("screen", folder.name, env, seed, entry["fitness"], entry["genome"], config)


def screen_bests(root: Path = SCREEN) -> List[Best]:
    if not root.is_dir():
        return []
    return [
        screen_best(f)
        for f in sorted(root.iterdir())
        if (f / "best_genome.json").is_file() and (f / "config.toml").is_file()
    ]


def search_best(folder: Path) -> Best:
    """The best archived swim of a kept search run: the fittest of its class_bests.json (the first class
    in name order among equals)."""
    config = animat.load_config(str(folder / "config.toml"))
    classes = json.loads((folder / "class_bests.json").read_text())
    name = max(sorted(classes), key=lambda c: classes[c]["fitness"])
    env, rest = folder.name.split("_", 1)
    if rest.startswith("64cells_"):
        env = f"{env}_64cells"
    seed = int(folder.name.rsplit("_seed", 1)[1])
    return _best("search", folder.name, env, seed, classes[name]["fitness"], classes[name]["genome"], config)


def search_class_bests(folder: Path) -> Dict[str, Best]:
    """Every morphology class's best of a kept search run (its class_bests.json, class name -> Best),
    for studies/search/figures.py, which classifies them all (``search_best`` is the fittest of them)."""
    config = animat.load_config(str(folder / "config.toml"))
    classes = json.loads((folder / "class_bests.json").read_text())
    env, rest = folder.name.split("_", 1)
    if rest.startswith("64cells_"):
        env = f"{env}_64cells"
    seed = int(folder.name.rsplit("_seed", 1)[1])
    return {
        name: _best("search", folder.name, env, seed, c["fitness"], c["genome"], config) for name, c in classes.items()
    }


def search_bests(root: Path = SEARCH) -> List[Best]:
    if not root.is_dir():
        return []
    return [search_best(f) for f in sorted(root.iterdir()) if (f / "class_bests.json").is_file()]


def _num(x: Optional[float]) -> float:
    return float("nan") if x is None else float(x)


def classify_best(best: Best) -> Dict[str, Any]:
    """The CSV row of one best: where it comes from, the earlier rules' label (default_label,
    ``classify_locomotion(genome, config, stroke=False)``), the stroke path's label (``stroke=True``) and
    the stroke path's numbers: the best symmetric pair's score and (smaller) loop area, whether it strokes, the
    protrusions and pairs found, the contraction wave and the bending wave."""
    # The earlier rules, named explicitly (the CSV column keeps the name default_label).
    default = animat.classify_locomotion(best.genome, best.config, stroke=False)
    mode = animat.classify_locomotion(best.genome, best.config, stroke=True)
    s = mode.stroke
    w = mode.wave
    b = mode.bend
    return {
        "source": best.source,
        "run": best.run,
        "environment": best.environment,
        "growth": best.growth,
        "damping": best.damping,
        "stiffness": best.stiffness,
        "frequency_max": best.frequency_max,
        "repeats": best.repeats,
        "seed": best.seed,
        "fitness": best.fitness,
        "default_label": default.label,
        "stroke_label": mode.label,
        "stroke_mode": mode.mode,
        "pair_score": _num(s.score) if s is not None else float("nan"),
        "pair_area": _num(s.area) if s is not None else float("nan"),
        "strokes": int(s.strokes) if s is not None else 0,
        "protrusions": len(s.protrusions) if s is not None else 0,
        "protrusions_at_rest": int(sum(s.at_rest)) if s is not None else 0,
        "pairs": len(s.pairs) if s is not None else 0,
        "coherence": mode.coherence,
        "wave_fit": w.fit if w is not None else float("nan"),
        "wave_lag": w.lag if w is not None else float("nan"),
        "travelling_index": mode.travelling_index,
        "bend_fit": b.fit if b is not None else float("nan"),
        "bend_p": _num(b.p_value) if b is not None else float("nan"),
        "bend_lag": b.lag if b is not None else float("nan"),
        "bend_angle": _num(b.angle) if b is not None else float("nan"),
        "omega": mode.omega,
        "reason": mode.reason,
    }


def _fmt(v: Any) -> Any:
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.6g}"
    return v


def write_csv(rows: Sequence[Dict[str, Any]], path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]), lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: _fmt(v) for k, v in r.items()})


def main_mode(label: str) -> str:
    """The main mode of a label ("undulation + protrusions" -> "undulation"): how replication_report.py
    counts a mixed strategy."""
    return label.split(" + ")[0]


def has_mode(label: str, mode: str) -> bool:
    """Whether ``mode`` is in a label at all, as its main mode or mixed in."""
    return mode in label.split(" + ")


# --- tables -----------------------------------------------------------------------------------------------


def _counts(labels: Sequence[str]) -> str:
    modes = [m for m in L.MODES if any(main_mode(x) == m for x in labels)]
    parts = []
    for m in modes:
        mine = [x for x in labels if main_mode(x) == m]
        mixed = sorted({x for x in mine if x != m})
        parts.append(f"{m} {len(mine)}" + (f" ({', '.join(f'{mine.count(x)} {x}' for x in mixed)})" if mixed else ""))
    return ", ".join(parts)


def fisher_line(title: str, labels: Dict[str, List[str]], groups: str = "environments") -> str:
    rows, cols, table = RS.mode_table({e: [main_mode(x) for x in v] for e, v in labels.items()}, list(L.MODES))
    res = RS.fisher_exact(table)
    return (
        f"Fisher's exact test (Freeman–Halton) of main mode against {title}: p = {res.p_value:.3g} "
        f"({res.method}, {res.tables} tables; {res.shape[0]} modes × {res.shape[1]} {groups}, "
        f"{int(table.sum())} bests)."
    )


def replication_lines(rows: Sequence[Dict[str, Any]]) -> List[str]:
    envs = sorted({r["environment"] for r in rows}, key=_env_key)
    if not envs:
        return []
    stroke = {e: [r["stroke_label"] for r in rows if r["environment"] == e] for e in envs}
    default = {e: [r["default_label"] for r in rows if r["environment"] == e] for e in envs}
    out = [
        "### Replication: modes per environment",
        "",
        "Main mode (a mixed best counts under its main mode): the stroke path / the earlier rules / "
        'the paper (of 10; "?" where its words give no main-mode count). "any": bests with the mode as main '
        "mode or mixed in.",
        "",
        "| mode | " + " | ".join(f"`{e}` (of {len(stroke[e])}): stroke / earlier / paper" for e in envs) + " |",
        "| --- | " + " | ".join("---" for _ in envs) + " |",
    ]
    used = [
        m
        for m in L.MODES
        if m in ("undulation", "synchronous contraction", "protrusions", "tail")
        or any(main_mode(x) == m for e in envs for x in stroke[e] + default[e])
    ]
    for m in used:
        cells = []
        for e in envs:
            paper = PAPER_COUNTS.get(e, {}).get(m, 0 if m in ("other", "none") else None)
            s = sum(main_mode(x) == m for x in stroke[e])
            d = sum(main_mode(x) == m for x in default[e])
            cells.append(f"{s} / {d} / {'?' if paper is None else paper}")
        out.append(f"| {m} | " + " | ".join(cells) + " |")
    for m in ANY_MODES:
        cells = []
        for e in envs:
            paper = PAPER_ANY.get(e, {}).get(m)
            s = sum(has_mode(x, m) for x in stroke[e])
            d = sum(has_mode(x, m) for x in default[e])
            cells.append(f"{s} / {d} / {'?' if paper is None else paper}")
        out.append(f"| *any {m}* | " + " | ".join(cells) + " |")
    out.append("")
    out.append("Stroke labels per run: " + "; ".join(f"`{e}` {_counts(stroke[e])}" for e in envs) + ".")
    out.append("")
    drag = [e for e in envs if e in ("dn0.5", "dn2", "dn10")]
    for name, labels in (("stroke path", stroke), ("earlier rules", default)):
        if len(drag) >= 2:
            out.append(
                f"{name}: " + fisher_line("drag over the three 32-cell environments", {e: labels[e] for e in drag})
            )
            out.append("")
        if len(envs) >= 2:
            out.append(f"{name}: " + fisher_line("environment over all environments", labels))
            out.append("")
    return out


def screen_key(r: Dict[str, Any], guard: str, substeps: int) -> Tuple:
    return (
        r["environment"],
        r["growth"],
        guard,
        substeps,
        r["repeats"],
        float(r["damping"]),
        float(r["stiffness"]),
        float(r["frequency_max"]),
    )


def screen_lines(rows: Sequence[Dict[str, Any]], points: Dict[str, Tuple[str, int]]) -> List[str]:
    """Modes per grid point of the screen (the points of summarize_screen.py); ``points`` maps a run
    to its guard and substeps."""
    if not rows:
        return []
    key = {r["run"]: screen_key(r, *points[r["run"]]) for r in rows}
    grid = sorted(set(key.values()), key=lambda p: (drag_of(p[0]), p[1], p[2], p[3], p[4], -p[5], -p[6], p[7]))
    out = [
        "### Screen: modes per grid point",
        "",
        "| environment | growth | guard | substeps | repeats | damping | stiffness | frequency max | runs | stroke path | "
        "earlier rules |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for p in grid:
        sel = [r for r in rows if key[r["run"]] == p]
        env, growth, guard, substeps, repeats, c, k, f = p
        out.append(
            f"| {env} | {growth} | {guard} | {substeps} | {repeats} | {c:g} | {k:g} | {f:g} | {len(sel)} | "
            f"{_counts([r['stroke_label'] for r in sel])} | {_counts([r['default_label'] for r in sel])} |"
        )
    out.append("")
    base = [
        r
        for r in rows
        if points[r["run"]] == ("record", 1)
        and r["repeats"] == "1"
        and float(r["stiffness"]) == 100
        and float(r["frequency_max"]) == 6
    ]
    envs = sorted({r["environment"] for r in base}, key=drag_of)
    growths = sorted({r["growth"] for r in base})
    out.append(
        "Pooled over the damping values at the base settings (guard record, substeps 1, repeats 1, stiffness 100, "
        "frequencies up to 6): mode against "
        "drag per growth rule (the drags run at all of the rule's damping values), mode against growth per drag "
        "(the damping values both rules were run at):"
    )
    out.append("")
    for g in growths:
        # the drags at which this growth rule was run at all of its damping values (not d_N = 2: damping 1 only)
        dampings = {e: {float(r["damping"]) for r in base if r["growth"] == g and r["environment"] == e} for e in envs}
        full = set().union(*dampings.values())
        labels = {
            e: [r["stroke_label"] for r in base if r["growth"] == g and r["environment"] == e]
            for e in envs
            if dampings[e] == full
        }
        if len(labels) >= 2:
            desc = ", ".join(f"`{e}` {_counts(v)}" for e, v in labels.items())
            out.append(f"- {g}: {desc}. " + fisher_line(f"drag ({g})", labels, "drags"))
    for e in envs:
        dampings = [
            {float(r["damping"]) for r in base if r["growth"] == g and r["environment"] == e}
            for g in ("paper", "tips2")
        ]
        shared = dampings[0] & dampings[1]
        labels = {
            g: [
                r["stroke_label"]
                for r in base
                if r["growth"] == g and r["environment"] == e and float(r["damping"]) in shared
            ]
            for g in ("paper", "tips2")
        }
        if shared and all(labels.values()):
            desc = ", ".join(f"{g} {_counts(v)}" for g, v in labels.items())
            damp = ", ".join(f"{c:g}" for c in sorted(shared, reverse=True))
            out.append(f"- `{e}`, damping {damp}: {desc}. " + fisher_line(f"growth at `{e}`", labels, "growth rules"))
    out.append("")
    return out


def _two(x: float) -> str:
    return "—" if math.isnan(x) else f"{x:.2f}"


def search_lines(rows: Sequence[Dict[str, Any]]) -> List[str]:
    if not rows:
        return []
    out = [
        "### Search comparison: modes of each run's best",
        "",
        "| run | fitness | stroke path | earlier rules | pair score | pair area |",
        "| --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        out.append(
            f"| {r['run']} | {r['fitness']:.1f} | {r['stroke_label']} | {r['default_label']} | "
            f"{_two(r['pair_score'])} | {_two(r['pair_area'])} |"
        )
    out.append("")
    return out


def transition_lines(rows: Sequence[Dict[str, Any]]) -> List[str]:
    """Main mode by the earlier rules (rows) against the stroke path (columns), over all bests."""
    modes = [m for m in L.MODES if any(main_mode(r[k]) == m for r in rows for k in ("default_label", "stroke_label"))]
    out = [
        f"### The earlier rules (rows) against the stroke path (columns), main modes, all {len(rows)} bests",
        "",
        "| earlier \\ stroke | " + " | ".join(modes) + " |",
        "| --- | " + " | ".join("---" for _ in modes) + " |",
    ]
    for a in modes:
        cells = [
            str(sum(main_mode(r["default_label"]) == a and main_mode(r["stroke_label"]) == b for r in rows))
            for b in modes
        ]
        out.append(f"| {a} | " + " | ".join(cells) + " |")
    out.append("")
    return out


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(
        description=(__doc__ or "").split("\n\n")[0], formatter_class=argparse.RawTextHelpFormatter
    )
    p.add_argument("--sources", default=",".join(SOURCES), help="comma-separated: replication, screen, search")
    p.add_argument("--out", type=Path, default=OUT_CSV, help="the CSV to write")
    args = p.parse_args(argv)
    sources = [s for s in args.sources.split(",") if s]
    unknown = [s for s in sources if s not in SOURCES]
    if unknown:
        p.error(f"unknown source(s): {', '.join(unknown)}")
    bests: List[Best] = []
    if "replication" in sources:
        bests += replication_bests()
    if "screen" in sources:
        bests += screen_bests()
    if "search" in sources:
        bests += search_bests()
    if not bests:
        print("stroke_modes: no bests found", file=sys.stderr)
        return 1
    points = {}
    rows = []
    for k, b in enumerate(bests):
        if b.source == "screen":
            _e, _g, guard, substeps, *_ = point_of(SCREEN / b.run, b.config)
            points[b.run] = (guard, substeps)
        rows.append(classify_best(b))
        print(f"[{k + 1}/{len(bests)}] {b.source} {b.run}: {rows[-1]['stroke_label']}", file=sys.stderr, flush=True)
    write_csv(rows, args.out)
    lines: List[str] = []
    lines += replication_lines([r for r in rows if r["source"] == "replication"])
    lines += screen_lines([r for r in rows if r["source"] == "screen"], points)
    lines += search_lines([r for r in rows if r["source"] == "search"])
    lines += transition_lines(rows)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
