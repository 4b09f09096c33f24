"""MAP-Elites describes its candidates from the bodies their evaluations built (animat.qd, the swim's
``describe=``): the same fitnesses as animat.evaluate_population, the same bodies as
build_body(develop(genome)), descriptor values bit-identical to animat.qd.measure (which develops the
genome again), and cell_heights (animat.shape) bit-identical to the per-cell computation it batches.

Tiny: 200-step swims, a few dozen genomes; the file runs in seconds.
"""

import numpy as np
import pytest

import animat
from animat import _core, qd, shape


def small_config(threads=1):
    c = animat.Config()
    c["evaluation.steps"] = 200
    c["evolution.threads"] = threads
    return c


def some_genomes(config, n=12, seed=21):
    """Random viable genomes and a mutant of each (other shapes, some not viable or not valid)."""
    found = [animat.Genome.random_viable(animat.Rng.derive(seed, 0, i), config)[0] for i in range(n)]
    rng = animat.Rng.derive(seed, 1, 0)
    return found + [g.mutate(rng, config) for g in found]


def candidate(fit):
    return fit.viable and fit.stable and fit.valid


def fitness_fields(f):
    return (f.fitness, f.viable, f.stable, f.cell_count, f.valid, f.drag_limited, f.morphology_kind)


@pytest.mark.parametrize("threads", [1, 2])
def test_the_evaluation_returns_the_fitness_of_evaluate_population_and_the_developed_body(threads):
    config = small_config(threads)
    genomes = some_genomes(config)
    fits, bodies = _core._evaluate_population_bodies(genomes, config, threads)
    assert [fitness_fields(f) for f in fits] == [
        fitness_fields(f) for f in animat.evaluate_population(genomes, config, threads)
    ]
    assert sum(map(candidate, fits)) >= 12
    for genome, fit, body in zip(genomes, fits, bodies):
        assert (body is not None) == candidate(fit)
        if body is None:
            continue
        embryo = animat.develop(genome, config)
        built = animat.build_body(embryo, config=config)
        for name in ("positions", "springs", "amplitude", "frequency", "phase"):
            assert np.array_equal(getattr(body, name), getattr(built, name)), name
        assert [loop.tolist() for loop in body.skin_loops] == [loop.tolist() for loop in built.skin_loops]
        assert np.array_equal(body.frequency, embryo.frequency) and len(body.positions) == len(embryo.positions)


def test_the_objective_scores_as_in_evaluate_population():
    config = small_config()
    genomes = some_genomes(config, n=4)
    for objective in (
        "distance_per_size",
        animat.Objective(lambda r: float(np.ptp(r.body.positions[:, 0])) + r.fitness, every=0, name="width"),
    ):
        fits, _ = _core._evaluate_population_bodies(genomes, config, 1, objective)
        want = animat.evaluate_population(genomes, config, 1, objective=objective)
        assert [fitness_fields(f) for f in fits] == [fitness_fields(f) for f in want]


def test_descriptors_from_the_evaluation_body_are_those_of_measure():
    config = small_config()
    genomes = some_genomes(config)
    names = tuple(qd.DESCRIPTORS)  # every one of the table, the locomotion replay included
    pairs = qd._fitnesses(None)(genomes, config, describe=names)
    described = 0
    for genome, (fit, values) in zip(genomes, pairs):
        if not candidate(fit):
            assert values is None
            continue
        want = qd.measure(genome, config, names, fit)
        assert want is not None
        assert np.array_equal(np.array(values), want, equal_nan=True), (values, want)
        described += 1
    assert described >= 12
    assert [fitness_fields(f) for f, _ in pairs] == [
        fitness_fields(f) for f in animat.evaluate_population(genomes, config, 1)
    ]


