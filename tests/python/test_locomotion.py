"""Locomotion modes (undulation, synchronous contraction, protrusions) and the paper's statistics of
the best individuals: synthetic swims with known answers, real swims with imposed phase
patterns, rigid-motion invariance, and the statistics helpers on hand-made inputs."""

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import animat
from animat import locomotion as L

OMEGA = 6.0
#: Seeds of animat.Genome.random whose genomes develop into viable embryos with the default config.
VIABLE_SEEDS = (241, 249)
PERIOD = 2 * math.pi / OMEGA


# --- synthetic swims --------------------------------------------------------------------------------------


def frame_times(periods=8, per_period=40):
    return np.arange(periods * per_period + 1) * (PERIOD / per_period)


def lattice(nx, ny, seed=0):
    """A rectangular lattice of cells, spacing 1, slightly jittered (no cocircular quadruples)."""
    xs, ys = np.meshgrid(np.arange(nx, dtype=float), np.arange(ny, dtype=float), indexing="ij")
    p = np.stack([xs.ravel(), ys.ravel()], axis=1)
    p += np.random.default_rng(seed).uniform(-0.02, 0.02, p.shape)
    return p - p.mean(axis=0)


def hex_blob(radius=2.2, seed=1):
    pts = [np.array([i + 0.5 * j, j * math.sqrt(3) / 2]) for i in range(-6, 7) for j in range(-6, 7)]
    p = np.array([q for q in pts if np.linalg.norm(q) <= radius])
    p += np.random.default_rng(seed).uniform(-0.02, 0.02, p.shape)
    return p - p.mean(axis=0)


def swim_forward(P, t, speed=0.3):
    """Add a steady drift along +x (the direction of motion)."""
    out = P.copy()
    out[:, :, 0] += speed * t[:, None]
    return out


def contraction_wave(k=0.6, amplitude=0.15):
    """Longitudinal wave of contraction: strain du/dx = -A sin(ωt - kx), i.e. contraction phase -k x
    (up to the sign of a strain): a wave travelling towards +x."""
    X, t = lattice(10, 3), frame_times()
    P = np.repeat(X[None], len(t), axis=0)
    P[:, :, 0] += -(amplitude / k) * np.cos(k * X[None, :, 0] - OMEGA * t[:, None])
    return swim_forward(P, t), t, X


def bending_wave(k=0.6, amplitude=0.4):
    """Euler-Bernoulli bending wave w(x, t) = A sin(kx - ωt) of a 3-row strip (travels towards +x)."""
    X, t = lattice(12, 3), frame_times()
    x, y = X[None, :, 0], X[None, :, 1]
    arg = k * x - OMEGA * t[:, None]
    P = np.empty((len(t), len(X), 2))
    P[:, :, 0] = x - y * amplitude * k * np.cos(arg)
    P[:, :, 1] = y + amplitude * np.sin(arg)
    return swim_forward(P, t), t, X


def breathing(amplitude=0.1):
    X, t = hex_blob(), frame_times()
    P = X[None] * (1 + amplitude * np.sin(OMEGA * t))[:, None, None]
    return swim_forward(P, t), t, X


def paddling(sweep=0.6, stretch=0.3, core=0.01):
    """A blob (breathing by 1 %) with two 3-cell appendages at its back that sweep through ±sweep rad
    and extend by `stretch` while they move backwards, as the paper describes (Fig. 6)."""
    X, t = hex_blob(), frame_times()
    bases = [X[np.argmax(X @ np.array([-0.5, s]))] for s in (1.0, -1.0)]
    frames = []
    for tt in t:
        pts = list(X * (1 + core * math.sin(OMEGA * tt)))
        for base, side in zip(bases, (1, -1)):
            angle = math.atan2(base[1], base[0]) + side * sweep * math.sin(OMEGA * tt)
            d = np.array([math.cos(angle), math.sin(angle)])
            spacing = 1.0 + stretch * math.cos(OMEGA * tt)
            pts += [base + m * spacing * d for m in (1, 2, 3)]
        frames.append(pts)
    appendage_cells = np.arange(len(X), len(X) + 6)
    return swim_forward(np.array(frames), t), t, appendage_cells


