"""Stored runs: written incrementally, read back exactly, bad folders rejected clearly."""

import json
import math

import pytest

from simparity.comparisons.engines import make_engine
from simparity.comparisons.store import RunWriter
from simparity.core.errors import ResultsError
from simparity.core.results import ResultRow
from simparity.reports.store import read_run
from tests.helpers import builtin


def test_rows_round_trip_with_full_precision(tmp_path):
    """Appended rows read back with the same values (17 digits), NaN kept as NaN, metadata present."""
    core = make_engine("core")
    writer = RunWriter(tmp_path, [core], "simparity run", [builtin("lecture-projectile")])
    value = 0.1 + 0.2
    writer.append([ResultRow("s", "core", "rk4", 1 / 30, "m", value, "m", "analytic:exact", "ok", "a, b")])
    writer.append([ResultRow("s", "core", "", math.nan, "m", math.nan, "m", "analytic:exact", "n/a", "why")])
    table, info = read_run(tmp_path)
    assert table["value"].iloc[0] == value and table["dt"].iloc[0] == 1 / 30
    assert math.isnan(table["value"].iloc[1]) and table["detail"].iloc[0] == "a, b"
    assert info["engine_versions"] == {"core": core.version()} and "lecture-projectile" in info["scenes"]
    assert info["theoretical_orders"]["core"]["rk4"] == 4 and "taylor2" not in info["theoretical_orders"]["core"]
    assert info["scenes"]["lecture-projectile"]["bodies"] == 1
    variants = info["integrator_variants"]["core"]
    assert variants["rk4+matrix"] == ["rk4", "matrix"] and variants["rk4"] == ["rk4", "quaternion"]
    assert "engine_euler" not in variants and "taylor2" not in variants   # one orientation update; a particle rule
    assert {"platform", "cpu_count", "python"} <= set(info["machine"]) and info["git_commit"]


def test_bad_run_folders_raise_results_error(tmp_path):
    """A folder without results, or with a future schema, is a ResultsError saying what is wrong."""
    with pytest.raises(ResultsError, match="missing"):
        read_run(tmp_path)
    RunWriter(tmp_path, [], "x", [])
    info = json.loads((tmp_path / "run.json").read_text())
    info["schema_version"] = 99
    (tmp_path / "run.json").write_text(json.dumps(info))
    with pytest.raises(ResultsError, match="schema_version 99"):
        read_run(tmp_path)
