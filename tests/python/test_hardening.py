"""Reliability, round 2 (issue 15) through Python: the issue's rows and a Hypothesis sweep of the API.

Rows: Rng.integer over the whole int64 range and clear argument errors; a Simulation shared by two
threads; load_config of a directory; an evolve callback returning a non-bool; Ctrl-C during
animat.evolve (partial result attached, resumable checkpoint); the `stop` event; one Ctrl-C stopping
`python -m animat experiment`; --resume with changed settings; a hand-edited checkpoint.
Anything that could kill the interpreter runs in a child interpreter, so a crash is a failed test.

docs/reliability.md lists every attack with its count and the test that covers it.
"""
from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import animat

ROOT = Path(__file__).resolve().parents[2]
PY = sys.executable
INT64_MIN, INT64_MAX = -2**63, 2**63 - 1


def run_python(code: str, timeout: float = 60, **kw) -> subprocess.CompletedProcess:
    """Run `code` in a fresh interpreter with this test's environment."""
    return subprocess.run([PY, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=timeout,
                          env=os.environ.copy(), **kw)


def small_config(**extra) -> animat.Config:
    c = animat.Config()
    c["evolution.population"] = 4
    c["evolution.elites"] = 1
    c["evolution.threads"] = 1
    c["evaluation.steps"] = 50
    for k, v in extra.items():
        c[k.replace("__", ".")] = v
    return c


def snapshot(d: Path) -> dict:
    return {str(p.relative_to(d)): (p.read_bytes() if p.is_file() else b"<dir>") for p in sorted(d.rglob("*"))}


# --------------------------------------------------------------------------------------------------
# Rng.integer

def test_rng_integer_over_the_whole_int64_range_does_not_kill_the_interpreter():
    # Was SIGFPE (a division by zero in below(0)).
    r = run_python(f"""
        import animat
        rng = animat.Rng(1)
        xs = [rng.integer({INT64_MIN}, {INT64_MAX}) for _ in range(64)]
        assert min(xs) < 0 < max(xs), xs
        print("ok")
    """)
    assert r.returncode == 0 and "ok" in r.stdout, r.stderr


def test_rng_integer_argument_errors_are_clear():
    rng = animat.Rng(1)
    with pytest.raises(ValueError, match=r"low = 10 exceeds high = 0"):  # was -5480124913605472049
        rng.integer(10, 0)
    with pytest.raises(OverflowError, match=r"high = 9223372036854775808 is outside the 64-bit signed range"):
        rng.integer(0, 2**63)
    with pytest.raises(TypeError, match=r"low must be an integer, got float"):
        rng.integer(0.5, 3)
    np = pytest.importorskip("numpy")
    assert 0 <= rng.integer(np.int64(0), np.int64(3)) <= 3
    assert rng.integer(7, 7) == 7


@settings(max_examples=300, deadline=None)
@given(st.integers(min_value=-2**70, max_value=2**70), st.integers(min_value=-2**70, max_value=2**70))
def test_rng_integer_property(a, b):
    rng = animat.Rng(abs(a) % 1000)
    if not (INT64_MIN <= a <= INT64_MAX and INT64_MIN <= b <= INT64_MAX):
        with pytest.raises(OverflowError):
            rng.integer(a, b)
    elif a > b:
        with pytest.raises(ValueError):
            rng.integer(a, b)
    else:
        assert a <= rng.integer(a, b) <= b


# --------------------------------------------------------------------------------------------------
# Objects that are not thread-safe

def test_one_simulation_stepped_from_two_threads_is_a_clear_error_not_an_abort():
    # Was SIGABRT (b2StackAllocator assertion): step() releases the GIL.
    r = run_python("""
        import threading, animat
        genome = None
        config = animat.Config()
        for seed in range(5000):
            g = animat.Genome.random(seed)
            e = animat.develop(g, config)
            if e.viable:
                break
        sim = animat.Simulation(animat.build_body(e))
        started = threading.Event()
        errors = []
        def long_step():
            started.set()
            sim.step(300000)
        t = threading.Thread(target=long_step)
        t.start()
        started.wait()
        for _ in range(200):
            try:
                sim.step(1)
                _ = sim.positions
            except RuntimeError as err:
                errors.append(str(err))
                break
        t.join()
        assert errors, "the second thread was never refused"
        assert "in use by another thread" in errors[0], errors[0]
        sim.step(1)  # usable again once the other thread is done
        print("ok")
    """, timeout=120)
    assert r.returncode == 0 and "ok" in r.stdout, (r.returncode, r.stderr[-2000:])


# --------------------------------------------------------------------------------------------------
# load_config

def test_load_config_of_a_directory_or_unreadable_file_is_an_error(tmp_path):
    with pytest.raises(OSError, match="Is a directory"):  # was the default config, silently
        animat.load_config(str(tmp_path))
    with pytest.raises(OSError):
        animat.load_config(str(tmp_path / "missing.toml"))
    if os.geteuid() != 0:
        f = tmp_path / "secret.toml"
        f.write_text("[evolution]\npopulation = 10\n")
        f.chmod(0)
        with pytest.raises(OSError, match="Permission denied"):
            animat.load_config(str(f))


# --------------------------------------------------------------------------------------------------
# animat.evolve: callback result, Ctrl-C, stop event, resume

def test_evolve_callback_returning_a_non_bool_is_a_type_error_with_a_resumable_checkpoint(tmp_path):
    out = tmp_path / "run"
    config = small_config(evolution__generations=5, evolution__checkpoint_every=3)
    with pytest.raises(TypeError, match=r"callback must return True, False or None.*got str 'no'") as e:
        animat.evolve(config, out=str(out), callback=lambda s: "no")  # was RuntimeError: std::bad_cast
    partial = e.value.result
    # The callback sees generation 0 too (the initial population), so the bad answer stops the run there.
    assert [s.generation for s in partial.history] == [0]
    resumed = animat.evolve(config, out=str(out), resume=True, callback=lambda s: None)
    assert resumed.history[-1].generation == 5
    np = pytest.importorskip("numpy")
    assert animat.evolve(small_config(evolution__generations=3), callback=lambda s: np.bool_(s.generation < 2)
                         ).stop_reason == "stopped by callback"


def test_evolve_exception_in_the_callback_is_raised_with_the_partial_result(tmp_path):
    def boom(stats):
        if stats.generation == 2:
            raise ZeroDivisionError("from the callback")
    config = small_config(evolution__generations=6, evolution__checkpoint_every=4)
    with pytest.raises(ZeroDivisionError) as e:
        animat.evolve(config, out=str(tmp_path / "run"), callback=boom)
    assert e.value.result.history[-1].generation == 2
    assert animat.Run(tmp_path / "run").history["generation"][-1] == 2


def test_evolve_stop_event_returns_an_interrupted_result(tmp_path):
    stop = threading.Event()
    config = small_config()
    config["evaluation.steps"] = 4000
    config["evolution.population"] = 30
    timer = threading.Timer(2.0, stop.set)
    timer.start()
    t0 = time.perf_counter()
    result = animat.evolve(config, out=str(tmp_path / "run"), stop=stop)
    timer.join()
    assert result.stop_reason == "interrupted"
    assert time.perf_counter() - t0 < 3.0
    if result.history:  # stopped after generation 0: a checkpoint to resume
        again = animat.evolve(config.copy(), out=str(tmp_path / "run"), resume=True,
                              callback=lambda s: False)
        assert again.history[0].generation == 0


def _ctrl_c_as_in_a_terminal():
    # A job started in the background by a non-interactive shell (`cmd &`) inherits SIGINT ignored, and
    # Python then installs no KeyboardInterrupt handler: the child would ignore the test's Ctrl-C.
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_ctrl_c_during_evolve_raises_keyboard_interrupt_with_the_result_and_a_checkpoint(tmp_path):
    # Was ignored until every generation was done, then the result was lost.
    out = tmp_path / "run"
    script = f"""
        import animat, sys, time
        c = animat.Config()
        c["evolution.population"] = 40
        c["evolution.threads"] = 2
        c["evolution.checkpoint_every"] = 100
        try:
            animat.evolve(c, out={str(out)!r})
        except KeyboardInterrupt as e:
            r = e.result
            print("interrupted", r.stop_reason, len(r.history), flush=True)
            sys.exit(0)
        print("not interrupted")
        sys.exit(1)
    """
    p = subprocess.Popen([PY, "-c", textwrap.dedent(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         preexec_fn=_ctrl_c_as_in_a_terminal)
    deadline = time.time() + 120
    while not (out / "checkpoint.json").exists() and time.time() < deadline and p.poll() is None:
        time.sleep(0.05)
    time.sleep(1.0)  # inside generation 1's evaluations
    p.send_signal(signal.SIGINT)
    t0 = time.perf_counter()
    try:
        stdout, stderr = p.communicate(timeout=30)
    finally:
        p.kill()  # never leave a run behind when the Ctrl-C is ignored
    took = time.perf_counter() - t0
    print(f"Ctrl-C during animat.evolve: the interpreter exited {took:.3f} s after the signal")
    assert p.returncode == 0, stderr[-2000:]
    assert stdout.startswith("interrupted interrupted"), stdout
    # Measured 0.2 to 0.6 s (docs/reliability.md); 3 s allowed on a shared machine. Before: never.
    assert took < 3.0, f"Ctrl-C took {took:.2f} s"
    generations = int(stdout.split()[2])
    assert generations >= 1
    # The checkpoint is the last complete generation, and it resumes.
    run = animat.Run(out)
    assert run.history["generation"][-1] == generations - 1
    c = animat.load_config(str(out / "config.toml"))
    c["evolution.generations"] = generations
    c["evaluation.steps"] = c["evaluation.steps"]  # unchanged: a resume may only change caps
    resumed = animat.evolve(c, out=str(out), resume=True)
    assert resumed.history[-1].generation == generations


def test_experiment_stops_every_run_on_one_ctrl_c(tmp_path):
    # Was: a second Ctrl-C needed, worker threads abandoned.
    cfg = tmp_path / "exp.toml"
    cfg.write_text("[evolution]\npopulation = 30\nelites = 1\n")
    out = tmp_path / "exp"
    p = subprocess.Popen([PY, "-m", "animat", "experiment", str(cfg), "--runs", "3", "--parallel", "2", "--threads", "2",
                          "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         cwd=str(tmp_path), preexec_fn=_ctrl_c_as_in_a_terminal)
    deadline = time.time() + 120
    while time.time() < deadline and p.poll() is None and not all(
            (out / f"run_{i}" / "checkpoint.json").exists() for i in (0, 1)):
        time.sleep(0.05)
    time.sleep(0.5)
    p.send_signal(signal.SIGINT)  # one Ctrl-C
    t0 = time.perf_counter()
    try:
        stdout, stderr = p.communicate(timeout=30)
    finally:
        p.kill()
    took = time.perf_counter() - t0
    print(f"one Ctrl-C during python -m animat experiment: exit {p.returncode}, {took:.3f} s after the signal")
    assert p.returncode == 130, (p.returncode, stderr[-2000:])
    assert "interrupted" in stderr and "resume" in stderr, stderr
    assert took < 3.0, f"one Ctrl-C took {took:.2f} s"  # measured 0.13 to 0.19 s; before: never
    for i in (0, 1):  # both running runs stopped with a checkpoint that restores
        run = animat.Run(out / f"run_{i}")
        assert len(run.history["generation"]) >= 1
    assert not (out / "run_2").exists(), "a run was started after the Ctrl-C"


def test_resume_with_a_changed_setting_is_refused_naming_it_and_writes_nothing(tmp_path):
    out = tmp_path / "run"
    config = small_config(evolution__generations=1)
    animat.evolve(config, out=str(out))
    before = snapshot(out)
    changed = config.copy()
    changed["scene.drag_normal"] = 10.0
    with pytest.raises(ValueError, match=r"scene\.drag_normal \(the run has 2\.0, this command gives 10\.0\)"):
        animat.evolve(changed, out=str(out), resume=True)
    assert snapshot(out) == before
    extended = config.copy()
    extended["evolution.generations"] = 2
    assert animat.evolve(extended, out=str(out), resume=True).history[-1].generation == 2
    assert "evolution.generations 1 -> 2" in (out / "resume.log").read_text()


def test_hand_edited_checkpoint_is_refused(tmp_path):
    out = tmp_path / "run"
    config = small_config(evolution__generations=2)
    animat.evolve(config, out=str(out))
    outer = json.loads((out / "checkpoint.json").read_text())
    payload = json.loads(outer["payload"])
    payload["history"].reverse()
    body = json.dumps(payload, separators=(",", ":"))
    h = 0xcbf29ce484222325
    for ch in body.encode():
        h = ((h ^ ch) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    (out / "checkpoint.json").write_text(json.dumps({"checksum": f"{h:016x}", "payload": body}))
    before = snapshot(out)
    with pytest.raises(ValueError, match="checkpoint"):
        animat.evolve(config, out=str(out), resume=True)
    assert snapshot(out) == before


# --------------------------------------------------------------------------------------------------
# Hypothesis: the config API with any key and any value

KEYS = animat.Config().keys()
VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-1e7, max_value=1e7),
    st.integers(min_value=-2**70, max_value=2**70),
    st.integers(min_value=-10, max_value=5000),
    st.booleans(),
    st.text(max_size=12),
    st.sampled_from(["stable", "explicit", "midpoint", "springs", "drag", "repulsion"]),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=7),
    st.lists(st.sampled_from(["springs", "drag", "pressure", "repulsion", "adhesion", "morphogens", "x"]), max_size=4),
)


@settings(max_examples=1500, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(KEYS), VALUES)
def test_config_set_any_key_to_any_value(key, value):
    c = animat.Config()
    try:
        c[key] = value
    except ValueError as e:
        assert key in str(e), str(e)
        assert c == animat.Config(), "a refused write changed the config"
        return
    except (TypeError, OverflowError):
        assert c == animat.Config()
        return
    # Accepted in range; a cross-field rule (elites < population...) may still refuse it, naming it.
    try:
        c.validate()
    except ValueError as e:
        assert key in str(e), str(e)
        return
    # Valid: it survives the TOML round trip exactly.
    back = animat.Config.from_toml(c.to_toml())
    got = back[key]
    if isinstance(got, float) and math.isnan(got):
        pytest.fail(f"{key} accepted NaN")
    assert back == c


SCENE_FLOATS = [k for k in KEYS if k.split(".")[0] in ("scene", "physics", "development")
                and isinstance(animat.Config()[k], float)]


@pytest.fixture(scope="module")
def viable_genome():
    config = animat.Config()
    for seed in range(5000):
        g = animat.Genome.random(seed)
        if animat.develop(g, config).viable:
            return g
    pytest.fail("no viable genome")


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(key=st.sampled_from(SCENE_FLOATS), fraction=st.one_of(st.just(0.0), st.just(1.0), st.floats(0, 1)))
def test_evaluate_at_any_in_range_value_is_finite(viable_genome, key, fraction):
    # Anywhere in a key's declared range, evaluate() gives a finite fitness >= 0, never a crash.
    c = animat.Config()
    c["evaluation.steps"] = 60
    doc = c.doc(key)
    lo, hi = _range_of(doc)
    if lo is None:
        return
    value = lo + (hi - lo) * fraction
    try:
        c[key] = value
        c.validate()
    except ValueError as e:
        assert key.split(".")[1] in str(e)
        return
    r = animat.evaluate(viable_genome, c)
    assert math.isfinite(r.fitness) and r.fitness >= 0.0
    assert r.fitness == 0.0 or (r.viable and r.stable)
    assert r.cell_count <= c["development.max_cells"]


def _range_of(doc: str):
    """(lo, hi) from a key's doc '... (in [a, b])' or '(in (a, b])'; None for other forms."""
    import re
    m = re.search(r"\(in [\[(]([-0-9.e+]+), ([-0-9.e+]+)[\])]\)$", doc)
    if not m:
        return None, None
    lo, hi = float(m.group(1)), float(m.group(2))
    return math.nextafter(lo, math.inf), math.nextafter(hi, -math.inf)


@settings(max_examples=150, deadline=None)
@given(st.lists(st.tuples(st.floats(-1e6, 1e6), st.floats(-1e6, 1e6)), min_size=1, max_size=12),
       st.floats(-1e3, 1e3), st.floats(0, 1e12))
def test_simulation_of_any_point_set_never_crashes(points, frequency, drag):
    # Built from any points the body stage accepts, a swim either runs or raises a clear error.
    np = pytest.importorskip("numpy")
    pts = np.array(points, dtype=float)
    n = len(pts)
    try:
        body = animat.build_body(pts, np.full(n, 0.2), np.full(n, frequency), np.zeros(n))
    except ValueError:
        return
    try:
        sim = animat.Simulation(body, animat.Scene(drag_normal=drag))
        sim.step(20)
        assert np.all(np.isfinite(sim.positions))
    except (ValueError, RuntimeError) as e:
        assert str(e)