def halves_in_antiphase(amplitude=0.12):
    """The upper half stretches along x while the lower half shrinks, and vice versa: a standing
    pattern (a 0/π phase jump across the body, no travelling wave)."""
    X, t = lattice(8, 4), frame_times()
    side = np.sign(X[:, 1])
    P = np.repeat(X[None], len(t), axis=0)
    P[:, :, 0] = X[None, :, 0] * (1 + amplitude * side[None, :] * np.sin(OMEGA * t)[:, None])
    return swim_forward(P, t), t, X


def rigid_body():
    X, t = lattice(6, 3), frame_times()
    return swim_forward(np.repeat(X[None], len(t), axis=0), t), t, X


def rigidly_moved(P, t, angle=0.7, spin=0.05, shift=(3.0, -2.0)):
    """Each frame rotated about its centroid by angle + spin*t and shifted: a rigid motion per frame."""
    out = np.empty_like(P)
    for f in range(len(P)):
        a = angle + spin * t[f]
        R = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
        c = P[f].mean(axis=0)
        out[f] = (P[f] - c) @ R.T + c + np.asarray(shift)
    return out


# --- classification of synthetic swims ------------------------------------------------------------------
# Positions arrays carry no outline, so classify_locomotion applies the earlier rules to them (the
# stroke path needs the body's outline): these tests check the rules both paths share.


def test_travelling_contraction_wave_is_undulation_with_its_phase_gradient():
    k = 0.6
    P, t, X = contraction_wave(k)
    m = L.classify_locomotion(P, times=t)
    assert m.mode == "undulation" and m.mixed == ()
    assert m.omega == pytest.approx(OMEGA, rel=0.01)  # found from the deformation spectrum
    g = m.wave.gradient
    assert g[0] == pytest.approx(-k, abs=0.06)  # contraction phase -k x: the wave runs towards +x
    assert abs(g[1]) < 0.05
    assert m.wave.fit > 0.95
    extent = np.ptp(X[:, 0])
    assert m.wave.lag == pytest.approx(k * extent, rel=0.1)
    assert m.wave.travel == "forward"  # same direction as the motion (+x)
    assert m.coherence < 0.3 and m.wave.travelling_index > 0.5


def test_wave_running_against_the_motion_is_backward():
    P, t, X = contraction_wave(0.6)
    P[:, :, 0] -= 2 * 0.3 * t[:, None]  # the same deformation, swimming towards -x
    m = L.classify_locomotion(P, times=t)
    assert m.mode == "undulation"
    assert m.wave.travel == "backward"
    assert m.wave.angle > 170


def test_bending_wave_is_undulation_along_the_body():
    k = 0.6
    P, t, X = bending_wave(k)
    m = L.classify_locomotion(P, times=t, omega=OMEGA)
    assert m.mode == "undulation"
    # the two sides contract in antiphase (the across component) while the wave runs along x
    assert m.wave.gradient[0] == pytest.approx(-k, rel=0.15)
    assert m.wave.fit > 0.9 and m.wave.lag > math.pi


def test_breathing_blob_is_synchronous_contraction():
    P, t, X = breathing()
    m = L.classify_locomotion(P, times=t)
    assert m.mode == "synchronous contraction" and m.mixed == ()
    assert m.coherence > 0.99
    assert m.wave.lag < 0.1 and m.wave.travelling_index < 0.01
    assert 0.3 < m.concentration < 0.45  # amplitude ∝ radius: about 0.36 for a disc
    assert m.deformation == pytest.approx(0.1, rel=0.1)  # displacement amplitude / RMS radius = 10 %


