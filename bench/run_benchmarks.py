#!/usr/bin/env python3
"""The performance benchmarks (docs/performance.md), run and tabulated in one go.

    .venv/bin/python bench/run_benchmarks.py            # everything (about 10 min on 2 cores)
    .venv/bin/python bench/run_benchmarks.py --no-callgrind --generations 3   # quicker

It builds the benchmarks (scripts/build.sh with ANIMAT_BUILD_BENCH=ON), then:
  1. bench_physics: µs per swim step at 32/64/128/256 cells against a bare Box2D Step of as many
     fixture-less bodies (and of the same bodies linked into one island), per-effect costs;
  2. bench_evaluation: one evaluation at the paper setting split into development, body and swim;
  3. callgrind instruction counts of the same (reproducible on a shared machine);
  4. animat_evolve with 1 and 2 threads: generations per second, speedup, peak memory
     (/usr/bin/time -v), and a check that both thread counts give the same run;
  5. the size exponent fit and the paper-scale projection.
Every result goes to bench/results/*.csv (the console output with the machine and settings to
bench/results/*.txt), and the tables into docs/performance.md between the
"BEGIN MEASURED" and "END MEASURED" markers (the text around them is written by hand).
Timings are medians of randomly interleaved repetitions; ratios are taken within one benchmark
process. On a shared VM the timings move by ±20% between runs; the instruction counts do not.
"""

from __future__ import annotations

import argparse
import csv
import io
import math
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CELLS = [32, 64, 128, 256]
EFFECTS = [
    "springs",
    "actuation",
    "pressure",
    "drag",
    "collisions",
    "none",
    "all (default scene)",
    "skin_collision",
    "gravity",
    "ground (no contact)",
    "crawl scene (crawl effects, impulse floor, on the floor)",
]  # BM_Effect/0..10


def sh(cmd, **kw) -> str:
    return subprocess.run(cmd, check=True, text=True, capture_output=True, **kw).stdout


def machine() -> dict:
    info = {
        "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
        "python": platform.python_version(),
        "kernel": platform.release(),
        "cores": str(os.cpu_count()),
    }
    try:
        for line in sh(["lscpu"]).splitlines():
            k, _, v = line.partition(":")
            if k.strip() in ("Model name", "Hypervisor vendor"):
                info[k.strip().lower().replace(" ", "_")] = v.strip()
    except (OSError, subprocess.CalledProcessError):
        pass
    try:
        mem = Path("/proc/meminfo").read_text().split("\n")[0].split()[1]
        info["memory"] = f"{int(mem) / 1024 / 1024:.1f} GiB"
    except OSError:
        pass
    try:
        info["compiler"] = sh(["c++", "--version"]).splitlines()[0]
        info["box2d"] = sh(["dpkg-query", "-W", "-f=${Version}", "libbox2d-dev"])
    except (OSError, subprocess.CalledProcessError):
        pass
    try:
        dirty = sh(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT).strip()
        info["commit"] = sh(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT).strip() + (
            " (modified)" if dirty else ""
        )
    except (OSError, subprocess.CalledProcessError):
        pass
    return info


def build_type(build: Path) -> str:
    m = re.search(r"^CMAKE_BUILD_TYPE:STRING=(.*)$", (build / "CMakeCache.txt").read_text(), re.M)
    flags = re.search(r"^CMAKE_CXX_FLAGS_RELEASE:STRING=(.*)$", (build / "CMakeCache.txt").read_text(), re.M)
    return f"{m.group(1) if m else '?'} ({flags.group(1) if flags else ''})"


# --- Google Benchmark ---------------------------------------------------------------------------


