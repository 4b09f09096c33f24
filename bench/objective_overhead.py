"""Cost of a Python objective against the built-in one: evaluations per second of the same viable
genomes (the default config: the paper's 32 cells, 4000 swim steps) scored by `distance` in C++ and by
a Python callable (with and without a trajectory), on 1 and 2 threads.

    PYTHONPATH=build/python .venv/bin/python bench/objective_overhead.py [--genomes 40] [--repeat 3]

Prints the machine and settings, and the median of `--repeat` runs. The Python objective runs under
the GIL while the swims run in parallel without it.
"""

import argparse
import os
import platform
import statistics
import time

import numpy as np

import animat


def py_distance(record):
    return float(np.linalg.norm(record.displacement))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--genomes", type=int, default=40)
    p.add_argument("--repeat", type=int, default=3)
    args = p.parse_args()
    config = animat.Config()
    genomes = [animat.Genome.random_viable(seed=s, config=config)[0] for s in range(args.genomes)]
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; animat "
        f"{animat.__version__}; {args.genomes} viable genomes, {int(config['evaluation.steps'])} steps, "
        f"median of {args.repeat}"
    )
    objectives = [
        ("distance (C++)", None),
        ("Python, no trajectory", animat.Objective(py_distance, every=0)),
        ("Python, every=20", animat.Objective(py_distance, every=20)),
    ]
    for threads in (1, 2):
        for name, objective in objectives:
            rates = []
            for _ in range(args.repeat):
                t = time.perf_counter()
                animat.evaluate_population(genomes, config, threads=threads, objective=objective)
                rates.append(len(genomes) / (time.perf_counter() - t))
            print(f"threads {threads}  {name:22s} {statistics.median(rates):6.1f} evaluations/s")


if __name__ == "__main__":
    main()