def test_two_paddling_appendages_are_protrusions():
    P, t, appendages = paddling()
    m = L.classify_locomotion(P, times=t, omega=OMEGA)
    assert m.mode == "protrusions"
    assert m.concentration > 0.8
    assert len(m.top_cells) == math.ceil(0.2 * P.shape[1]) == 5
    assert set(m.top_cells.tolist()) <= set(appendages.tolist())  # the most mobile cells are appendage cells


def test_standing_antiphase_halves_are_not_a_wave():
    P, t, X = halves_in_antiphase()
    m = L.classify_locomotion(P, times=t, omega=OMEGA)
    assert m.mode == "other"
    assert m.wave.travelling_index < L.WAVE_TI
    assert m.coherence < 0.3


def test_rigid_body_is_none():
    P, t, X = rigid_body()
    m = L.classify_locomotion(P, times=t, omega=OMEGA)
    assert m.mode == "none" and m.wave is None
    assert m.deformation < 1e-9
    assert m.speed == pytest.approx(0.3, rel=1e-6)
    assert np.allclose(m.direction, [1.0, 0.0])
    spinning = L.classify_locomotion(rigidly_moved(P, t, spin=0.3), times=t, omega=OMEGA)
    assert spinning.mode == "none"


@pytest.mark.parametrize("make", [contraction_wave, bending_wave, breathing, paddling, halves_in_antiphase])
def test_rigid_motions_do_not_change_the_result(make):
    P, t, _ = make()
    springs = animat.gabriel_graph(P[0])
    base = L.classify_locomotion(P, times=t, springs=springs, omega=OMEGA)
    for moved in (rigidly_moved(P, t, spin=0.0), rigidly_moved(P, t, angle=-2.0, spin=0.4, shift=(-50, 7))):
        m = L.classify_locomotion(moved, times=t, springs=springs, omega=OMEGA)
        assert m.mode == base.mode and m.mixed == base.mixed
        for name in ("deformation", "coherence", "concentration", "travelling_index"):
            assert getattr(m, name) == pytest.approx(getattr(base, name), abs=1e-7), name
        assert m.wave.fit == pytest.approx(base.wave.fit, abs=1e-6)
        assert m.wave.lag == pytest.approx(base.wave.lag, abs=1e-3)
        assert np.linalg.norm(m.wave.gradient) == pytest.approx(np.linalg.norm(base.wave.gradient), abs=1e-3)
        assert np.array_equal(m.top_cells, base.top_cells)


def test_direction_of_the_wave_is_relative_to_the_motion():
    P, t, _ = contraction_wave(0.6)
    a = 2.1  # rotate the whole swim (path included) about a fixed point: the wave still runs forward
    R = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
    m = L.classify_locomotion(P @ R.T + [4.0, -1.0], times=t, omega=OMEGA)
    assert m.wave.travel == "forward" and m.wave.angle < 5
    # rotating each frame about its own centroid keeps the path along +x but turns the body by 40°:
    # the wave (along the body) now runs at 40° to the motion
    m = L.classify_locomotion(rigidly_moved(P, t, angle=math.radians(40), spin=0.0), times=t, omega=OMEGA)
    assert m.wave.angle == pytest.approx(40, abs=5)


def test_classify_motion_checks_its_input():
    P, t, _ = breathing()
    with pytest.raises(ValueError, match="times are required"):
        L.classify_locomotion(P)
    with pytest.raises(ValueError, match="positions must be"):
        L.classify_motion(P[:, :, 0], t)
    with pytest.raises(ValueError, match="times must be"):
        L.classify_motion(P, t[:-1])


# --- helpers --------------------------------------------------------------------------------------------


def test_harmonic_amplitudes_use_the_actuation_phase_convention():
    t = np.linspace(0, 5 * PERIOD, 400)
    s = np.stack([0.3 * np.sin(OMEGA * t + 1.2) + 2.0, 0.1 * np.sin(OMEGA * t - 2.5)], axis=1)
    z = L.harmonic_amplitudes(s, t, OMEGA)
    assert np.abs(z) == pytest.approx([0.3, 0.1], abs=1e-9)
    assert np.angle(z) == pytest.approx([1.2, -2.5], abs=1e-9)


