"""What MAP-Elites' descriptors cost against the evaluation itself: the same random viable genomes (the
default config: the paper's 32 cells, 4000 swim steps) evaluated by `animat.evaluate_population`
alone, then with their descriptors computed as MapElites.step() computes them (from the bodies the
evaluations built: `qd._fitnesses(...)(genomes, config, describe=names)`), and as `tell()` computes
them for a told result (`animat.qd.measure`: the genome developed and its body built again in Python).

    PYTHONPATH=build/python .venv/bin/python bench/qd_descriptor_cost.py [--genomes 40] [--repeat 3] \
        [--threads 1] [--descriptors elongation,protrusions]

Prints the machine and settings, then ms per evaluation (the median of `--repeat` rounds, the three
ways timed one after another in each round) and each way's ratio to the evaluation alone; and, per
described genome, what `measure` spends in development, body construction and `shape.body_shape`.
The values of both ways are checked equal (bit for bit). On an animat whose swim function has no
``describe`` (before it), only the evaluation alone and ``measure`` are timed: the before of a
before/after.
"""

import argparse
import os
import platform
import statistics
import time

import numpy as np

import animat
from animat import _core, pipeline, qd
from animat.shape import body_shape


def candidate(fit):
    return fit.viable and fit.stable and fit.valid


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--genomes", type=int, default=40)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--descriptors", default="elongation,protrusions")
    args = p.parse_args()
    names = tuple(args.descriptors.split(","))
    config = animat.Config()
    config["evolution.threads"] = args.threads
    genomes = [animat.Genome.random_viable(animat.Rng.derive(1, 0, i), config)[0] for i in range(args.genomes)]
    swim = qd._fitnesses(None)
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; animat "
        f"{animat.__version__}; {args.genomes} random viable genomes, {int(config['evaluation.steps'])} steps, "
        f"{args.threads} thread(s), descriptors {','.join(names)}; median of {args.repeat}"
    )

    def alone():
        return animat.evaluate_population(genomes, config, args.threads)

    def measured():  # tell(): measure() develops and builds again
        fits = animat.evaluate_population(genomes, config, args.threads)
        return [qd.measure(g, config, names, f) if candidate(f) else None for g, f in zip(genomes, fits)]

    def described():  # step(): from the evaluation's own bodies
        return [None if v is None else np.array(v) for _, v in swim(genomes, config, describe=names)]

    times = {"evaluation alone": [], "+ descriptors (step: the evaluation's bodies)": [], "+ measure() (tell)": []}
    ways = dict(zip(times, (alone, described, measured)))
    try:  # an animat before the step's own descriptors (for a before/after): measure() only
        swim([], config, describe=names)
    except TypeError:
        del (
            times["+ descriptors (step: the evaluation's bodies)"],
            ways["+ descriptors (step: the evaluation's bodies)"],
        )
    values = {}
    for _ in range(args.repeat):
        for label, way in ways.items():
            t = time.perf_counter()
            values[label] = way()
            times[label].append((time.perf_counter() - t) / len(genomes))
    new, old = values.get("+ descriptors (step: the evaluation's bodies)"), values["+ measure() (tell)"]
    if new is not None:
        assert all((a is None) == (b is None) for a, b in zip(new, old))
        assert all(np.array_equal(a, b, equal_nan=True) for a, b in zip(new, old) if a is not None)
    base = statistics.median(times["evaluation alone"])
    for label, ts in times.items():
        m = statistics.median(ts)
        print(f"{label:48s} {1000 * m:7.2f} ms per evaluation   x{m / base:.3f}")

    parts = {"develop": 0.0, "build_body": 0.0, "body_shape": 0.0}
    fits = animat.evaluate_population(genomes, config, args.threads)
    described_count = 0
    for g, f in zip(genomes, fits):
        if not candidate(f):
            continue
        described_count += 1
        t0 = time.perf_counter()
        embryo = _core.develop(g, config)
        t1 = time.perf_counter()
        body = pipeline.build_body(embryo, config=config)
        t2 = time.perf_counter()
        body_shape(body)
        t3 = time.perf_counter()
        parts["develop"] += t1 - t0
        parts["build_body"] += t2 - t1
        parts["body_shape"] += t3 - t2
    print(
        f"per described genome ({described_count}): "
        + ", ".join(f"{k} {1000 * v / described_count:.2f} ms" for k, v in parts.items())
    )


if __name__ == "__main__":
    main()