def run_gbench(exe: Path, out_csv: Path, filt: str, reps: int, min_time: float) -> dict:
    """Runs a benchmark binary; returns {name: row} of the median aggregates (CPU time in µs)."""
    subprocess.run(
        [
            str(exe),
            f"--benchmark_filter={filt}",
            f"--benchmark_repetitions={reps}",
            "--benchmark_report_aggregates_only=true",
            f"--benchmark_min_time={min_time}",
            "--benchmark_enable_random_interleaving=true",  # machine drift spreads over all benchmarks
            f"--benchmark_out={out_csv}",
            "--benchmark_out_format=csv",
        ],
        check=True,
        stdout=open(out_csv.with_suffix(".txt"), "w"),
        stderr=subprocess.STDOUT,
    )
    text = out_csv.read_text()
    text = text[text.index("name,") :]  # skip the context lines
    rows = {}
    scale = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}
    for r in csv.DictReader(io.StringIO(text)):
        if not r["name"].endswith("_median"):
            continue
        name = r["name"][: -len("_median")]
        r["cpu_us"] = float(r["cpu_time"]) * scale[r["time_unit"]]
        r["real_us"] = float(r["real_time"]) * scale[r["time_unit"]]
        rows[name] = r
    return rows


# --- callgrind ----------------------------------------------------------------------------------