def test_travelling_index_and_coherence():
    x = np.linspace(0, 2 * math.pi, 40, endpoint=False)
    assert L.travelling_index(np.exp(1j * x)) == pytest.approx(1.0, abs=1e-9)
    assert L.travelling_index(np.exp(0.7j) * np.cos(x)) == pytest.approx(0.0, abs=1e-12)
    assert L.travelling_index(np.zeros(5)) == 0.0
    assert L.phase_coherence(np.full(6, 2 * np.exp(0.4j))) == pytest.approx(1.0)
    assert L.phase_coherence(np.array([1.0, -1.0])) == pytest.approx(0.0)


def test_circular_linear_fit_recovers_a_gradient_modulo_2pi():
    rng = np.random.default_rng(4)
    xy = rng.uniform(-3, 3, (40, 2))
    g_true = np.array([0.8, -0.5])
    phases = np.mod(1.1 + xy @ g_true, 2 * math.pi)
    g, r = L.circular_linear_fit(phases, np.ones(40), xy)
    assert g == pytest.approx(g_true, abs=1e-3) and r == pytest.approx(1.0, abs=1e-6)
    g1, r1 = L.circular_linear_fit(np.mod(-0.4 * xy[:, 0], 2 * math.pi), np.ones(40), xy[:, 0])
    assert g1 == pytest.approx(-0.4, abs=1e-3) and r1 == pytest.approx(1.0, abs=1e-6)


def test_procrustes_removes_rotation_and_translation():
    X = hex_blob()
    frames = np.array(
        [
            X @ np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]]).T + [a, 2 * a]
            for a in np.linspace(0, 3, 7)
        ]
    )
    Q, R, mean = L.procrustes_frames(frames)
    assert np.allclose(Q, Q[0], atol=1e-12)
    assert np.allclose(np.einsum("fij,fkj->fik", R, R), np.eye(2), atol=1e-12)
    assert np.all(np.linalg.det(R) > 0)


# --- real swims with imposed phase patterns ---------------------------------------------------------------


@pytest.fixture(scope="module")
def real_body_setup():
    X = hex_blob(radius=3.2, seed=5) * 1.0
    c = animat.Config()
    c["evaluation.steps"] = 2400
    c["scene.drag_normal"] = 2.0
    return X, c


@pytest.mark.parametrize("stroke", [True, False], ids=["stroke_path", "earlier_rules"])
@pytest.mark.parametrize(
    "pattern,expected", [("sync", "synchronous contraction"), ("ramp", "undulation"), ("halves", "other")]
)
def test_real_swims_with_imposed_phases(real_body_setup, pattern, expected, stroke):
    # The calibration of the module docstring: the default classifier (the stroke path) and the earlier
    # rules (stroke=False) agree on these whole-body patterns.
    X, config = real_body_setup
    n = len(X)
    x = X[:, 0]
    phase = {
        "sync": np.zeros(n),
        "ramp": np.mod(-2 * math.pi * (x - x.min()) / np.ptp(x), 2 * math.pi),
        "halves": np.where(X[:, 1] > 0, math.pi, 0.0),
    }[pattern]
    body = animat.build_body(X, np.full(n, 0.2), np.full(n, 8.0), phase)
    tr = animat.replay(body, config)
    m = L.classify_locomotion(tr, stroke=stroke)
    assert m.omega == pytest.approx(8.0)
    assert m.mode == expected, m.reason
    if pattern == "ramp":
        assert m.wave.gradient[0] < 0 and m.wave.lag > math.pi  # the imposed 2π lag along x, measured
    if pattern == "sync":
        assert m.coherence > 0.95


def test_viable_seeds_are_viable():
    for s in VIABLE_SEEDS:
        assert animat.develop(animat.Genome.random(s), animat.Config()).viable