def test_map_elites_steps_to_the_run_that_tell_and_measure_give():
    def width(genome, config, evaluation):  # your own descriptor: computed by the search, as before
        return float(np.ptp(animat.develop(genome, config).positions[:, 0])) + evaluation.fitness

    def archive():
        return animat.GridArchive(
            [("elongation", 1, 3), "cells", "frequency", "concavity", "symmetric_pair", (width, 0, 20)], 3
        )

    def run(by_step):
        me = animat.MapElites(small_config(), archive(), batch=8, seed=9, crossover_fraction=0.5)
        while me.generation < 2:
            if by_step:
                me.step()  # descriptors from the evaluation's bodies
            else:
                genomes = me.ask()  # tell() measures: develops every genome again
                me.tell(animat.evaluate_population(genomes, me.config, 1))
        return me

    new, old = run(True), run(False)
    assert len(new.archive) > 3
    elites = [(e.index, e.genome.to_json(), e.fitness, e.descriptors, e.reference) for e in new.archive.elites()]
    assert elites == [
        (e.index, e.genome.to_json(), e.fitness, e.descriptors, e.reference) for e in old.archive.elites()
    ]
    for name in qd.QD_HISTORY_DTYPE.names:
        assert np.array_equal(new.history[name], old.history[name], equal_nan=True), name


# --- cell_heights: the batch against the per-cell computation -------------------------------------


def _segment_distances(q, a, b):
    ab = b - a
    ll = np.einsum("ij,ij->i", ab, ab)
    ll = np.where(ll > 0, ll, 1.0)
    aq = q[:, None, :] - a[None, :, :]
    t = np.clip(np.einsum("nej,ej->ne", aq, ab) / ll, 0.0, 1.0)
    closest = a[None, :, :] + t[..., None] * ab[None, :, :]
    return np.linalg.norm(q[:, None, :] - closest, axis=2)


def _in_core_erosion(q, a, b, rho):
    out = np.zeros(len(q), dtype=bool)
    for start in range(0, len(q), 2048):
        chunk = q[start : start + 2048]
        deep = _segment_distances(chunk, a, b).min(axis=1) >= rho * (1 - 1e-9) - 1e-12
        if deep.any():
            idx = np.nonzero(deep)[0]
            deep[idx] = shape._inside(chunk[idx], a, b)
        out[start : start + 2048] = deep
    return out


def norm_spacing(p):
    """cell_spacing with np.linalg.norm."""
    d = np.linalg.norm(p[:, None, :] - p[None, :, :], axis=2)
    np.fill_diagonal(d, np.inf)
    return float(np.median(d.min(axis=1)))


def per_cell_heights(positions, outline, rho=0.75):
    """cell_heights one cell at a time, every candidate point measured with np.linalg.norm (no
    shortcut)."""
    p = np.asarray(positions, dtype=float)
    s = norm_spacing(p)
    u = p / s
    a = u[np.asarray(outline, dtype=np.int64)]
    b = np.roll(a, -1, axis=0)
    keep = np.any(a != b, axis=1)
    a, b = a[keep], b[keep]
    corners, o, t, v = shape._core_candidates(a, b, rho)
    lo, hi = a.min(axis=0) - 1e-9, a.max(axis=0) + 1e-9
    corners = corners[np.all((corners >= lo) & (corners <= hi), axis=1)]
    pool = [corners[_in_core_erosion(corners, a, b, rho)]]
    for x in u:
        along = np.einsum("kj,kj->k", x - o, t)
        radial = x - v
        r = np.linalg.norm(radial, axis=1)
        radial = v[r > 0] + rho * radial[r > 0] / r[r > 0, None]
        own = np.concatenate([x[None, :], o + along[:, None] * t, radial])
        pool.append(own[_in_core_erosion(own, a, b, rho)])
    core = np.concatenate(pool)
    if len(core) == 0:
        return None
    return np.maximum(0.0, np.linalg.norm(u[:, None, :] - core[None, :, :], axis=2).min(axis=1) - rho)


@pytest.mark.parametrize("config_name", [None, "paper_dn0.2_64cells"])
def test_cell_heights_and_spacing_equal_the_per_cell_computation_bit_for_bit(config_name):
    config = animat.Config() if config_name is None else animat.load_config(config_name)
    config["evaluation.steps"] = 1
    bodies = []
    for genome in some_genomes(config, n=15, seed=4):
        embryo = animat.develop(genome, config)
        if embryo.viable:
            bodies.append(animat.build_body(embryo, config=config))
    assert len(bodies) >= 15
    with_core = 0
    for body in bodies:
        outline = body.skin_loops[0]
        assert shape.cell_spacing(body.positions) == norm_spacing(body.positions)
        got = shape.cell_heights(body.positions, outline)
        want = per_cell_heights(body.positions, outline)
        assert (got is None) == (want is None)
        if got is not None:
            assert np.array_equal(got, want)
            with_core += 1
    assert with_core >= 10
