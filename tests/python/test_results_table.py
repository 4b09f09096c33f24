"""studies/results_table.py: the CSV every study writes its results as."""

import csv

from results_table import write_rows


def test_floats_keep_six_significant_digits_and_other_values_pass_through(tmp_path):
    out = tmp_path / "nested" / "table.csv"
    write_rows(out, [{"env": "dn0.5", "run": 3, "share": 2.0 / 3.0, "tiny": 1.0e-9, "flag": True}])
    assert out.read_text() == "env,run,share,tiny,flag\ndn0.5,3,0.666667,1e-09,True\n"


def test_columns_default_to_first_seen_order_and_skip_private_keys(tmp_path):
    out = tmp_path / "table.csv"
    write_rows(out, [{"a": 1, "_controller": object()}, {"a": 2, "b": 0.5}])
    rows = list(csv.DictReader(open(out)))
    assert list(rows[0]) == ["a", "b"]
    assert [(r["a"], r["b"]) for r in rows] == [("1", ""), ("2", "0.5")]


def test_explicit_columns_fix_the_order(tmp_path):
    out = tmp_path / "table.csv"
    write_rows(out, [{"b": 1.5, "a": "x"}], ["a", "b"])
    assert out.read_text() == "a,b\nx,1.5\n"