def test_classify_locomotion_replays_a_genome():
    config = animat.Config()
    config["evaluation.steps"] = 600
    genome = animat.Genome.random(VIABLE_SEEDS[0])
    m = L.classify_locomotion(genome, config)  # the default classifier (the stroke path), of a genome ...
    assert m.mode in L.MODES
    tr = animat.replay(genome, config)
    again = L.classify_locomotion(tr)  # ... and of its replay
    assert again.mode == m.mode and again.coherence == pytest.approx(m.coherence)


# --- statistics --------------------------------------------------------------------------------------------


def test_phase_spread_on_the_circle():
    same = L.phase_spread([1.0, 1.0, 1.0])
    assert (same.range, same.circular_std, same.distinct, same.differentiated) == (0.0, 0.0, 1, False)
    wrap = L.phase_spread([6.2, 0.1])  # 0.1 + (2π - 6.2) apart across 0
    assert wrap.range == pytest.approx(0.1 + 2 * math.pi - 6.2)
    assert not wrap.differentiated and wrap.distinct == 2
    half = L.phase_spread([0.0, math.pi, 0.5])
    assert half.range == pytest.approx(math.pi) and half.differentiated
    assert L.phase_spread([0.0, 0.3]).circular_std == pytest.approx(math.sqrt(-2 * math.log(math.cos(0.15))))


def test_oscillator_spread_of_a_hand_made_body():
    points = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, 0.9]])
    body = animat.build_body(points, [0.2, 0.2, 0.1], [5.0, 5.0, 5.0], [0.0, math.pi / 2, math.pi / 2])
    s = L.oscillator_spread(body)  # default config: amplitude_max 0.2
    assert s.amplitude_mean == pytest.approx(0.5 / 3)
    assert (s.amplitude_min, s.amplitude_max) == (0.1, 0.2)
    assert s.amplitude_relative == pytest.approx(0.5 / 0.6)
    assert s.amplitude_range == pytest.approx(0.5) and s.amplitude_differentiated
    assert (s.frequency_min, s.frequency_max, s.frequency_range, s.frequency_differentiated) == (5.0, 5.0, 0.0, False)
    assert s.phase.range == pytest.approx(math.pi / 2) and s.phase.differentiated
    # springs (0,1): |0.2 + 0.2i|, (0,2): |0.2 + 0.1i|, (1,2): 0.2i + 0.1i
    eff = [math.hypot(0.2, 0.2), math.hypot(0.2, 0.1), 0.3]
    assert s.spring_amplitude_mean == pytest.approx(np.mean(eff))
    assert s.spring_amplitude_range == pytest.approx(0.3 - math.hypot(0.2, 0.1))
    uniform = L.oscillator_spread(animat.build_body(points, [0.2] * 3, [5.0] * 3, [1.0] * 3))
    assert uniform.amplitude_relative == pytest.approx(1.0) and not uniform.amplitude_differentiated
    assert not uniform.phase.differentiated and uniform.spring_amplitude_mean == pytest.approx(0.4)
    detuned = L.oscillator_spread(animat.build_body(points, [0.2] * 3, [5.0, 5.0, 5.23], [1.0] * 3))
    dev = animat.Config().development  # the range is relative to the configured frequency span
    assert detuned.frequency_range == pytest.approx(0.23 / (dev.frequency_max - dev.frequency_min))
    assert detuned.frequency_differentiated
    assert detuned.spring_amplitude_mean == pytest.approx(0.4)  # unequal frequencies: a_i + a_j


def test_grow_output_final_and_realised():
    embryo = SimpleNamespace(
        outputs=np.array([[0, 0, 0.2, 0, 0, 0], [0, 0, 0.4, 0, 0, 0], [0, 0, 0.6, 0, 0, 0]]),
        radii=np.array([0.5, 0.55, 0.75]),
    )
    g = L.grow_output(embryo)  # cell_radius 0.5, max_growth 0.5
    assert (g.final_mean, g.final_min, g.final_max) == pytest.approx((0.4, 0.2, 0.6))
    assert g.realized == pytest.approx((0.2 + 1.0) / 2) and g.realized_min == pytest.approx(0.2)