def callgrind(exe: Path, filt: str, functions: list[str], toggle: str | None = None, min_time: float = 0.2) -> dict:
    """Inclusive instructions per call of each function (matched by prefix) under one benchmark.

    LD_BIND_NOW keeps the dynamic linker's lazy binding out of the first calls; min_time (in
    valgrind's slowed-down time) gives enough calls to amortise the remaining first-call costs."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cg.out"
        cmd = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}"]
        if toggle:
            cmd.append(f"--toggle-collect={toggle}")
        cmd += [str(exe), f"--benchmark_filter={filt}", f"--benchmark_min_time={min_time}"]
        subprocess.run(
            cmd,
            check=True,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            env={**os.environ, "LD_BIND_NOW": "1"},
        )
        tree = sh(["callgrind_annotate", "--inclusive=yes", "--tree=caller", "--threshold=100", str(out)])
    lines = tree.splitlines()
    result = {}
    for fn in functions:
        total, calls = 0, 0
        for i, line in enumerate(lines):
            m = re.match(r"\s*([\d,]+) \([ \d.]+%\)  \*  \S*?:(.*?) \[", line)
            if not m or not m.group(2).startswith(fn):
                continue
            total += int(m.group(1).replace(",", ""))
            j = i - 1
            while j >= 0 and "  < " in lines[j]:
                c = re.search(r"\((\d[\d,]*)x\)", lines[j])
                calls += int(c.group(1).replace(",", "")) if c else 0
                j -= 1
        result[fn] = (total / calls if calls else float("nan"), calls, total)
    return result


# --- animat_evolve ------------------------------------------------------------------------------


def run_evolve(exe: Path, threads: int, generations: int, seed: int, workdir: Path) -> dict:
    out = workdir / f"evolve_t{threads}"
    shutil.rmtree(out, ignore_errors=True)
    cmd = [
        "/usr/bin/time",
        "-v",
        str(exe),
        "--generations",
        str(generations),
        "--threads",
        str(threads),
        "--seed",
        str(seed),
        "--out",
        str(out),
        "--quiet",
    ]
    t0 = time.perf_counter()
    p = subprocess.run(cmd, check=True, text=True, capture_output=True)
    wall = time.perf_counter() - t0
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr).group(1))
    hist = list(csv.DictReader(open(out / "history.csv")))
    g0 = float(hist[0]["wall_seconds"])
    last = float(hist[-1]["wall_seconds"])
    gens = int(hist[-1]["generation"])
    return {
        "threads": threads,
        "wall": wall,
        "peak_rss_mb": rss / 1024,
        "gen0_seconds": g0,
        "seconds_per_generation": (last - g0) / gens if gens else float("nan"),
        "generations": gens,
        "evaluations": int(hist[-1]["evaluations"]),
        "gen0_evaluations": int(hist[0]["evaluations"]),
        "best": [h["best"] for h in hist],
    }


def fit_exponent(xs, ys) -> float:
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def table(header, rows) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join(" --- " for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.environ.get("ANIMAT_BUILD_DIR", "build"))
    ap.add_argument("--results", default="bench/results")
    ap.add_argument("--doc", default="docs/performance.md")
    ap.add_argument("--repetitions", type=int, default=9)
    ap.add_argument("--min-time", type=float, default=0.2)
    ap.add_argument("--generations", type=int, default=20, help="animat_evolve generations per thread count")
    ap.add_argument("--no-build", action="store_true")
    ap.add_argument("--no-callgrind", action="store_true")
    ap.add_argument("--no-evolve", action="store_true")
    args = ap.parse_args()
    os.chdir(ROOT)
    build = Path(args.build)
    if not args.no_build:
        # valgrind and GNU time are only needed here, so scripts/setup.sh installs them on request.
        subprocess.run(["scripts/setup.sh"], check=True, env={**os.environ, "ANIMAT_EXTRA_APT": "valgrind time"})
        subprocess.run(
            ["scripts/build.sh"],
            check=True,
            env={**os.environ, "ANIMAT_BUILD_BENCH": "ON", "ANIMAT_BUILD_DIR": str(build)},
        )
    for tool, needed in (("valgrind", not args.no_callgrind), ("/usr/bin/time", not args.no_evolve)):
        if needed and not shutil.which(tool):
            sys.exit(f"run_benchmarks: {tool} is missing (apt install valgrind time, or run without --no-build)")
    results = Path(args.results)
    results.mkdir(parents=True, exist_ok=True)
    info = machine()
    info["build"] = build_type(build)
    info["load_average_start"] = "{:.2f} {:.2f} {:.2f}".format(*os.getloadavg())
    print("machine:", info, flush=True)
    md = []

    # 1, 2, 5: swim step, floor, effects, size.
    print("bench_physics ...", flush=True)
    phys = run_gbench(
        build / "bench_physics",
        results / "bench_physics.csv",
        "BM_Box2DBareStep|BM_Box2DLinkedStep|BM_SwimStep|BM_Effect",
        args.repetitions,
        args.min_time,
    )
    print("bench_evaluation, development steps ...", flush=True)
    dev = run_gbench(
        build / "bench_evaluation",
        results / "bench_develop_step.csv",
        "BM_DevelopStep",
        args.repetitions,
        args.min_time,
    )
    print("bench_evaluation ...", flush=True)
    ev = run_gbench(
        build / "bench_evaluation",
        results / "bench_evaluation.csv",
        "^BM_(Evaluate|Develop|BuildBody|Swim|RandomTry)$",
        args.repetitions,
        max(args.min_time, 0.5),
    )
    cg = {}
    if not args.no_callgrind:
        print("callgrind ...", flush=True)
        for n in CELLS:
            cg[("swim", n)] = callgrind(
                build / "bench_physics", f"^BM_SwimStep/{n}$", ["animat::Simulation::step(long)"]
            )
            cg[("swim_box2d", n)] = callgrind(
                build / "bench_physics", f"^BM_SwimStepBox2D/{n}$", ["animat::Simulation::step(long)", "b2World::Step("]
            )
            cg[("bare", n)] = callgrind(build / "bench_physics", f"^BM_Box2DBareStep/{n}$", ["b2World::Step("])
            cg[("linked", n)] = callgrind(build / "bench_physics", f"^BM_Box2DLinkedStep/{n}$", ["b2World::Step("])
        for k in range(len(EFFECTS)):
            cg[("effect", k)] = callgrind(
                build / "bench_physics", f"^BM_Effect/{k}$", ["animat::Simulation::step(long)"]
            )
        cg["evaluate"] = callgrind(
            build / "bench_evaluation",
            "^BM_Evaluate$",
            ["animat::evaluate(", "animat::develop(", "animat::build_body(", "animat::swim(", "b2World::Step("],
            toggle="animat::evaluate(*",
            min_time=0.01,
        )

    rows = []
    for n in CELLS:
        s, b, l = (
            phys[f"BM_SwimStep/{n}"]["cpu_us"],
            phys[f"BM_Box2DBareStep/{n}"]["cpu_us"],
            phys[f"BM_Box2DLinkedStep/{n}"]["cpu_us"],
        )
        sb = phys[f"BM_SwimStepBox2D/{n}"]["cpu_us"]
        row = [
            n,
            f"{s:.2f}",
            f"{l:.2f}",
            f"**{s / l:.2f}×**",
            f"{sb:.2f}",
            f"{sb / l:.2f}×",
            f"{b:.2f}",
            f"{s / b:.2f}×",
        ]
        if cg:
            si = cg[("swim", n)]["animat::Simulation::step(long)"][0]
            li = cg[("linked", n)]["b2World::Step("][0]
            sbi = cg[("swim_box2d", n)]["animat::Simulation::step(long)"][0]
            bx = cg[("swim_box2d", n)]["b2World::Step("][0]
            row += [f"{si / 1e3:.1f}k", f"{li / 1e3:.1f}k", f"{si / li:.2f}×", f"{sbi / 1e3:.1f}k", f"{bx / sbi:.0%}"]
        rows.append(row)
    header = [
        "cells",
        "swim step µs (native integrator, the default)",
        "Box2D Step, one island µs (the honest floor)",
        "swim / one-island (time)",
        "swim step with integrator = box2d µs",
        "box2d swim / one-island",
        "bare Box2D Step, unlinked µs",
        "swim / unlinked",
    ]
    if cg:
        header += [
            "swim step instr.",
            "one-island Step instr.",
            "swim / one-island (instr.)",
            "swim step instr., integrator = box2d",
            "Box2D's share of that",
        ]
    md += ["### 1. Swim step versus the Box2D floor", "", table(header, rows), ""]

    rows = []
    base = phys["BM_Effect/5"]["cpu_us"]
    for k, name in enumerate(EFFECTS):
        t = phys[f"BM_Effect/{k}"]["cpu_us"]
        row = [name, f"{t:.2f}", f"{t - base:+.2f}"]
        if cg:
            ins = cg[("effect", k)]["animat::Simulation::step(long)"][0]
            ins0 = cg[("effect", 5)]["animat::Simulation::step(long)"][0]
            row += [f"{ins / 1e3:.1f}k", f"{(ins - ins0) / 1e3:+.1f}k"]
        rows.append(row)
    header = ["effects in the scene (32 cells)", "µs per step", "over none"]
    if cg:
        header += ["instr. per step", "over none"]
    md += [
        "### 2. Per-effect cost",
        "",
        table(header, rows),
        "",
        f"A bare Box2D Step of 32 unlinked bodies in the same run: {phys['BM_Box2DBareStep/32']['cpu_us']:.2f} µs; "
        f"of 32 bodies in one island: {phys['BM_Box2DLinkedStep/32']['cpu_us']:.2f} µs.",
        "",
    ]

    # Development step against cells (the exponent target of docs/performance.md).
    dev_cells = [32, 64, 128, 256, 512, 1024]
    cutoffs = [0, 40, 80]  # development.morphogen_cutoff in tenths (0 = none, the paper's field)
    us = {(n, c): dev[f"BM_DevelopStep/{n}/{c}"]["cpu_us"] for n in dev_cells for c in cutoffs}
    rows = [[n] + [f"{us[(n, c)]:.1f}" for c in cutoffs] for n in dev_cells]
    small = [n for n in dev_cells if n <= 256]
    large = [n for n in dev_cells if n >= 256]
    exps = {
        c: (fit_exponent(small, [us[(n, c)] for n in small]), fit_exponent(large, [us[(n, c)] for n in large]))
        for c in cutoffs
    }
    rows.append(["exponent 32 → 256"] + [f"**{exps[c][0]:.2f}**" for c in cutoffs])
    rows.append(["exponent 256 → 1024"] + [f"**{exps[c][1]:.2f}**" for c in cutoffs])
    md += [
        "### 2b. Development step against cells",
        "",
        table(
            [
                "cells",
                "µs per step, every pair (the paper's field, default)",
                "morphogen_cutoff = 4",
                "morphogen_cutoff = 8",
            ],
            rows,
        ),
        "",
        "Least-squares exponents of the cost in cells (target ≤ 1.1 from 32 to 256). `BM_DevelopStep/n/c`: n cells "
        "on a triangular lattice, the GRN of the first sample genome with morphogen products, max_cells = n (no "
        "division), `development.morphogen_cutoff` = c/10. Contact forces use the neighbour grid from 64 cells on "
        "in every column.",
        "",
    ]

    e, d, bb, sw, rt = (
        ev[k]["cpu_us"] for k in ("BM_Evaluate", "BM_Develop", "BM_BuildBody", "BM_Swim", "BM_RandomTry")
    )
    tries = float(ev["BM_Evaluate"]["tries_per_viable"])
    viable_fraction = float(ev["BM_RandomTry"]["label"].split("=")[1])
    rows = [
        ["whole evaluation", f"{e / 1e3:.2f}", f"{1e6 / e:.1f}", "100%"],
        ["development (400 steps)", f"{d / 1e3:.2f}", f"{1e6 / d:.1f}", f"{d / e:.0%}"],
        ["body construction (Gabriel, regions, skin)", f"{bb / 1e3:.3f}", f"{1e6 / bb:.0f}", f"{bb / e:.1%}"],
        ["swim (4000 steps) + fitness", f"{sw / 1e3:.2f}", f"{1e6 / sw:.1f}", f"{sw / e:.0%}"],
        ["one random try (gen-0 seeding)", f"{rt / 1e3:.3f}", f"{1e6 / rt:.0f}", "—"],
    ]
    md += [
        "### 3. Evaluation throughput (paper setting, 8 random viable genomes, seeds from 0)",
        "",
        table(["stage", "ms", "per second (1 core)", "share"], rows),
        "",
        f"Development costs {d / sw:.0%} of the swim. Random tries per viable genome: {tries:.1f} over the 8 "
        f"genomes; viable fraction of 10^4-ish consecutive seeds in BM_RandomTry: {viable_fraction:.4f} "
        f"(1 in {1 / viable_fraction:.0f})."
        if viable_fraction > 0
        else "",
        "",
    ]
    if cg:
        ce = cg["evaluate"]
        tot = ce["animat::evaluate("][0]
        b2 = ce["b2World::Step("][2] / ce["animat::evaluate("][1]
        md += [
            table(
                ["instructions per evaluation", "count", "share"],
                [
                    ["total", f"{tot / 1e6:.1f}M", "100%"],
                    [
                        "development",
                        f"{ce['animat::develop('][2] / ce['animat::evaluate('][1] / 1e6:.1f}M",
                        f"{ce['animat::develop('][2] / ce['animat::evaluate('][1] / tot:.0%}",
                    ],
                    [
                        "body construction",
                        f"{ce['animat::build_body('][2] / ce['animat::evaluate('][1] / 1e6:.2f}M",
                        f"{ce['animat::build_body('][2] / ce['animat::evaluate('][1] / tot:.1%}",
                    ],
                    [
                        "swim",
                        f"{ce['animat::swim('][2] / ce['animat::evaluate('][1] / 1e6:.1f}M",
                        f"{ce['animat::swim('][2] / ce['animat::evaluate('][1] / tot:.0%}",
                    ],
                    [
                        "inside Box2D's Step (development + swim; none with the native integrator)",
                        f"{b2 / 1e6:.1f}M",
                        f"{b2 / tot:.0%}",
                    ],
                    ["outside Box2D's Step", f"{(tot - b2) / 1e6:.1f}M", f"{(tot - b2) / tot:.0%}"],
                ],
            ),
            "",
        ]

    evo = []
    if not args.no_evolve:
        print("animat_evolve 1 and 2 threads ...", flush=True)
        with tempfile.TemporaryDirectory() as tmp:
            for t in (1, 2):
                evo.append(run_evolve(build / "animat_evolve", t, args.generations, 1, Path(tmp)))
        same = evo[0]["best"] == evo[1]["best"]
        rows = [
            [
                r["threads"],
                f"{r['gen0_seconds']:.1f}",
                f"{r['seconds_per_generation']:.2f}",
                f"{1 / r['seconds_per_generation']:.3f}",
                f"{r['peak_rss_mb']:.0f}",
            ]
            for r in evo
        ]
        speed = evo[0]["seconds_per_generation"] / evo[1]["seconds_per_generation"]
        speed0 = evo[0]["gen0_seconds"] / evo[1]["gen0_seconds"]
        md += [
            f"### 4. Parallel scaling: animat_evolve, embedded default config, seed 1, {args.generations} generations",
            "",
            table(
                [
                    "threads",
                    "generation 0 (seeding) s",
                    "s per later generation",
                    "generations per s",
                    "peak RSS MB (/usr/bin/time -v)",
                ],
                rows,
            ),
            "",
            f"Speedup 2 threads over 1: **{speed:.2f}×** on later generations, {speed0:.2f}× on generation 0. "
            f"Both thread counts give the same best fitness in every generation: {'yes' if same else 'NO'}.",
            "",
        ]
        with open(results / "evolve_scaling.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(
                ["threads", "gen0_seconds", "seconds_per_generation", "peak_rss_mb", "generations", "evaluations"]
            )
            for r in evo:
                w.writerow(
                    [
                        r["threads"],
                        r["gen0_seconds"],
                        r["seconds_per_generation"],
                        r["peak_rss_mb"],
                        r["generations"],
                        r["evaluations"],
                    ]
                )

    times = [phys[f"BM_SwimStep/{n}"]["cpu_us"] for n in CELLS]
    rows = [
        ["swim step, CPU time", f"{fit_exponent(CELLS, times):.2f}"],
        [
            "bare Box2D Step, CPU time",
            f"{fit_exponent(CELLS, [phys[f'BM_Box2DBareStep/{n}']['cpu_us'] for n in CELLS]):.2f}",
        ],
    ]
    if cg:
        rows.append(
            [
                "swim step, instructions",
                f"{fit_exponent(CELLS, [cg[('swim', n)]['animat::Simulation::step(long)'][0] for n in CELLS]):.2f}",
            ]
        )
    md += [
        "### 5. Scaling with size (least-squares fit of log cost against log cells, 32 → 256)",
        "",
        table(["cost", "exponent"], rows),
        "",
    ]

    if evo:
        r = evo[1]
        evals_per_gen = (r["evaluations"] - r["gen0_evaluations"]) / max(r["generations"], 1)
        hours = (r["gen0_seconds"] + 5000 * r["seconds_per_generation"]) / 3600
        md += [
            "### 6. Projection: a paper-scale run (population 100, 5000 generations, 2 threads)",
            "",
            f"Generation 0 ({r['gen0_evaluations']} random tries) took {r['gen0_seconds']:.1f} s and each later "
            f"generation {r['seconds_per_generation']:.2f} s ({evals_per_gen:.0f} new evaluations per generation: "
            f"elites and unchanged copies are not re-evaluated). 5000 generations: "
            f"{r['gen0_seconds']:.0f} s + 5000 × {r['seconds_per_generation']:.2f} s = **{hours:.2f} h**.",
            "",
        ]

    info["load_average_end"] = "{:.2f} {:.2f} {:.2f}".format(*os.getloadavg())
    head = [
        "Measured by `.venv/bin/python bench/run_benchmarks.py` "
        f"(repetitions {args.repetitions}, min time {args.min_time} s, medians of CPU time).",
        "",
        table(["machine", ""], [[k, v] for k, v in info.items()]),
        "",
    ]
    block = "\n".join(head + md)
    (results / "tables.md").write_text(block + "\n")
    doc = Path(args.doc)
    begin, end = "<!-- BEGIN MEASURED -->", "<!-- END MEASURED -->"
    text = doc.read_text() if doc.exists() else f"# Performance\n\n{begin}\n{end}\n"
    if begin not in text:
        text += f"\n{begin}\n{end}\n"
    pre, rest = text.split(begin, 1)
    post = rest.split(end, 1)[1]
    doc.write_text(pre + begin + "\n" + block + "\n" + end + post)
    print(block)
    return 0


if __name__ == "__main__":
    sys.exit(main())
