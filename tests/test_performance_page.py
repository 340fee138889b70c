"""The performance page shows the numbers of its results file, and the file says where each comes from.

``docs/performance.md`` holds every measured figure between ``<!-- results: NAME -->`` markers,
written by ``scripts/benchmarks/performance_page.py`` from ``docs/performance/results.json``.
"""

import copy
import importlib.util
import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCH = ROOT / "scripts" / "benchmarks"
PAGE = ROOT / "docs" / "performance.md"


@pytest.fixture(scope="module")
def page_module():
    sys.path.insert(0, str(BENCH))
    try:
        spec = importlib.util.spec_from_file_location("performance_page", BENCH / "performance_page.py")
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        yield mod
    finally:
        sys.path.remove(str(BENCH))


@pytest.fixture(scope="module")
def data():
    return json.loads((ROOT / "docs" / "performance" / "results.json").read_text())


def test_the_page_shows_the_numbers_of_the_results_file(page_module, data):
    text = PAGE.read_text()
    assert page_module.render(text, data) == text, (
        "docs/performance.md differs from docs/performance/results.json: "
        "run python scripts/benchmarks/performance_page.py")


def test_a_changed_record_changes_the_page(page_module, data):
    # the comparison above can fail: any figure of the file reaches the page
    text = PAGE.read_text()
    for table in sorted({r["table"] for r in data["records"]}):
        changed = copy.deepcopy(data)
        rec = next(r for r in changed["records"] if r["table"] == table)
        key = next(k for k in ("rate_cpu", "bytes_per_particle", "cpu_seconds", "first_seconds", "wall_seconds",
                               "microseconds", "instantaneous", "ratio", "cells_rate_cpu") if k in rec)
        rec[key] = 123.456
        assert page_module.render(text, changed) != text, table


def test_every_record_says_where_it_comes_from(data):
    for r in data["records"]:
        where = f"{r.get('table')} {r.get('id')}"
        for key in ("table", "id", "machine", "date", "commit", "command"):
            assert r.get(key), f"{where}: no {key}"
        assert r["machine"] in data["machines"], where
        assert re.fullmatch(r"\d{4}-\d{2}-\d{2}", r["date"]), where
        assert re.fullmatch(r"[0-9a-f]{7,40}(\+changes)?", r["commit"]), where
        assert "python scripts/" in r["command"], where
    ids = [(r["table"], r["id"]) for r in data["records"]]
    assert len(ids) == len(set(ids)), "a case measured twice: the file keeps the latest record per case"


def test_every_table_of_the_file_is_on_the_page(page_module, data):
    text = PAGE.read_text()
    shown = set(re.findall(r"<!-- results: ([\w-]+) -->", text + (ROOT / "README.md").read_text()))
    assert shown == set(page_module.BLOCKS), set(page_module.BLOCKS) ^ shown
    for table in {r["table"] for r in data["records"]}:
        assert any(r["table"] == table for r in data["records"])
        assert f"by_table(data, \"{table}\")" in (BENCH / "performance_page.py").read_text(), table


def test_the_page_has_no_dated_sections():
    heads = [line for line in PAGE.read_text().splitlines() if line.startswith("#")]
    dated = [h for h in heads if re.search(r"\d{4}-\d{2}-\d{2}|commit|branch", h)]
    assert not dated, dated


def test_the_results_file_round_trips(tmp_path, data):
    # results.record replaces the record of the same case and stamps machine, date, commit, command
    sys.path.insert(0, str(BENCH))
    try:
        spec = importlib.util.spec_from_file_location("results", BENCH / "results.py")
        results = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(results)
    finally:
        sys.path.remove(str(BENCH))
    path = tmp_path / "results.json"
    path.write_text(json.dumps(data))
    old = next(r for r in data["records"] if r["table"] == "engine")
    new = {k: old[k] for k in ("table", "id", "n", "dim", "packing", "rule", "neighbours", "scene")}
    new["rate_cpu"] = 0.5
    results.record([new], "python scripts/benchmarks/run.py quick", path=path, commit="abcdef1")
    after = json.loads(path.read_text())
    same = [r for r in after["records"] if (r["table"], r["id"]) == (old["table"], old["id"])]
    assert len(same) == 1 and same[0]["rate_cpu"] == 0.5 and same[0]["commit"] == "abcdef1"
    assert same[0]["machine"] in after["machines"] and same[0]["command"].endswith("quick")
    assert len(after["records"]) == len(data["records"])