def test_grow_output_of_a_developed_genome_is_in_range():
    config = animat.Config()
    genome = animat.Genome.random(VIABLE_SEEDS[0])
    g = L.grow_output(genome, config)
    embryo = animat.develop(genome, config)
    assert g.final_mean == pytest.approx(float(embryo.outputs[:, int(animat.OutputChannel.grow)].mean()))
    assert 0.0 <= g.realized_min <= g.realized <= 1.0 + 1e-12
    stats = L.best_statistics(genome, config)
    assert stats.cells == embryo.cell_count and stats.max_cells == 32
    assert stats.grow == g


def test_tries_per_viable():
    h = np.zeros(3, dtype=animat.HISTORY_DTYPE)
    h["generation"] = [0, 1, 2]
    h["evaluations"] = [13468, 13568, 13668]
    assert L.tries_per_viable(h, population=100) == pytest.approx(134.68)
    assert math.isnan(L.tries_per_viable(h[:0], population=100))
    with pytest.raises(ValueError, match="population"):
        L.tries_per_viable(h)


def test_tries_per_viable_of_a_run(tmp_path):
    c = animat.Config()
    c["evolution.population"] = 8
    c["evolution.generations"] = 1
    c["evaluation.steps"] = 100
    animat.evolve(c, out=str(tmp_path / "run"))
    run = animat.Run(tmp_path / "run")
    tries = L.tries_per_viable(run)
    assert tries == pytest.approx(run.history["evaluations"][0] / 8)
    assert tries >= 1.0


def _entry(generation, genome):
    return animat.LineageEntry(generation, float(generation), 0, genome, Path(f"gen_{generation:06d}.json"))


def test_morphology_changes_of_a_hand_made_lineage():
    config = animat.Config()
    a, b = animat.Genome.random(VIABLE_SEEDS[0]), animat.Genome.random(VIABLE_SEEDS[1])
    assert animat.morphology_distance(animat.develop(a, config), animat.develop(b, config)) > 0.25
    lineage = [_entry(0, a), _entry(3, a.__copy__()), _entry(7, b), _entry(9, b), _entry(12, a)]
    changes = L.morphology_changes(lineage, config)
    assert [e.generation for e in changes] == [0, 7, 12]
    assert L.last_morphology_change(lineage, config) == 12
    assert L.last_morphology_change(lineage[:4], config) == 7
    assert L.last_morphology_change(lineage[:2], config) == 0
    assert L.last_morphology_change([], config) is None


def test_morphology_changes_of_a_run_match_the_run_method(tmp_path):
    c = animat.Config()
    c["evolution.population"] = 12
    c["evolution.generations"] = 4
    c["evaluation.steps"] = 300
    animat.evolve(c, out=str(tmp_path / "run"))
    run = animat.Run(tmp_path / "run")
    ours = [e.generation for e in L.morphology_changes(run, graph=False)]
    assert ours == [e.generation for e in run.morphology_changes()]
    assert L.last_morphology_change(run) >= ours[-1]


# --- the report script on a tiny experiment -----------------------------------------------------------------


