"""Run history in SQLite: runs side by side, the latest for a baseline, never breaking on a bad database."""

import dataclasses
import math
import multiprocessing

import pandas as pd
import pytest

from simparity.core.model.errors import HistoryError
from simparity.comparisons.gate.history import (
    HISTORY_ENV,
    history_path,
    latest_before,
    metric_history,
    record_run,
    run_table,
    runs,
)
from simparity.core.model.run_info import RunInfo
from simparity.core.model.results import COLUMNS, SWEEP_COLUMN, ResultRow, sweep_column

INFO = RunInfo(created_utc="2026-11-22T10:00:00+00:00", git_commit="abc", command="simparity run",
               machine={"cpu_count": 2}, engine_versions={"core": "1"})


def _table(value):
    rows = [ResultRow("s", "core", "rk4", 0.01, "position_error_max", value, "m", "analytic:exact", "ok", "d"),
            ResultRow("s", "core", "", math.nan, "order_position", math.nan, "1", "analytic:exact", "n/a", "why")]
    return pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS))


def test_two_runs_side_by_side_and_the_latest_for_a_baseline(tmp_path):
    db = tmp_path / "h.sqlite"
    first = record_run(db, tmp_path / "r1", INFO, _table(1e-6))
    second = record_run(db, tmp_path / "r2", dataclasses.replace(INFO, created_utc="2026-11-22T11:00:00+00:00"), _table(2e-6))
    shown = metric_history(db, scene="s", metric="position_error_max")
    assert list(shown.columns[-2:]) == [f"#{first} 2026-11-22T10:00:00+00:00", f"#{second} 2026-11-22T11:00:00+00:00"]
    assert list(shown.iloc[0, -2:]) == ["1e-06", "2e-06"]
    assert latest_before(db, tmp_path / "r2") == (first, str(tmp_path / "r1"))
    table = run_table(db, first)
    assert table["value"].iloc[0] == 1e-6 and math.isnan(table["dt"].iloc[1]) and table["status"].iloc[1] == "n/a"


def test_path_from_option_environment_or_default(monkeypatch, tmp_path):
    monkeypatch.setenv(HISTORY_ENV, str(tmp_path / "env.sqlite"))
    assert history_path() == tmp_path / "env.sqlite"
    assert history_path(str(tmp_path / "opt.sqlite")) == tmp_path / "opt.sqlite"
    monkeypatch.delenv(HISTORY_ENV)
    assert history_path().name == "history.sqlite"


def test_missing_or_corrupt_database_is_a_history_error(tmp_path):
    with pytest.raises(HistoryError, match="no run history"):
        runs(tmp_path / "none.sqlite")
    corrupt = tmp_path / "corrupt.sqlite"
    corrupt.write_bytes(b"this is not a database" * 100)
    with pytest.raises(HistoryError, match="unusable"):
        record_run(corrupt, tmp_path / "r", INFO, _table(1.0))


def _writer(db, name, count):
    for i in range(count):
        record_run(db, f"{name}{i}", INFO, _table(float(i)))


@pytest.mark.slow
def test_two_processes_writing_at_once_lose_nothing(tmp_path):
    db = tmp_path / "h.sqlite"
    context = multiprocessing.get_context("spawn")
    workers = [context.Process(target=_writer, args=(db, name, 20)) for name in ("a", "b")]
    for w in workers:
        w.start()
    for w in workers:
        w.join(60)
    assert all(w.exitcode == 0 for w in workers)
    recorded = runs(db)
    assert len(recorded) == 40 and recorded["id"].is_unique
    assert all(len(run_table(db, int(i))) == 2 for i in recorded["id"])


def test_a_run_with_sweep_columns_is_recorded_in_the_fixed_columns(tmp_path):
    """The history keeps the fixed columns of any run (a variant's values are in its name and its run.json)."""
    swept = _table(1e-6).assign(**{SWEEP_COLUMN: "drop", sweep_column("body[ball].mass"): 2.0})
    run = record_run(tmp_path / "h.sqlite", tmp_path / "r", INFO, swept)
    table = run_table(tmp_path / "h.sqlite", run)
    assert tuple(table.columns) == COLUMNS and table["value"].iloc[0] == 1e-6
