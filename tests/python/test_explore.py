"""``animat explore``: the page's data (curves downsampled, flags, lineage, genealogy, swim, config
differences), the command line, and the page itself in a real headless Chromium (playwright driving
Debian's ``/usr/bin/chromium``): it loads without a console error, its canvases draw, play, pause and
the scrubber move the swim, the genealogy of a hand-written genealogy.csv is drawn, and a served live
page redraws after rows are appended to history.csv.

The browser tests skip, saying why, only when Chromium or playwright is missing and ``CI`` is unset;
under ``CI=true`` they fail instead (scripts/setup.sh installs both). The load time of a 1,000-generation
study is measured by ``bench/explore_load.py``, not asserted here: a test holds the page's size and its
downsampling, which decide it.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import threading
import urllib.parse
import urllib.request
from pathlib import Path

import numpy as np
import pytest

import animat
from animat import explore

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = os.environ.get("ANIMAT_CHROMIUM") or shutil.which("chromium") or shutil.which("chromium-browser")
IN_CI = os.environ.get("CI", "").strip().lower() not in ("", "0", "false", "no")


def tiny_config(base=None, **keys):
    c = animat.Config() if base is None else animat.load_config(str(base))
    c["evolution.population"] = 8
    c["evaluation.steps"] = 300
    for k, v in keys.items():
        c[k.replace("__", ".")] = v
    return c


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Three tiny runs: seed 1 and seed 2 of the default world (an experiment directory), and a copy of
    the first with a hand-written genealogy.csv."""
    root = tmp_path_factory.mktemp("explore")
    for seed in (1, 2):
        animat.evolve(
            tiny_config(evolution__seed=seed), out=str(root / "study" / f"run_{seed}"), generations=3, quiet=True
        )
    shutil.copytree(root / "study" / "run_1", root / "genealogy" / "run")
    write_genealogy_fixture(root / "genealogy" / "run")
    return root


#: The fixture's individuals: (generation, id, parent_a, parent_b, fitness). Ids 0-5 are generation 0;
#: 6 and 8 are mutants, 7, 9, 12 and 13 children of a crossover. The best (13, generation 4) descends
#: from 13 individuals (itself included): 13, 11, 12, 9, 10, 4, 6, 7, 8 and the founders 0, 1, 2, 3;
#: 5, 14 and 15 are not its ancestors. Its primary line (parent_a) is 13, 11, 9, 6, 0.
GENEALOGY = [
    (0, 0, -1, -1, 0.01),
    (0, 1, -1, -1, 0.002),
    (0, 2, -1, -1, 0.003),
    (0, 3, -1, -1, 0.004),
    (0, 4, -1, -1, 0.005),
    (0, 5, -1, -1, 0.006),
    (1, 6, 0, -1, 0.02),
    (1, 7, 1, 2, 0.002),
    (1, 8, 3, -1, 0.003),
    (2, 9, 6, 7, 0.03),
    (2, 10, 8, -1, 0.004),
    (3, 11, 9, -1, 0.025),
    (3, 12, 10, 4, 0.02),
    (4, 13, 11, 12, 0.04),
    (4, 14, 5, -1, 0.01),
    (5, 15, 13, -1, 0.05),
]
FIXTURE_LINEAGE = {0: 0, 1: 6, 2: 9, 4: 13}  # generation of each best -> its id
FIXTURE_ANCESTORS = {13, 11, 12, 9, 10, 4, 6, 7, 8, 0, 1, 2, 3}
FIXTURE_PRIMARY = [13, 11, 9, 6, 0]


def write_genealogy_fixture(run: Path, ids: bool = True) -> None:
    """genealogy.csv from GENEALOGY, and best/gen_*.json for the bests of FIXTURE_LINEAGE (the run's own
    best genome in each, with the fixture's fitness and, when ``ids``, the fixture's id)."""
    files = sorted((run / "best").glob("gen_*.json"))
    data = json.loads(files[-1].read_text())
    data.pop("id", None)
    for f in files:
        f.unlink()
    fitness = {i: f for _, i, _, _, f in GENEALOGY}
    for generation, i in FIXTURE_LINEAGE.items():
        entry = {**data, "generation": generation, "fitness": fitness[i]}
        if ids:
            entry["id"] = i
        (run / "best" / f"gen_{generation:06d}.json").write_text(json.dumps(entry))
    rows = "".join(f"{g},{i},{a},{b},{f!r},32\n" for g, i, a, b, f in GENEALOGY)
    (run / "genealogy.csv").write_text("generation,id,parent_a,parent_b,fitness,cells\n" + rows)


def cli(*args):
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-m", "animat", *map(str, args)], capture_output=True, text=True, env=env)


# --- finding runs, downsampling, genealogy ---------------------------------------------------------------