def test_replication_report_on_finished_and_partial_runs(tmp_path):
    import subprocess
    import sys

    root = Path(__file__).resolve().parents[2]
    runs = tmp_path / "runs"
    tiny = tmp_path / "tiny.toml"
    tiny.write_text("[evaluation]\nsteps = 300\n[evolution]\npopulation = 8\ngenerations = 2\n")
    animat.run_experiment(str(tiny), runs=2, out=str(runs / "dn2"), parallel=1, threads=1)  # finished: summary.json
    c = animat.load_config(str(tiny))
    c["scene.drag_normal"] = 10.0
    c["evolution.generations"] = 1
    animat.evolve(c, out=str(runs / "dn10" / "run_0"))  # a run without summary.json ("in progress")
    doc = tmp_path / "docs" / "replication.md"
    report = str(root / "studies" / "replication" / "replication_report.py")
    # The calibration swims about 500 hand-built swims (minutes): test_replication_report_calibration_section
    # checks its section on a few.
    out = subprocess.run(
        [sys.executable, report, "--runs", str(runs), "--doc", str(doc), "--no-gif", "--no-calibration"],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stderr
    text = doc.read_text()
    assert text.count("<!-- DISCUSSION -->") == 1
    assert text.index("## Where we differ") < text.index("<!-- DISCUSSION -->")
    assert "Status: runs still in progress" in text and "1 of 3 runs had not finished" in text
    assert "| `dn2` | 2 | 0.01 | 32 | 2 | 2, 2 |" in text
    assert "| `dn10` | 10 | 0.05 | 32 | 1 | 1 |" in text
    assert text.index("## d_N = 2, 32 cells") < text.index("## d_N = 10, 32 cells")  # the paper's order
    # The page's figures: per environment the fitness plot and the best run's, under fixed names; nothing else.
    images = tmp_path / "docs" / "images" / "replication"
    page = {
        "dn2_fitness.png",
        "dn2_best_motion.png",
        "dn2_best_phase.png",
        "dn10_fitness.png",
        "dn10_best_motion.png",
        "dn10_best_phase.png",
    }
    assert {q.name for q in images.iterdir()} == page
    for name in page:
        assert (images / name).stat().st_size > 1000, name
        assert f"images/replication/{name}" in text
    assert "--all-figures" in text
    # deterministic: a second run writes the same document; --all-figures adds every run's figures elsewhere
    first = text
    figures = tmp_path / "figures"
    subprocess.run(
        [
            sys.executable,
            report,
            "--runs",
            str(runs),
            "--doc",
            str(doc.with_name("all.md")),
            "--no-gif",
            "--no-calibration",
            "--all-figures",
            "--figures",
            str(figures),
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert {q.name for q in images.iterdir()} == page
    assert {q.name for q in figures.iterdir()} == {
        "dn2_run0_motion.png",
        "dn2_run0_phase.png",
        "dn2_run1_motion.png",
        "dn2_run1_phase.png",
        "dn10_run0_motion.png",
        "dn10_run0_phase.png",
    }
    subprocess.run(
        [sys.executable, report, "--runs", str(runs), "--doc", str(doc), "--no-gif", "--no-calibration"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert doc.read_text() == first


def test_replication_report_calibration_section():
    import replication_report as RR  # studies/replication (conftest.py)

    import known_swimmers as K  # studies/locomotion (conftest.py)

    cal = {s.name: s for s in K.paper_calibration_set()}
    swum = K.classify_known([cal["paper_single"], cal["synchronous_teardrop"]], drags=(0.5,))
    assert all(r.mode is not None and r.mode.stroke is not None for r in swum)  # the stroke path by default
    unstable = K.KnownResult(cal["tail4"], 0.5, 2000, None, 0.0, False)
    text = "\n".join(RR.calibration_lines({"calibration": swum, "eighth": [unstable]}))
    assert (
        "**Calibration sets** (2 bodies × 1 drag, 2 swims): synchronous contraction 1 of 1, protrusions 1 of 1." in text
    )
    assert "**Held-out set** (1 body × 1 drag, 1 swim): tail 0 of 1." in text
    assert "| tail | 0 | 0 | 0 | 0 | 0 | 1 |" in text  # the held-out matrix has the unstable column
    assert "| eighth | `tail4` | 0.5 | tail | unstable |" in text  # the misses: only the unstable swim
    assert "| calibration |" not in text
    assert "; protrusion swimmers " in text and " paddling; tails no pair in any of 0 swims;" in text
