#!/usr/bin/env python3
"""The speed budget of trustworthy physics (docs/performance.md): one paper-setting evaluation at
the new defaults against the previous release at its defaults, side by side in one run, on the same
genomes.

    git worktree add --detach ../baseline aaac293      # the previous release
    cmake -S ../baseline -B ../baseline/build -G Ninja -DCMAKE_BUILD_TYPE=Release \\
          -DANIMAT_BUILD_TESTS=OFF -DANIMAT_BUILD_BENCH=ON && ninja -C ../baseline/build bench_evaluation animat
    ANIMAT_BUILD_BENCH=ON scripts/build.sh
    .venv/bin/python bench/speed_budget.py --old ../baseline --new . --genomes 'runs/study/*/run_*'

Two measurements, each build at its own defaults:
  1. Google Benchmark `BM_Evaluate` of both builds' bench_evaluation: the first 8 viable random genomes
     of seeds 0, 1, ... (400 development steps, up to 32 cells, 4000 swim steps), rounds interleaved;
  2. bench_genomes (compiled here against each build's library) on the best genome of each run
     directory matched by --genomes: evolved swimmers, which move and collide more than random ones.
Times are medians of interleaved rounds (old, new, old, new...) on this machine, printed with the
load average; callgrind instruction counts of one pass over the same genomes sit beside them (they
do not depend on the load).
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

LIBS = ["-lbox2d", "-lspdlog", "-lfmt", "-ltomlplusplus", "-fopenmp", "-lgmp", "-lmpfr"]


def archives(build: Path) -> list[str]:
    """The library's static archives in link order: the five layers (top first), or libanimat.a of a
    tree from before the layers."""
    single = build / "libanimat.a"
    if single.exists():
        return [str(single)]
    return [str(build / f"libanimat_{layer}.a") for layer in ("run", "evolution", "evaluation", "simulation", "model")]


def build_genomes_tool(tree: Path, build: Path, out: Path) -> Path:
    src = Path(__file__).resolve().parent / "bench_genomes.cpp"
    exe = out / f"bench_genomes_{tree.name}"
    cmd = [
        "g++",
        "-O3",
        "-DNDEBUG",
        "-std=c++20",
        f"-I{tree / 'include'}",
        "-I/usr/include/eigen3",
        '-DANIMAT_VERSION="bench"',
        str(src),
        "-o",
        str(exe),
        *archives(build),
        *LIBS,
    ]
    subprocess.run(cmd, check=True)
    return exe


def bm_evaluate(exe: Path) -> float:
    """Median ms of BM_Evaluate (one short Google Benchmark run)."""
    out = subprocess.run(
        [
            str(exe),
            "--benchmark_filter=^BM_Evaluate$",
            "--benchmark_format=json",
            "--benchmark_min_time=2",
            "--benchmark_repetitions=1",
        ],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    data = json.loads(out)
    runs = [b for b in data["benchmarks"] if b.get("run_type") == "iteration"]
    b = runs[0]
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
    return b["cpu_time"] * scale


def genomes_ms(exe: Path, files: list[str]) -> float:
    out = subprocess.run([str(exe), "--repeat", "3", *files], capture_output=True, text=True, check=True).stdout
    m = re.search(r"median over \d+ genomes: ([0-9.]+) ms", out)
    return float(m.group(1))


def instructions(cmd: list[str]) -> int:
    with tempfile.TemporaryDirectory() as d:
        r = subprocess.run(
            ["valgrind", "--tool=callgrind", f"--callgrind-out-file={d}/cg.out", *cmd], capture_output=True, text=True
        )
        m = re.search(r"Collected : (\d+)", r.stderr) or re.search(r"refs:\s+([\d,]+)", r.stderr)
        return int(m.group(1).replace(",", ""))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--old", required=True, help="source tree of the previous release (with build/)")
    ap.add_argument("--new", default=".", help="source tree of this release (with build/)")
    ap.add_argument("--genomes", default="runs/study/*/run_*", help="glob of run directories")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument(
        "--random",
        type=int,
        default=8,
        help="random viable genomes (seeds 0..N-1, default config) timed and counted with bench_genomes too",
    )
    args = ap.parse_args()
    old, new = Path(args.old).resolve(), Path(args.new).resolve()
    runs = sorted(glob.glob(args.genomes))
    files = [sorted(glob.glob(f"{r}/best/gen_*.json"))[-1] for r in runs if glob.glob(f"{r}/best/gen_*.json")]
    with tempfile.TemporaryDirectory() as tmp:
        tools = {
            name: build_genomes_tool(tree, tree / "build", Path(tmp)) for name, tree in (("old", old), ("new", new))
        }
        # Random viable genomes as files: bench_genomes gives their per-evaluation instructions (the
        # callgrind total of BM_Evaluate is dominated by its setup, which draws ~1,250 random genomes).
        random_files = []
        if args.random > 0:
            draw = (
                "import animat, sys\n"
                "c = animat.Config()\n"
                "for i in range(int(sys.argv[2])):\n"
                "    open(f'{sys.argv[1]}/random_{i}.json', 'w').write(animat.Genome.random_viable(seed=i, config=c)[0].to_json())\n"
            )
            subprocess.run(
                [sys.executable, "-c", draw, tmp, str(args.random)],
                check=True,
                env={**os.environ, "PYTHONPATH": str(new / "build" / "python")},
            )
            random_files = [f"{tmp}/random_{i}.json" for i in range(args.random)]
        bench = {"old": old / "build" / "bench_evaluation", "new": new / "build" / "bench_evaluation"}
        cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
        print(
            f"machine: {cpu}, {os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f} at start; "
            f"old {old}, new {new}; {len(files)} evolved genomes; {args.rounds} interleaved rounds"
        )
        t = {k: [] for k in ("old_random", "new_random", "old_evolved", "new_evolved", "old_rfiles", "new_rfiles")}
        for _ in range(args.rounds):
            for name in ("old", "new"):
                t[f"{name}_random"].append(bm_evaluate(bench[name]))
                if files:
                    t[f"{name}_evolved"].append(genomes_ms(tools[name], files))
                if random_files:
                    t[f"{name}_rfiles"].append(genomes_ms(tools[name], random_files))
        med = {k: statistics.median(v) for k, v in t.items() if v}
        ins = {
            name: instructions([str(bench[name]), "--benchmark_filter=^BM_Evaluate$", "--benchmark_min_time=0.01"])
            for name in ("old", "new")
        }
        if files:
            ins_ev = {name: instructions([str(tools[name]), "--repeat", "1", *files]) for name in ("old", "new")}
        if random_files:
            ins_rf = {name: instructions([str(tools[name]), "--repeat", "1", *random_files]) for name in ("old", "new")}
        print(f"load average at end {os.getloadavg()[0]:.1f}")
        print()
        print(
            "| genomes | previous release (ms per evaluation) | this release | ratio | instructions, previous | this | ratio |"
        )
        print("|---|---|---|---|---|---|---|")
        print(
            f"| 8 random viable (BM_Evaluate) | {med['old_random']:.1f} | {med['new_random']:.1f} | "
            f"{med['new_random'] / med['old_random']:.2f}x | {ins['old'] / 1e6:.0f}M (whole benchmark) | "
            f"{ins['new'] / 1e6:.0f}M | {ins['new'] / ins['old']:.2f}x |"
        )
        if random_files:
            print(
                f"| {len(random_files)} random viable, seeds 0.. (bench_genomes, median) | {med['old_rfiles']:.1f} | "
                f"{med['new_rfiles']:.1f} | {med['new_rfiles'] / med['old_rfiles']:.2f}x | "
                f"{ins_rf['old'] / len(random_files) / 1e6:.0f}M per evaluation | "
                f"{ins_rf['new'] / len(random_files) / 1e6:.0f}M | {ins_rf['new'] / ins_rf['old']:.2f}x |"
            )
        if files:
            print(
                f"| {len(files)} evolved bests (bench_genomes, median) | {med['old_evolved']:.1f} | {med['new_evolved']:.1f} | "
                f"{med['new_evolved'] / med['old_evolved']:.2f}x | {ins_ev['old'] / len(files) / 1e6:.0f}M per evaluation | "
                f"{ins_ev['new'] / len(files) / 1e6:.0f}M | {ins_ev['new'] / ins_ev['old']:.2f}x |"
            )
        print()
        print("rounds (ms):", json.dumps({k: [round(x, 2) for x in v] for k, v in t.items()}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