def test_find_runs_reads_run_and_experiment_directories(runs, tmp_path):
    one = explore.find_runs([runs / "study" / "run_1"])
    assert [(r.label, r.group) for r in one] == [("run_1", "")]
    study = explore.find_runs([runs / "study"])
    assert [r.label for r in study] == ["run_1", "run_2"]
    nested = tmp_path / "exp"
    for env in ("dn2", "dn10"):
        for i in (0, 1):
            shutil.copytree(runs / "study" / "run_1", nested / env / f"run_{i}")
    refs = explore.find_runs([nested])
    assert [(r.label, r.group) for r in refs] == [  # natural order: dn2 before dn10
        ("dn2/run_0", "dn2"),
        ("dn2/run_1", "dn2"),
        ("dn10/run_0", "dn10"),
        ("dn10/run_1", "dn10"),
    ]
    both = explore.find_runs([runs / "study" / "run_1", runs / "genealogy" / "run", runs / "study" / "run_1"])
    assert len({r.label for r in both}) == 3


def test_find_runs_names_the_bad_path(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope"):
        explore.find_runs([tmp_path / "nope"])
    (tmp_path / "empty").mkdir()
    with pytest.raises(FileNotFoundError, match="empty.*neither a run directory"):
        explore.find_runs([tmp_path / "empty"])
    (tmp_path / "file.txt").write_text("x")
    with pytest.raises(NotADirectoryError, match="file.txt"):
        explore.find_runs([tmp_path / "file.txt"])


def test_downsampling_keeps_the_ends_and_the_changes_within_the_budget():
    assert list(explore.downsample_indices(10, 500)) == list(range(10))
    keep = [3, 77, 78, 401, 998]
    idx = explore.downsample_indices(1000, 100, keep)
    assert len(idx) <= 100 and idx[0] == 0 and idx[-1] == 999
    assert set(keep) <= set(idx.tolist())
    assert np.all(np.diff(idx) > 0)
    many = explore.downsample_indices(1000, 50, range(0, 1000, 2))  # more changes than half the budget
    assert len(many) <= 50


def test_read_genealogy_and_the_ancestry_of_the_best(runs, tmp_path):
    table = explore.read_genealogy(runs / "genealogy" / "run" / "genealogy.csv")
    assert len(table) == len(GENEALOGY) and table[9] == (2, 6, 7, 0.03, 32)
    ancestors, primary = explore.ancestry(table, 13)
    assert set(ancestors) == FIXTURE_ANCESTORS and primary == FIXTURE_PRIMARY
    generations = [table[i][0] for i in ancestors]
    assert generations == sorted(generations, reverse=True)  # youngest first
    partial = tmp_path / "genealogy.csv"
    partial.write_text((runs / "genealogy" / "run" / "genealogy.csv").read_text() + "6,16,15,-")
    assert len(explore.read_genealogy(partial)) == len(GENEALOGY)  # a row being written is ignored
    partial.write_text("generation,id,parent_a,parent_b,fitness,cells\n0,0,-1,-1,0.1,32\n1,x,0,-1,0.2,32\n")
    with pytest.raises(ValueError, match=r"genealogy.csv:3: not a number"):
        explore.read_genealogy(partial)
    partial.write_text("gen,id\n")
    with pytest.raises(ValueError, match=r"genealogy.csv:1: unexpected header"):
        explore.read_genealogy(partial)


def test_the_genealogy_payload_traces_the_fixture_and_degrades_without_it(runs, tmp_path):
    data = explore.build_data([runs / "genealogy" / "run"], frames=20)
    g = data["runs"][0]["genealogy"]
    ids = [n[0] for n in g["nodes"]]
    assert set(ids) == FIXTURE_ANCESTORS and g["total"] == g["shown"] == 13 and g["founders"] == 4 + 1
    assert [ids[k] for k in g["primary"]] == FIXTURE_PRIMARY and ids[g["best"]] == 13
    assert g["matched_by"] == "id"
    node = {n[0]: n for n in g["nodes"]}
    assert ids[node[12][2]] == 10 and ids[node[12][3]] == 4  # parent_a, parent_b as indices
    assert {n[0] for n in g["nodes"] if n[6]} == set(FIXTURE_LINEAGE.values())  # the bests of the lineage
    assert [e["id"] for e in data["runs"][0]["lineage"]] == [0, 6, 9, 13]
    # lineage files without an id (a run written before them): the best is found by generation and fitness
    no_ids = tmp_path / "no_ids"
    shutil.copytree(runs / "genealogy" / "run", no_ids)
    write_genealogy_fixture(no_ids, ids=False)
    g2 = explore.build_data([no_ids], frames=20)["runs"][0]["genealogy"]
    assert g2["matched_by"] == "match" and {n[0] for n in g2["nodes"]} == FIXTURE_ANCESTORS
    # a capped drawing keeps the primary line
    capped = explore.build_data([runs / "genealogy" / "run"], frames=20, max_nodes=6)["runs"][0]["genealogy"]
    assert capped["shown"] == 6 and capped["total"] == 13
    assert [capped["nodes"][k][0] for k in capped["primary"]] == FIXTURE_PRIMARY
    # no genealogy.csv (a run made before it was recorded): a note
    old = tmp_path / "old"
    shutil.copytree(runs / "study" / "run_1", old)
    (old / "genealogy.csv").unlink()
    plain = explore.build_data([old], frames=20)["runs"][0]["genealogy"]
    assert "nodes" not in plain and "no genealogy.csv" in plain["note"]
    # a real run's genealogy: the best traced back to generation 0
    real = explore.build_data([runs / "study" / "run_1"], frames=20)["runs"][0]["genealogy"]
    assert real["matched_by"] == "id" and real["total"] >= 1


def test_the_data_hold_curves_flags_lineage_swim_and_config_differences(runs):
    data = explore.build_data([runs / "study"], frames=30, modes=True)
    assert [r["label"] for r in data["runs"]] == ["run_1", "run_2"]
    run = animat.Run(runs / "study" / "run_1")
    r = data["runs"][0]
    h = run.history
    assert r["history"]["generation"] == h["generation"].tolist() and r["history"]["total"] == len(h)
    assert r["history"]["best"] == pytest.approx(h["best"].tolist(), rel=1e-5)
    assert [e["generation"] for e in r["lineage"]] == [e.generation for e in run.best_genomes]
    s = r["swim"]
    assert s["frames"] <= 30 and s["n"] == run.best().cell_count
    assert len(explore.base64.b64decode(s["pos"])) == s["frames"] * s["n"] * 2 * 2  # int16 x, y
    assert len(explore.base64.b64decode(s["state"])) == s["frames"] * s["n"]
    assert s["world"]["floor"] is None and s["world"]["source"] is None and s["stiffness"] is None
    assert s["graph"] == "Gabriel graph" and "fluid d_N = 2" in r["world"]
    assert len(s["phase"]) == s["n"] and len(s["rest"]) == 2 * s["n"]
    assert r["mode"] and isinstance(r["mode"], str)
    assert data["config_diff"] == {"against": "runs", "keys": [["evolution.seed", [1, 2]]]}
    single = explore.build_data([runs / "study" / "run_1"], frames=10)["config_diff"]
    assert single["against"] == "defaults" and ["evaluation.steps", [4000, 300]] in single["keys"]


def test_the_flags_mark_invalid_swims_the_drag_limiter_and_unconfirmed_bests(runs, tmp_path):
    run = tmp_path / "flags"
    shutil.copytree(runs / "study" / "run_1", run)
    lines = (run / "history.csv").read_text().splitlines()
    col = {name: k for k, name in enumerate(lines[0].split(","))}
    rows = [line.split(",") for line in lines[1:]]
    rows[1][col["invalid"]] = "3"
    rows[2][col["drag_limited"]] = "2"
    # best_reference far below best: not confirmed
    rows[3][col["best_reference"]] = str(float(rows[3][col["best"]]) * 0.5 - 1.0)
    (run / "history.csv").write_text("\n".join([lines[0]] + [",".join(r) for r in rows]) + "\n")
    flags = explore.build_data([run], frames=10)["runs"][0]["flags"]
    assert flags["invalid"] == [[1, 3]] and flags["drag_limited"] == [[2, 2]]
    assert [f[0] for f in flags["guard"]] == [3]


def test_the_worlds_are_drawn_as_they_are(tmp_path):
    crawl = tmp_path / "crawl"
    animat.evolve(tiny_config(ROOT / "configs" / "crawl.toml"), out=str(crawl), generations=1, quiet=True)
    chem = tmp_path / "chemotaxis"
    animat.evolve(tiny_config(ROOT / "configs" / "chemotaxis.toml"), out=str(chem), generations=1, quiet=True)
    data = explore.build_data([crawl, chem], frames=20)
    floor, source = data["runs"][0]["swim"], data["runs"][1]["swim"]
    assert floor["world"]["floor"] == 0.0 and not floor["aligned"] and floor["world"]["source"] is None
    assert source["world"]["source"] is not None and source["world"]["chemical"]["kind"] == "point"
    assert source["progress_label"] == "to source" and source["control"] == "grn"
    assert "floor at y = 0" in data["runs"][0]["world"] and "source" in data["runs"][1]["world"]


def test_a_long_study_is_downsampled_and_the_page_stays_small(runs, tmp_path):
    study = long_study(runs, tmp_path, runs_count=3, generations=1000)
    data = explore.build_data([study], frames=200)
    for r in data["runs"]:
        h = r["history"]
        assert h["total"] == 1000 and len(h["generation"]) <= 500
        assert h["changes_kept"] and len(set(h["best"])) == 200  # every step of the best is drawn
        assert len(r["flags"]["invalid"]) == 100  # flags are never downsampled
    page = explore.render_html(data)
    assert len(page.encode()) < 600_000, len(page)
    assert not re.search(r"""<(script|link|img)[^>]+(src|href)=["']?(https?:|//)""", page)  # nothing fetched


def long_study(runs: Path, tmp_path: Path, runs_count: int, generations: int) -> Path:
    """An experiment directory of copies of a tiny run whose history.csv has ``generations`` rows: a
    best that rises in 200 steps, invalid swims every tenth generation."""
    study = tmp_path / "long"
    header = (runs / "study" / "run_1" / "history.csv").read_text().splitlines()[0]
    for k in range(runs_count):
        run = study / f"run_{k}"
        shutil.copytree(runs / "study" / "run_1", run)
        values = lambda g, k=k: {  # noqa: E731
            "generation": g,
            "best": (g // 5) * 0.01 + k,
            "mean": g * 0.001,
            "median": g * 0.001,
            "viable_fraction": 0.9,
            "best_cells": 32,
            "evaluations": 100 * g,
            "swims": 90,
            "best_reference": (g // 5) * 0.01 + k,
            "invalid": int(g % 10 == 0),
            "drag_limited": 0,
            "wall_seconds": g * 0.5,
        }
        rows = [",".join(str(values(g)[name]) for name in header.split(",")) for g in range(generations)]
        (run / "history.csv").write_text(header + "\n" + "\n".join(rows) + "\n")
    return study


# --- the command line -----------------------------------------------------------------------------------------


def test_cli_writes_the_page_of_one_run_and_of_a_study(runs, tmp_path):
    r = cli("explore", runs / "study" / "run_1", "--frames", 20)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == str(runs / "study" / "run_1" / "explore.html")
    out = tmp_path / "study.html"
    r = cli("explore", runs / "study", runs / "genealogy" / "run", "--out", out, "--frames", 20)
    assert r.returncode == 0, r.stderr
    text = out.read_text()
    assert "__ANIMAT_DATA__" not in text and '"label":"study/run_1"' in text and '"label":"run"' in text


def test_cli_errors_are_one_line_naming_the_path(runs, tmp_path):
    for args, expected in (
        ([tmp_path / "nope"], "nope"),
        ([tmp_path], str(tmp_path)),
        ([runs / "study" / "run_1", runs / "study" / "run_2"], "--out"),
        ([runs / "study" / "run_1", "--live"], "--serve"),
        ([runs / "study" / "run_1", "--frames", "1"], "--frames"),
    ):
        r = cli("explore", *args)
        assert r.returncode == 1, (args, r.stderr)
        assert r.stderr.startswith("animat explore: error:") and expected in r.stderr, r.stderr
        assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr


# --- in Chromium --------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def browser():
    missing = []
    if CHROMIUM is None:
        missing.append("Chromium (apt-get install chromium; scripts/setup.sh installs it)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        sync_playwright = None
        missing.append("playwright (.venv/bin/pip install -r requirements-dev.txt)")
    if missing:
        message = f"the browser tests need {' and '.join(missing)}"
        if IN_CI:
            pytest.fail(f"CI is set: {message}")
        pytest.skip(message)
    assert sync_playwright is not None
    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=CHROMIUM)
        yield b
        b.close()


def open_page(browser, url: str):
    """The page, loaded and ready, with the list its console errors and uncaught exceptions go to."""
    page = browser.new_page(viewport={"width": 1200, "height": 900})
    page.set_default_timeout(0)  # every wait is on an event of the page, however busy the machine
    problems: list = []
    page.on("console", lambda m: problems.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: problems.append(str(e)))
    page.goto(url)
    page.wait_for_function("window.animatExplore && (window.animatExplore.ready || window.animatExplore.errors.length)")
    assert page.evaluate("animatExplore.ready"), page.evaluate("animatExplore.errors")
    return page, problems


INKED = """(id) => { const c = document.getElementById(id); const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
  let k = 0; for (let i = 0; i < d.length; i += 4) if (d[i] < 235 || d[i + 1] < 235 || d[i + 2] < 235) k++; return k; }"""
PIXELS = "(id) => document.getElementById(id).toDataURL()"


def test_the_page_draws_plays_pauses_and_scrubs(browser, runs, tmp_path):
    path = explore.write_page([runs / "genealogy" / "run"], tmp_path / "page.html", frames=60)
    page, problems = open_page(browser, path.as_uri())
    for canvas in ("curves", "viable", "swim", "phase", "genealogy"):
        assert page.evaluate(INKED, canvas) > 500, canvas
    assert page.evaluate("animatExplore.frame") == 0 and not page.evaluate("animatExplore.playing")
    first = page.evaluate(PIXELS, "swim")
    page.click("#play")
    page.wait_for_function("animatExplore.frame >= 3")
    page.click("#play")  # pause
    assert not page.evaluate("animatExplore.playing")
    paused = page.evaluate("animatExplore.frame")
    page.wait_for_timeout(300)
    assert page.evaluate("animatExplore.frame") == paused  # paused: no frame moves
    assert page.evaluate(PIXELS, "swim") != first
    page.eval_on_selector("#scrub", "(e) => { e.value = '40'; e.dispatchEvent(new Event('input')); }")
    assert page.evaluate("animatExplore.frame") == 40
    frames = page.evaluate("animatExplore.data.runs[0].swim.frames")
    assert 40 < frames <= 60 and page.text_content("#frame-label") == f"frame 41 / {frames}"
    scrubbed = page.evaluate(PIXELS, "swim")
    modes = page.eval_on_selector_all("#color-by option", "(os) => os.map((o) => o.value)")
    assert modes == ["state", "term", "phase"]
    page.select_option("#color-by", "phase")
    assert page.evaluate(PIXELS, "swim") != scrubbed
    page.select_option("#color-by", "term")
    assert page.evaluate("animatExplore.genealogy.drawn") == 13
    assert page.evaluate("animatExplore.genealogy.primary") == 5
    assert page.evaluate("animatExplore.genealogy.edges") == 12  # 4 mutants (1 parent) and 4 crossovers (2)
    assert "13 ancestors" in page.text_content("#genealogy-note")
    assert page.eval_on_selector_all("#lineage tbody tr", "(rs) => rs.length") == 4
    page.hover("#curves", position={"x": 600, "y": 150})
    assert "generation" in page.text_content("#readout")
    assert not problems and not page.evaluate("animatExplore.errors")
    page.close()


def test_a_study_page_overlays_runs_and_shows_modes_and_worlds(browser, runs, tmp_path):
    crawl = tmp_path / "crawl"
    animat.evolve(tiny_config(ROOT / "configs" / "crawl.toml"), out=str(crawl), generations=1, quiet=True)
    chem = tmp_path / "chem"
    animat.evolve(tiny_config(ROOT / "configs" / "chemotaxis.toml"), out=str(chem), generations=1, quiet=True)
    path = explore.write_page([runs / "study", crawl, chem], tmp_path / "study.html", frames=30, modes=True)
    page, problems = open_page(browser, path.as_uri())
    assert page.eval_on_selector_all("#curves-legend .legend-run", "(e) => e.length") == 4
    assert page.eval_on_selector_all("#summary tbody tr", "(e) => e.length") == 4
    assert not page.is_hidden("#modes-section")
    assert page.eval_on_selector_all("#modes tbody tr", "(e) => e.length") == 4
    assert "keys differ between the runs" in page.text_content("#config-note")
    # every run here records its genealogy: the first run's is drawn
    assert "traced through the parent ids" in page.text_content("#genealogy-note")
    assert not page.is_hidden("#genealogy")
    before = page.evaluate(PIXELS, "curves")
    page.click("#curves-legend .legend-run >> nth=0")  # hide a run
    assert page.evaluate("animatExplore.curves.runs") == 3 and page.evaluate(PIXELS, "curves") != before
    page.evaluate("animatExplore.selectRun(2)")  # the crawl: a floor
    assert page.evaluate(INKED, "swim") > 500 and "floor" in page.text_content("#run-world")
    page.evaluate("animatExplore.selectRun(3)")  # chemotaxis: the source, and the chemical sensed
    assert "chemical" in page.eval_on_selector_all("#color-by option", "(os) => os.map((o) => o.value)")
    page.select_option("#color-by", "chemical")
    page.evaluate("animatExplore.setFrame(10)")
    assert page.evaluate(INKED, "swim") > 500
    assert not problems and not page.evaluate("animatExplore.errors")
    page.close()


def test_a_long_study_loads(browser, runs, tmp_path):
    study = long_study(runs, tmp_path, runs_count=3, generations=1000)
    path = explore.write_page([study], tmp_path / "long.html")
    page, problems = open_page(browser, path.as_uri())
    curves = page.evaluate("animatExplore.curves")
    assert curves["total"] == 3000 and curves["points"] <= 1500
    assert "Downsampled" in page.text_content("#curves-note")
    assert page.evaluate(INKED, "curves") > 2000
    assert not problems
    page.close()


def test_the_live_page_redraws_as_the_history_grows(browser, runs, tmp_path):
    run = tmp_path / "growing"
    shutil.copytree(runs / "study" / "run_1", run)
    server = explore.make_server([run], port=0, live=True, poll=0.2, frames=20)
    assert server.server_address[0] == "127.0.0.1"
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        page, problems = open_page(browser, server.url)
        rows = (run / "history.csv").read_text().splitlines()
        total = len(rows) - 1
        assert page.evaluate("animatExplore.data.runs[0].history.total") == total
        last = rows[-1].split(",")
        with open(run / "history.csv", "a") as f:
            for k in (1, 2, 3):
                row = list(last)
                row[0], row[1] = str(int(last[0]) + k), repr(float(last[1]) + k)
                f.write(",".join(row) + "\n")
            f.write("99,1.0,")  # a row being written: not read
        page.wait_for_function(f"animatExplore.data.runs[0].history.total === {total + 3}")
        assert page.evaluate("animatExplore.live.updates") >= 1
        assert page.text_content("#summary tbody tr td:nth-child(3)") == str(total + 3)
        newest = sorted((run / "best").glob("gen_*.json"))[-1]
        entry = {**json.loads(newest.read_text()), "generation": int(last[0]) + 3}
        (run / "best" / f"gen_{int(last[0]) + 3:06d}.json").write_text(json.dumps(entry))  # a new best
        page.wait_for_function("animatExplore.live.note.includes('reload to replay it')")
        assert page.eval_on_selector_all("#lineage tbody tr", "(rs) => rs.length") == len(
            list((run / "best").iterdir())
        )
        reloaded = urllib.request.urlopen(server.url).read().decode()  # a reload is built again
        assert f'"generations":{total + 3},' in reloaded and f'"generation":{int(last[0]) + 3},"n":' in reloaded
        version = json.loads(urllib.request.urlopen(server.url + "live.json").read())["version"]
        again = urllib.request.urlopen(server.url + "live.json?since=" + urllib.parse.quote(version)).read()
        assert json.loads(again) == {"changed": False, "version": version}
        assert not problems
        page.close()
    finally:
        server.shutdown()
        server.server_close()


def test_cli_serves_the_page_on_localhost_until_interrupted(runs):
    import signal

    env = {**os.environ, "MPLBACKEND": "Agg"}
    args = ["explore", runs / "study" / "run_1", "--serve", "--port", "0", "--live", "--frames", "10"]
    proc = subprocess.Popen(
        [sys.executable, "-m", "animat", *map(str, args)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        # A suite started by a non-interactive shell's `cmd &` passes SIGINT on ignored, and the
        # server would never see the Ctrl-C below: restore it, as a terminal gives it.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        url = re.search(r"http://127\.0\.0\.1:\d+/", line)
        assert url, line + (proc.stderr.read() if proc.stderr else "")
        page = urllib.request.urlopen(url.group(0)).read().decode()
        assert '"live":{"poll":2.0' in page and "animat-data" in page
        live = json.loads(urllib.request.urlopen(url.group(0) + "live.json").read())
        rows = len(animat.Run(runs / "study" / "run_1").history)
        assert live["runs"][0]["label"] == "run_1" and live["runs"][0]["history"]["total"] == rows
        proc.send_signal(signal.SIGINT)
        # Readiness, not a clock: the server says it stopped, then the process ends by itself.
        assert proc.stderr is not None
        said = [line for line in iter(proc.stderr.readline, "") if "stopped serving" in line]
        assert said, "the server never said it stopped"
        assert proc.wait() == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


# --- MAP-Elites and NSGA-II runs; studies grouped by environment -------------------------------------------


@pytest.fixture(scope="module")
def searches(tmp_path_factory):
    """A 3-generation MAP-Elites run and a 3-generation NSGA-II run, as their commands write them."""
    root = tmp_path_factory.mktemp("searches")
    tiny = ["--set", "evaluation.steps=300", "--threads", "2", "--quiet", "--generations", "3"]
    r = cli("map-elites", "paper_dn2", "--out", root / "me", "--set", "evolution.population=8", *tiny)
    assert r.returncode == 0, r.stderr
    r = cli("nsga2", "paper_dn2", "--out", root / "ns", "--population", "8", *tiny)
    assert r.returncode == 0, r.stderr
    return root


def test_search_runs_read_with_their_history_snapshots_and_best(searches):
    me, ns = animat.Run(searches / "me"), animat.Run(searches / "ns")
    assert (me.search, ns.search) == ("map_elites", "nsga2")
    assert me.generations == ns.generations == 4
    assert me.history.dtype.names[:3] == ("generation", "evaluations", "qd_score")
    assert "hypervolume" in ns.history.dtype.names and "best_distance" in ns.history.dtype.names
    archive = me.snapshot()
    assert archive.kind == "archive" and archive.generation == 3 and len(archive) == int(me.history["elites"][-1])
    assert archive.descriptors == ["elongation", "protrusions"]
    best = me.best()
    assert best.fitness == pytest.approx(float(archive.columns["objective"].max()))
    assert best.fitness == pytest.approx(float(me.history["best"][-1]))
    front = ns.snapshot()
    assert front.kind == "front" and len(front) == int(ns.history["front_size"][-1])
    assert front.objectives == [("distance", "max"), ("actuation_work_positive", "min")]
    assert ns.best().fitness == pytest.approx(float(ns.history["best_distance"][-1]))
    # the lineage is every change of the best over all the snapshots (it reads only those after a change)
    changes, previous = [], None
    for g, _ in ns.snapshots():
        snap = ns.snapshot(g)
        if snap.genomes[snap.best()] != previous:
            previous = snap.genomes[snap.best()]
            changes.append(previous)
    assert len(ns.snapshots()) == 4 and [e.genome.to_json() for e in ns.best_genomes] == [
        animat.Genome.from_json(text).to_json() for text in changes
    ]
    with pytest.raises(ValueError, match="no snapshot of generation 2; there are 0, 3"):
        me.snapshot(2)


def test_cli_info_and_show_read_search_runs(searches, tmp_path):
    r = cli("info", searches / "me")
    assert r.returncode == 0 and "MAP-Elites run" in r.stdout and "QD-score" in r.stdout, r.stderr
    r = cli("info", searches / "ns")
    assert r.returncode == 0 and "NSGA-II run" in r.stdout and "hypervolume" in r.stdout, r.stderr
    r = cli("show", searches / "me", "--out", tmp_path / "figures", "--frames", 2)
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in (tmp_path / "figures").iterdir()) == [
        "construction.png",
        "development.png",
        "motion_cycle.png",
        "phase_map.png",
    ]
    r = cli("show", searches / "ns", "--only", "fitness_history", "--out", tmp_path / "none")
    assert r.returncode == 1 and "this is a nsga2 run" in r.stderr and not (tmp_path / "none").exists()


def test_the_page_shows_the_archive_and_replays_an_elite(browser, searches, tmp_path):
    run = animat.Run(searches / "me")
    data = explore.build_data([searches / "me"], frames=20, replays=20)
    r = data["runs"][0]
    assert r["kind"] == "map_elites" and r["search"]["total"] == len(run.snapshot())
    assert r["history"]["best"] == pytest.approx(run.history["best"].tolist(), rel=1e-5)
    assert "QD-score" in r["history"]["extra"] and r["summary"]["search"].startswith("MAP-Elites")
    assert len(r["replays"]) == len(run.snapshot()) - 1  # every elite but the best, which is the swim
    path = explore.write_page([searches / "me"], tmp_path / "me.html", frames=20, replays=20)
    page, problems = open_page(browser, path.as_uri())
    search = page.evaluate("animatExplore.search")
    assert search["drawn"] == len(run.snapshot()) and search["kind"] == "map_elites"
    assert page.evaluate(INKED, "search-map") > 2000
    before = page.evaluate(PIXELS, "swim")
    other = next(k for k in range(len(run.snapshot())) if k != run.snapshot().best())
    page.evaluate(f"animatExplore.showIndividual('row:3:{other}', 'the elite of row {other}')")
    assert page.text_content("#swim-note").startswith(f"Replaying the elite of row {other}")
    assert page.evaluate(PIXELS, "swim") != before and not page.is_hidden("#show-best")
    page.click("#show-best")
    assert page.text_content("#swim-note").startswith("Best of generation")
    # a click on the heatmap replays the elite of that cell
    k, x, y = next(p for p in search["points"] if p[0] == other)
    page.click("#search-map", position={"x": x, "y": y})
    assert page.text_content("#swim-note").startswith(f"Replaying the elite of row {other}")
    assert "record holders, not an ancestry" in page.text_content("#lineage-note")
    assert not problems and not page.evaluate("animatExplore.errors")
    page.close()


def test_the_page_shows_the_front_and_a_served_page_replays_any_genome(browser, searches):
    front = animat.Run(searches / "ns").snapshot()
    server = explore.make_server([searches / "ns"], port=0, frames=20, replays=0)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        page, problems = open_page(browser, server.url)
        search = page.evaluate("animatExplore.search")
        assert search["drawn"] == len(front) and search["kind"] == "nsga2"
        assert page.evaluate("Object.keys(animatExplore.data.runs[0].replays).length") == 0
        other = next(k for k in range(len(front)) if k != front.best())
        k, x, y = next(p for p in search["points"] if p[0] == other)
        page.click("#search-map", position={"x": x, "y": y})  # not in the page: fetched from swim.json
        page.wait_for_function(f"animatExplore.data.runs[0].replays['row:3:{other}'] !== undefined")
        assert page.text_content("#swim-note").startswith(f"Replaying the front's genome of row {other}")
        assert page.evaluate(f"animatExplore.data.runs[0].replays['row:3:{other}'].generation") == int(
            front.columns["generation"][other]
        )
        bad = json.loads(urllib.request.urlopen(server.url + "swim.json?run=0&key=row:3:999").read())
        assert "no row 999" in bad["error"]
        bad = json.loads(urllib.request.urlopen(server.url + "swim.json?run=0&key=row:7:0").read())
        assert "no snapshot of generation 7" in bad["error"]
        assert not problems and not page.evaluate("animatExplore.errors")
        page.close()
    finally:
        server.shutdown()
        server.server_close()


def test_a_click_in_the_genealogy_replays_an_ancestor_that_held_the_record(browser, runs, tmp_path):
    path = explore.write_page([runs / "genealogy" / "run"], tmp_path / "g.html", frames=20)
    page, problems = open_page(browser, path.as_uri())
    assert page.eval_on_selector_all("#lineage tbody tr", "(rs) => rs.length") == 4
    page.click("#lineage tbody tr >> nth=1")  # the best of generation 1, id 6
    assert page.text_content("#swim-note").startswith("Replaying the best of generation 1")
    page.click("#show-best")
    assert page.text_content("#swim-note").startswith("Best of generation")
    layout = {i: (x, y) for i, x, y in page.evaluate("animatExplore.genealogy.xy")}
    x, y = layout[9]  # a record holder: the best of generation 2
    page.click("#genealogy", position={"x": x, "y": y})
    assert page.text_content("#swim-note").startswith("Replaying ancestor 9 (the best of generation 2)")
    x, y = layout[12]  # an ancestor that never held the record: no genome to replay
    page.click("#genealogy", position={"x": x, "y": y})
    assert "keeps no genome" in page.text_content("#genealogy-readout")
    assert page.text_content("#swim-note").startswith("Replaying ancestor 9")
    assert not problems and not page.evaluate("animatExplore.errors")
    page.close()


def grouped_study(runs: Path, tmp_path: Path) -> Path:
    """Two environments of three runs each (copies of the tiny runs, the best curve scaled per run)."""
    study = tmp_path / "grouped"
    for env, factor in (("low", 1.0), ("high", 10.0)):
        for i in range(3):
            run = study / env / f"run_{i}"
            shutil.copytree(runs / "study" / "run_1", run)
            lines = (run / "history.csv").read_text().splitlines()
            col = lines[0].split(",").index("best")
            rows = [line.split(",") for line in lines[1:]]
            for g, row in enumerate(rows):
                row[col] = repr(factor * (i + 1) * (g + 1))
            (run / "history.csv").write_text("\n".join([lines[0]] + [",".join(r) for r in rows]) + "\n")
    return study


def test_groups_have_the_median_and_quartiles_of_their_runs(runs, tmp_path):
    study = grouped_study(runs, tmp_path)
    data = explore.build_data([study], frames=10)
    assert data["group_by"] == "folders"
    groups = {g["name"]: g for g in data["groups"]}
    assert set(groups) == {"low", "high"} and groups["low"]["runs"] == [3, 4, 5]  # natural order: high first
    generations = len(animat.Run(runs / "study" / "run_1").history)
    low = groups["low"]
    assert low["generation"] == list(range(generations)) and low["n"] == [3] * generations
    assert low["median"] == pytest.approx([2.0 * (g + 1) for g in range(generations)])
    assert low["q1"] == pytest.approx([1.5 * (g + 1) for g in range(generations)])
    assert low["q3"] == pytest.approx([2.5 * (g + 1) for g in range(generations)])
    assert groups["high"]["median"] == pytest.approx([20.0 * (g + 1) for g in range(generations)])
    # runs given one by one: grouped by config, the seed left out
    loose = explore.build_data([runs / "study" / "run_1", runs / "study" / "run_2"], frames=10)
    assert loose["group_by"] == "config" and [g["runs"] for g in loose["groups"]] == [[0, 1]]
    assert loose["groups"][0]["name"] == "study"


def test_a_study_page_draws_groups_toggles_them_uses_a_log_scale_and_exports(browser, runs, tmp_path):
    study = grouped_study(runs, tmp_path)
    path = explore.write_page([study], tmp_path / "groups.html", frames=10)
    page, problems = open_page(browser, path.as_uri())
    curves = page.evaluate("animatExplore.curves")
    assert curves["mode"] == "groups" and curves["groups"] == 2
    assert page.eval_on_selector_all("#group-legend .legend-group", "(e) => e.length") == 2
    assert page.is_hidden("#curves-legend")
    before = page.evaluate(PIXELS, "curves")
    page.click("#group-legend .legend-group >> nth=0")
    assert page.evaluate("animatExplore.curves.groups") == 1 and page.evaluate(PIXELS, "curves") != before
    page.click("#group-legend .legend-group >> nth=0")
    linear = page.evaluate(PIXELS, "curves")
    page.check("#log-scale")
    assert page.evaluate("animatExplore.curves.log") and page.evaluate(PIXELS, "curves") != linear
    page.uncheck("#log-scale")
    with page.expect_download() as png:
        page.click("#export-png")
    assert png.value.suggested_filename == "fitness_groups.png"
    assert Path(png.value.path()).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with page.expect_download() as svg:
        page.click("#export-svg")
    text = Path(svg.value.path()).read_text()
    assert text.startswith("<svg") and text.count("<path") > 10 and ">generation</text>" in text
    with page.expect_download() as table:
        page.click("#export-csv")
    rows = Path(table.value.path()).read_text().splitlines()
    data = page.evaluate("animatExplore.data.groups")
    assert rows[0] == "group,generation,runs,median_best,q1_best,q3_best"
    assert len(rows) == 1 + sum(len(g["generation"]) for g in data)
    assert rows[1].split(",")[:4] == [data[0]["name"], str(data[0]["generation"][0]), "3", repr(data[0]["median"][0])]
    page.select_option("#curve-mode", "runs")
    assert page.evaluate("animatExplore.curves.mode") == "runs" and not page.is_hidden("#curves-legend")
    assert page.evaluate("animatExplore.curvesCsv()").splitlines()[0].startswith("run,group,generation,best")
    assert not problems and not page.evaluate("animatExplore.errors")
    page.close()


def test_the_page_of_the_forty_packed_runs_stays_small_and_opens_on_the_groups(browser, tmp_path):
    study = ROOT / "data" / "replication_regime"
    path = explore.write_page([study], tmp_path / "study.html")
    assert path.stat().st_size < 2_500_000, path.stat().st_size
    page, problems = open_page(browser, path.as_uri())
    assert page.evaluate("animatExplore.data.runs.length") == 40
    assert page.evaluate("animatExplore.data.runs.every((r) => r.summary.generations > 500)")
    assert page.evaluate("animatExplore.curves.mode") == "groups" and page.evaluate("animatExplore.curves.groups") == 4
    assert not problems and not page.evaluate("animatExplore.errors")
    page.close()
