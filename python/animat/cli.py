"""``animat`` (or ``python -m animat``): evolve, and the paper's figures and an animation of a run's best swimmer.

    animat evolve [animat_evolve's flags]   # the config's search: the GA (animat_evolve), or with
                                        #   search.algorithm = "map_elites" / "nsga2" those, same flags
    python -m animat show RUN_DIR       # figures/ development, construction, motion_cycle, phase_map, fitness_history
                                        #   (+ stiffness_map for a body with evolved stiffness)
    python -m animat animate RUN_DIR    # figures/best.gif
    python -m animat info RUN_DIR       # a short summary of the run
    python -m animat explore RUN_DIR... # one HTML page: curves, lineage, genealogy, the best's swim (--serve --live)
    python -m animat experiment CONFIG --runs N --out DIR   # N independent seeds, resumable, with a summary
    mpirun -np R python -m animat experiment NAME=CONFIG ... --runs N --out DIR --mpi   # a study over MPI ranks
    python -m animat map-elites CONFIG --out DIR [--descriptors NAME,NAME] [--bins B,B] [--mpi]   # MAP-Elites
    python -m animat nsga2 CONFIG --out DIR [--objectives NAME:max,NAME:min] [--mpi]   # NSGA-II
        (their options set search.descriptors, search.bins and search.objectives; OUT holding a run resumes it)

Every command exits with status 1 and a one-line message for a missing or malformed run directory.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import List, Optional, Sequence

from .pool import MpiAbort

FIGURES = ("development", "construction", "motion_cycle", "phase_map", "stiffness_map", "fitness_history")


def _size(text: str):
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT in pixels, e.g. 560x360, got {text!r}") from None
    return w, h


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="animat", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    sub = p.add_subparsers(
        dest="command", required=True, metavar="{evolve,show,animate,info,explore,experiment,map-elites,nsga2}"
    )

    sub.add_parser(
        "evolve",
        add_help=False,
        help="run the config's search with animat_evolve's flags (animat evolve --help lists them): the GA "
        "in animat_evolve's engine, or MAP-Elites / NSGA-II when search.algorithm says so",
    )

    s = sub.add_parser(
        "show",
        help="write the paper's figures for the run's best genome into RUN_DIR/figures/ "
        "(a packed run of data/: runs/<its path below data>/figures/)",
    )
    s.add_argument("run", metavar="RUN_DIR")
    s.add_argument("--out", type=Path, help="output directory (default RUN_DIR/figures; see above for a packed run)")
    s.add_argument(
        "--only",
        nargs="+",
        choices=FIGURES,
        help="draw only these figures (default: all; stiffness_map only for a body with evolved stiffness)",
    )
    s.add_argument("--frames", type=int, default=6, help="snapshots in the motion cycle (default 6)")
    s.add_argument("--steps", type=int, help="swim steps to replay (default: the run's evaluation.steps)")
    s.add_argument("--dpi", type=int, default=110, help="PNG resolution (default 110)")

    a = sub.add_parser("animate", help="render the run's best swimmer to RUN_DIR/figures/best.gif")
    a.add_argument("run", metavar="RUN_DIR")
    a.add_argument(
        "--out",
        type=Path,
        help="output file, .gif or .mp4 (default RUN_DIR/figures/best.gif; for a packed run runs/<path below data>/figures/best.gif)",
    )
    a.add_argument("--fps", type=float, default=25.0, help="frames per second (default 25)")
    a.add_argument("--max-frames", type=int, default=240, help="at most this many frames (default 240)")
    a.add_argument("--start", type=int, help="first control step to show (default: show the end of the swim)")
    a.add_argument("--steps", type=int, help="swim steps to replay (default: the run's evaluation.steps)")
    a.add_argument("--size", type=_size, default=(560, 360), help="WIDTHxHEIGHT pixels (default 560x360)")
    a.add_argument("--colors", type=int, default=64, help="GIF palette size (default 64)")
    a.add_argument("--follow", action="store_true", default=None, help="camera follows the body")
    a.add_argument("--no-progress", action="store_true", help="no progress bar")

    i = sub.add_parser(
        "info", help="print a summary of a run directory: a GA, MAP-Elites or NSGA-II run, or a packed run of data/"
    )
    i.add_argument("run", metavar="RUN_DIR")

    x = sub.add_parser(
        "explore",
        help="write one self-contained HTML page for runs or a study (curves, lineage, genealogy, swims)",
        description="One HTML page for one or several run directories (GA, MAP-Elites, NSGA-II, or packed runs "
        "of data/), or an experiment directory of `animat experiment`: fitness curves overlaid or per group "
        "(median and IQR), the lineage and genealogy of each best, its swim animated, a search's archive or "
        "front, the phase map, config differences. It works offline from a file (docs/python.md, "
        "docs/explore.md). Packed runs are read in place; their page goes to runs/<path below data>/.",
    )
    x.add_argument("runs", metavar="RUN_DIR", nargs="+", help="run directories or experiment directories")
    x.add_argument(
        "--out",
        type=Path,
        help="the page to write (default RUN_DIR/explore.html for one RUN_DIR, runs/<path below data>/explore.html "
        "for packed runs; needed for several)",
    )
    x.add_argument("--modes", action="store_true", help="classify every best's locomotion (a few seconds per run)")
    x.add_argument(
        "--frames",
        type=int,
        help="frames of each best's swim at most (default 200; 60 on a page of more than 8 runs)",
    )
    x.add_argument(
        "--replays",
        type=int,
        help="swims embedded per run besides the best's, of record holders or of a search's elites "
        "(default 12; none on a page of more than 8 runs; a served page replays any on request)",
    )
    x.add_argument("--max-points", type=int, default=500, help="generations per curve at most (default 500)")
    x.add_argument("--serve", action="store_true", help="serve the page on http://127.0.0.1:PORT/ until Ctrl-C")
    x.add_argument("--port", type=int, default=8765, help="port of --serve (default 8765; 0: any free port)")
    x.add_argument("--live", action="store_true", help="with --serve: the page polls the runs and redraws as they grow")
    x.add_argument("--poll", type=float, default=2.0, help="seconds between live polls (default 2)")

    e = sub.add_parser("experiment", help="run (or resume) N independent seeds of a config and summarise them")
    e.add_argument(
        "config",
        metavar="CONFIG",
        nargs="+",
        help="TOML config file; several as NAME=CONFIG make a study in OUT/NAME/ (docs/cluster.md)",
    )
    e.add_argument("--runs", type=int, default=3, help="independent runs, seeds evolution.seed + 0..N-1 (default 3)")
    e.add_argument("--out", required=True, help="experiment directory (run_<i>/ per run, summary.json, summary.md)")
    e.add_argument("--parallel", type=int, default=1, help="runs at once; the cores are split between them")
    e.add_argument("--threads", type=int, default=0, help="cores in all (default: all)")
    e.add_argument("--generations", type=int, help="per-run generation cap (overrides the config)")
    e.add_argument("--wall-seconds", type=float, help="per-run wall-clock budget in seconds (overrides the config)")
    e.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override a config value")
    e.add_argument("--quiet", action="store_true", help="no per-run lines")
    e.add_argument(
        "--mpi",
        action="store_true",
        help="place the runs on the ranks of an MPI job: mpirun -np R python -m animat experiment ... --mpi "
        "(needs mpi4py)",
    )
    e.add_argument(
        "--index",
        type=int,
        action="append",
        metavar="I",
        help="run only run I of the study, numbered environment-major (one Slurm array task: "
        "--index $SLURM_ARRAY_TASK_ID); repeatable; writes no summary",
    )
    _search_parsers(sub)
    return p


def _search_parsers(sub) -> None:
    from .moo import CRITERIA
    from .qd import DESCRIPTORS

    m = sub.add_parser(
        "map-elites",
        help="run (or resume) MAP-Elites from a config into a run directory",
        description="MAP-Elites (docs/python.md, section 7b) from a config: animat.run_map_elites into OUT "
        "(config.toml, history.csv, archive/gen_*.csv, checkpoint.json). OUT holding a MAP-Elites run: the "
        "same command resumes it.",
    )
    n = sub.add_parser(
        "nsga2",
        help="run (or resume) NSGA-II from a config into a run directory",
        description="NSGA-II (docs/python.md, section 7c) from a config: animat.run_nsga2 into OUT "
        "(config.toml, history.csv, front/gen_*.csv, checkpoint.json). OUT holding an NSGA-II run: the "
        "same command resumes it.",
    )
    for q in (m, n):
        q.add_argument(
            "config", metavar="CONFIG", help="TOML config file, or a packaged config by name (paper_dn2 ...)"
        )
        q.add_argument("--out", required=True, type=Path, help="the run directory (a run there is resumed)")
    m.add_argument(
        "--descriptors",
        metavar="NAME,NAME",
        help=f"the archive's descriptors, of {', '.join(DESCRIPTORS)}: sets search.descriptors (default: the config's)",
    )
    m.add_argument(
        "--bins",
        metavar="B[,B...]",
        help="grid bins: one count for every descriptor, or one each: sets search.bins (default: the config's)",
    )
    n.add_argument(
        "--objectives",
        metavar="NAME[:SENSE],...",
        help=f"the objectives, each max or min (default: the table's sense), of {', '.join(CRITERIA)}: sets "
        "search.objectives (default: the config's)",
    )
    m.add_argument(
        "--batch",
        type=int,
        help="offspring per generation: sets search.batch (default: the config's; 0 = evolution.population)",
    )
    n.add_argument(
        "--population", type=int, help="population and offspring per generation (default evolution.population)"
    )
    for q, snapshots in ((m, "archive"), (n, "front")):
        q.add_argument(
            "--generations", type=int, help="run up to this generation (default evolution.generations, when set)"
        )
        q.add_argument("--seed", type=int, help="the run's seed (default evolution.seed)")
        q.add_argument(
            "--threads", type=int, help="evaluation threads per rank (default evolution.threads; 0 = all cores)"
        )
        q.add_argument(
            f"--{snapshots}-every",
            type=int,
            default=10 if snapshots == "archive" else 1,
            help=f"write {snapshots}/gen_NNNNNN.csv every this many generations and at the last "
            f"(default {10 if snapshots == 'archive' else 1})",
        )
        q.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override a config value")
        q.add_argument(
            "--mpi",
            action="store_true",
            help="swim on the ranks of an MPI job: mpirun -np R python -m animat ... --mpi (needs mpi4py); "
            "the same run as without",
        )
        q.add_argument("--quiet", action="store_true", help="no line per generation")
        q.set_defaults(resume=None, overwrite=False)  # OUT holding a run resumes it


def has_evolved_stiffness(run, entry=None) -> bool:
    """True when the run's best body has evolved stiffness: the GRN output ``stiffness`` is enabled
    (``genome.extra_outputs``) or the body carries per-cell factors (``Body.stiffness``)."""
    from .trajectory import body_of

    config = run.config
    if "stiffness" in [c.strip() for c in str(config["genome.extra_outputs"]).split(",")]:
        return True
    try:
        return len(body_of(entry if entry is not None else run.best(), config).stiffness) > 0
    except ValueError:
        return False


def show_figures(run, only=None, *, frames: int = 6, steps: Optional[int] = None):
    """The figures of ``animat show`` for a run (an :class:`animat.Run`), in order: a dict of figure
    name -> a function that draws it (a matplotlib Figure). ``only`` picks names of :data:`FIGURES`
    (default: all of them, ``stiffness_map`` only when the best body has evolved stiffness,
    :func:`has_evolved_stiffness`, ``phase_map`` only when oscillators drive the swim,
    :func:`animat.plot.oscillator_phases_used`; for a MAP-Elites or NSGA-II run, whose best is that of its last
    archive or front, all but ``fitness_history``, which draws the GA's history). Every figure names
    the run's objective and world where it has a title to do so."""
    import animat
    from animat import plot

    entry = run.best()
    config = run.config
    search = run.search != "ga"
    if only and search and "fitness_history" in only:
        raise ValueError(
            f"{run.path}: fitness_history draws the GA's history.csv; this is a {run.search} run "
            "(animat explore draws its curves and its archive or front)"
        )
    wanted = (
        list(only)
        if only
        else [
            n
            for n in FIGURES
            if (n != "stiffness_map" or has_evolved_stiffness(run, entry))
            and not (search and n == "fitness_history")
            and (n != "phase_map" or plot.oscillator_phases_used(config))  # no oscillator runs: nothing to map
        ]
    )
    objective, _, _ = plot.objective_info(config)
    label = f"best of {run.path.name}: generation {entry.generation}, fitness ({objective}) {entry.fitness:.3f}"
    cache = {}

    def trajectory():
        if "tr" not in cache:
            cache["tr"] = animat.replay(entry, config, steps=steps)
        return cache["tr"]

    makers = {
        "development": lambda: plot.development(
            entry, config=config, title=f"Development (paper Fig. 2) of the {label}"
        ),
        "construction": lambda: plot.construction(
            entry, config=config, title=f"From embryo to body (paper Fig. 3): {label}"
        ),
        "motion_cycle": lambda: plot.motion_cycle(trajectory(), count=frames),
        "phase_map": lambda: plot.phase_map(entry, config=config),
        "stiffness_map": lambda: plot.stiffness_map(entry, config=config),
        "fitness_history": lambda: plot.fitness_history(run),
    }
    return {name: makers[name] for name in FIGURES if name in wanted}


def output_home(path: Path, packed: bool) -> Path:
    """Where a command writes what it makes of the run (or study) at ``path``: ``path`` itself, but for
    packed runs, which are read-only data (``data/``), ``runs/<the path below data/>`` of the current
    directory (``runs/replication_regime/dn0.5/run_0``)."""
    if not packed:
        return path
    parts = path.resolve().parts
    below = parts[len(parts) - parts[::-1].index("data") :] if "data" in parts else parts[-1:]
    return Path("runs", *below) if below else Path("runs")


def cmd_show(args) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import animat

    run = animat.Run(args.run)
    entry = run.best()
    out = args.out or output_home(run.path, run.packed) / "figures"
    t0 = time.perf_counter()
    figures = show_figures(run, args.only, frames=args.frames, steps=args.steps)  # refuses before any file
    out.mkdir(parents=True, exist_ok=True)
    for name, make in figures.items():
        fig = make()
        path = out / f"{name}.png"
        fig.savefig(path, dpi=args.dpi)
        plt.close(fig)
        print(path)
    print(
        f"(best of {run.path.name}: generation {entry.generation}, fitness ({run.config['evaluation.objective']}) "
        f"{entry.fitness:.3f}; {time.perf_counter() - t0:.1f} s)",
        file=sys.stderr,
    )
    return 0


def cmd_animate(args) -> int:
    import animat

    run = animat.Run(args.run)
    entry = run.best()
    config = run.config
    out = args.out or output_home(run.path, run.packed) / "figures" / "best.gif"
    t0 = time.perf_counter()
    trajectory = animat.replay(entry, config, steps=args.steps)
    start = None if args.start is None else trajectory.frame_index(args.start)
    path = animat.animate(
        trajectory,
        out,
        fps=args.fps,
        max_frames=args.max_frames,
        start=start,
        size=args.size,
        colors=args.colors,
        follow=args.follow,
        progress=False if args.no_progress else None,
    )
    print(path)
    print(
        f"(best of {run.path.name}: generation {entry.generation}, fitness ({config['evaluation.objective']}) "
        f"{entry.fitness:.3f}; {time.perf_counter() - t0:.1f} s)",
        file=sys.stderr,
    )
    return 0


def cmd_info(args) -> int:
    import animat

    run = animat.Run(args.run)
    print(run.summary())
    changes = run.morphology_changes() if run.best_genomes else []
    if changes:
        print(f"  morphology changed at generation(s) {', '.join(str(e.generation) for e in changes)}")
    return 0


def cmd_explore(args) -> int:
    from . import explore

    if args.frames is not None and args.frames < 2:
        raise ValueError(f"--frames must be at least 2, got {args.frames}")
    if args.replays is not None and args.replays < 0:
        raise ValueError(f"--replays must be at least 0, got {args.replays}")
    if args.max_points < 10:
        raise ValueError(f"--max-points must be at least 10, got {args.max_points}")
    if args.poll <= 0:
        raise ValueError(f"--poll must be positive, got {args.poll}")
    if args.live and not args.serve:
        raise ValueError("--live needs --serve (a page opened from a file cannot poll)")
    if not 0 <= args.port <= 65535:
        raise ValueError(f"--port must be in 0..65535, got {args.port}")
    refs = explore.find_runs(args.runs)  # every path checked before anything runs
    out = args.out
    if out is None and not args.serve:
        if len(args.runs) > 1:
            raise ValueError(f"{len(args.runs)} RUN_DIRs: name the page with --out FILE.html")
        from .run import Run

        packed = any(Run(r.path).packed for r in refs)
        out = output_home(Path(args.runs[0]), packed) / "explore.html"
    t0 = time.perf_counter()
    live = {"poll": args.poll, "max_polls": 20000} if args.live else None
    data = explore.build_data(
        args.runs,
        frames=args.frames,
        max_points=args.max_points,
        modes=args.modes,
        replays=args.replays,
        live=live,
        refs=refs,
    )
    page = explore.render_html(data)
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(page, encoding="utf-8")
        print(out)
    print(
        f"({len(refs)} run(s), {len(page.encode('utf-8')) / 1e3:.0f} kB; {time.perf_counter() - t0:.1f} s)",
        file=sys.stderr,
    )
    if args.serve:
        try:
            explore.serve(
                args.runs,
                port=args.port,
                live=args.live,
                poll=args.poll,
                page=page,
                log=lambda m: print(m, flush=True),
                frames=args.frames,
                max_points=args.max_points,
                modes=args.modes,
                replays=args.replays,
            )
        except KeyboardInterrupt:
            print("(stopped serving)", file=sys.stderr)
    return 0


def cmd_experiment(args) -> int:
    from .experiment import run_study, summarize

    by_env = run_study(
        args.config,
        args.runs,
        args.out,
        mpi=args.mpi,
        index=args.index,
        parallel=args.parallel,
        threads=args.threads,
        generations=args.generations,
        wall_seconds=args.wall_seconds,
        overrides=args.set,
        quiet=args.quiet,
        log=lambda m: print(m, flush=True),
    )
    nested = len(by_env) > 1 or "=" in args.config[0]
    for name, records in by_env.items():
        where = f"{args.out}/{name}" if nested else args.out
        if args.index is not None:
            for r in records:
                print(f"{where}/run_{r.index}: best {r.best:.4f} after {r.generations} generations ({r.stop_reason})")
            continue
        stats = summarize(records)
        if stats:
            print(
                f"{where}: median best fitness {stats['median']:.4f} over {stats['runs']} runs "
                f"(min {stats['min']:.4f}, max {stats['max']:.4f}); see {where}/summary.md"
            )
    return 0


def _names(option: str, text: str, table) -> List[str]:
    names = [t.strip() for t in text.split(",")]
    for name in names:
        if name not in table:
            raise ValueError(f"{option} {text!r}: no name {name!r}; the names are {', '.join(table)}")
    if len(set(names)) != len(names):
        raise ValueError(f"{option} {text!r}: a name appears twice")
    return names


def _at_least(option: str, value: Optional[int], least: int) -> None:
    if value is not None and value < least:
        raise ValueError(f"{option} must be >= {least}, got {value}")


def _search_config(args, search: Sequence[str] = ()):
    """CONFIG with the --set overrides and the search options' keys (``search``), checked together."""
    from .pipeline import load_config

    config = load_config(args.config)
    config.apply_overrides(list(args.set) + list(search))
    return config


def _search_setup(args, what: str, config):
    """The generations and whether ``args.out`` is resumed, for a search from ``config``; every check
    before any file is written."""
    from .experiment import launched_ranks

    ranks = launched_ranks()
    if ranks > 1 and not args.mpi:
        raise RuntimeError(
            f"started as one of {ranks} MPI ranks without --mpi: every rank would run the whole search into "
            f"{args.out}; add --mpi to swim on the ranks"
        )
    _at_least("--seed", args.seed, 0)
    _at_least("--threads", args.threads, 0)
    _at_least("--generations", args.generations, 0)
    generations = args.generations
    if generations is None:
        generations = int(config["evolution.generations"])
        if generations == 0:
            raise ValueError(
                f"--generations is needed: the config's evolution.generations is 0, no cap, and {what} has no other stop"
            )
    checkpoint = args.out / "checkpoint.json"
    return generations, checkpoint.is_file() if args.resume is None else args.resume


def _search(args, config, run, what: str, snapshots: str, line, **options) -> int:
    """``run`` (run_map_elites or run_nsga2) from ``config`` into ``args.out`` with ``options`` and
    those every search command shares; ``line(row)`` is printed after every generation (unless
    --quiet), a summary at the end (rank 0 only over MPI)."""
    generations, resume = _search_setup(args, what, config)

    def report(row) -> None:
        if not args.quiet:
            print(line(row), flush=True)

    search = run(
        config=config,
        out=args.out,
        generations=generations,
        resume=resume,
        seed=args.seed,
        threads=args.threads,
        callback=report,
        mpi=args.mpi,
        overwrite=args.overwrite,
        **options,
    )
    if args.mpi:
        from .experiment import _mpi_world

        if _mpi_world().Get_rank() != 0:
            return 0
    print(
        f"{args.out}: generation {search.generation}, {search.evaluations} evaluations"
        f"{' (resumed)' if resume else ''}; history.csv, {snapshots}/gen_*.csv, checkpoint.json"
    )
    return 0


def cmd_map_elites(args) -> int:
    from .qd import DESCRIPTORS, GridArchive, run_map_elites

    _at_least("--batch", args.batch, 1)
    _at_least("--archive-every", args.archive_every, 1)
    config = _search_config(args)
    names = list(config["search.descriptors"])
    search = []
    if args.descriptors is not None:
        names = _names("--descriptors", args.descriptors, DESCRIPTORS)
        search.append(f"search.descriptors={json.dumps(names)}")
    if args.bins is not None:
        try:
            bins = [int(b) for b in args.bins.split(",")]
        except ValueError:
            raise ValueError(f"--bins {args.bins!r}: counts are integers, e.g. 10 or 12,8") from None
        if len(bins) not in (1, len(names)) or min(bins) < 1:
            raise ValueError(
                f"--bins {args.bins!r}: one count >= 1 for every descriptor, or one each for the {len(names)} "
                f"descriptors {','.join(names)}"
            )
        search.append(f"search.bins={json.dumps(bins)}")
    config.apply_overrides(search)
    # A new run searches the config's grid; a resume its own archive, which a given one must match.
    archive = GridArchive.from_config(config) if search else None

    return _search(
        args,
        config,
        run_map_elites,
        "MAP-Elites",
        "archive",
        _archive_line,
        archive=archive,
        batch=args.batch,
        archive_every=args.archive_every,
    )


def cmd_nsga2(args) -> int:
    from .moo import CRITERIA, objectives_from_config, run_nsga2

    _at_least("--population", args.population, 1)
    _at_least("--front-every", args.front_every, 1)
    config = _search_config(args)
    objectives = None  # a new run's: the config's; a resume's: its own, which given ones must match
    if args.objectives is not None:
        text = args.objectives
        entries = [item.strip() for item in text.split(",")]
        _names("--objectives", ",".join(e.partition(":")[0] for e in entries), CRITERIA)
        config.apply_overrides([f"search.objectives={json.dumps(entries)}"])
        try:  # the senses, checked by the table that owns the names
            objectives = objectives_from_config(config)
        except ValueError as e:
            raise ValueError(f"--objectives {text!r}: {str(e).partition(': ')[2]}") from None
        # written with their senses: the run's config says what it optimises
        config.apply_overrides([f"search.objectives={json.dumps([f'{n}:{s}' for n, s in objectives])}"])
    return _search(
        args,
        config,
        run_nsga2,
        "NSGA-II",
        "front",
        _front_line,
        objectives=objectives,
        population=args.population,
        front_every=args.front_every,
    )


def _front_line(row) -> str:
    best = ", ".join(f"{name} {row[name]:.6g}" for name in row.dtype.names if name.startswith("best_"))
    return f"generation {row.generation:4d}: front {row.front_size}, hypervolume {row.hypervolume:.6g}, {best}"


def _evolve_parser() -> argparse.ArgumentParser:
    """animat_evolve's flags, for a config whose search.algorithm is not the GA (``animat evolve``)."""
    p = argparse.ArgumentParser(prog="animat evolve", add_help=False)
    p.add_argument("--config")
    p.add_argument("--set", action="append", default=[])
    p.add_argument("--seed", type=int)
    p.add_argument("--generations", type=int)
    p.add_argument("--threads", type=int)
    p.add_argument("--out", type=Path)
    p.add_argument("--resume", type=Path)
    p.add_argument("--overwrite", action="store_true")
    p.add_argument("--print-config", action="store_true")
    p.add_argument("--log-level")
    p.add_argument("--quiet", action="store_true")
    p.add_argument("--mpi", action="store_true")
    return p


def _search_algorithm(argv: List[str]) -> str:
    """search.algorithm of the config ``animat evolve argv`` would run; "ga" when it cannot tell (help,
    a flag or config animat_evolve refuses: its message then says why)."""
    from . import _core
    from .pipeline import load_config

    if any(a in ("-h", "--help") for a in argv):
        return "ga"
    try:
        args, _ = _evolve_parser().parse_known_args(argv)
        if args.resume is not None:
            config = load_config(args.resume / "config.toml")
        elif args.config is not None:
            config = load_config(args.config)
        else:
            config = _core.Config()
        config.apply_overrides(list(args.set))
    except (Exception, SystemExit):
        return "ga"
    return str(config["search.algorithm"])


def cmd_evolve(argv: List[str]) -> int:
    """``animat evolve``: animat_evolve for the GA; MAP-Elites or NSGA-II, with the same flags, when
    the config's search.algorithm says so."""
    from . import _core
    from .experiment import launched_ranks
    from .moo import objectives_from_config, run_nsga2
    from .pipeline import load_config
    from .qd import GridArchive, run_map_elites

    algorithm = _search_algorithm(argv)
    if algorithm == "ga":
        return _core.evolve_cli(argv)
    try:
        args = _evolve_parser().parse_args(argv)
    except SystemExit as e:
        return int(e.code or 0)
    try:
        if args.resume is not None and args.out is not None and args.resume != args.out:
            raise ValueError("--resume and --out name different directories; --resume continues in place")
        if args.resume is not None and args.overwrite:
            raise ValueError("--resume continues the run and --overwrite replaces it; pass one of them")
        if args.resume is not None and args.config is not None:
            raise ValueError("--resume takes its config from the run directory; do not also pass --config")
        if args.resume is not None:
            config = load_config(args.resume / "config.toml")
        else:
            config = load_config(args.config) if args.config is not None else _core.Config()
        config.apply_overrides(args.set)
        if args.print_config:
            print(config.to_toml(), end="")
            return 0
        if args.resume is None:  # the search's names, checked by the tables that own them, naming the file
            try:
                GridArchive.from_config(config) if algorithm == "map_elites" else objectives_from_config(config)
            except ValueError as e:
                raise ValueError(f"{args.config or 'the default config'}: {e}") from None
        args.mpi = args.mpi or launched_ranks() > 1  # as animat_evolve: automatic under mpirun
        seed = args.seed if args.seed is not None else int(config["evolution.seed"])
        if args.out is None:
            args.out = args.resume or Path("runs") / f"{time.strftime('%Y%m%d-%H%M%S')}-seed{seed}"
        args.resume = args.resume is not None
        if algorithm == "map_elites":
            return _search(args, config, run_map_elites, "MAP-Elites", "archive", _archive_line, archive_every=10)
        return _search(args, config, run_nsga2, "NSGA-II", "front", _front_line, objectives=None, front_every=1)
    except MpiAbort:  # a rank other than 0 of a run that rank 0 stopped: rank 0 says why
        return 1
    except KeyboardInterrupt as e:
        print(f"animat evolve: {e or 'interrupted'}", file=sys.stderr)
        return 130
    except (FileNotFoundError, FileExistsError, NotADirectoryError, ValueError, RuntimeError, OSError) as e:
        print(f"animat evolve: error: {e}", file=sys.stderr)
        return 2


def _archive_line(row) -> str:
    return (
        f"generation {row.generation:4d}: {row.elites} elites, coverage {row.coverage:.3f}, "
        f"QD-score {row.qd_score:.6g}, best {row.best:.6g}"
    )


def main(argv: Optional[List[str]] = None) -> int:
    """Entry point of ``animat`` and ``python -m animat``; returns the exit status (0 ok, 1 error, 2 usage;
    ``animat evolve`` returns animat_evolve's)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] == "evolve":
        return cmd_evolve(argv[1:])
    args = _parser().parse_args(argv)
    command = {
        "show": cmd_show,
        "animate": cmd_animate,
        "info": cmd_info,
        "explore": cmd_explore,
        "experiment": cmd_experiment,
        "map-elites": cmd_map_elites,
        "nsga2": cmd_nsga2,
    }[args.command]
    try:
        return command(args)
    except MpiAbort:  # a rank other than 0 of a run that rank 0 stopped: rank 0 says why
        return 1
    except KeyboardInterrupt as e:
        print(f"animat {args.command}: {e or 'interrupted'}", file=sys.stderr)
        return 130
    except (FileNotFoundError, NotADirectoryError, ValueError, RuntimeError, OSError) as e:
        print(f"animat {args.command}: error: {e}", file=sys.stderr)
        return 1
