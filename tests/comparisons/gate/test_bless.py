"""``check --bless``: a tolerances file from a run that passes that run, fails a degraded copy, and never blesses a
failed row or a timing."""

import dataclasses
import math

import pandas as pd
import pytest

from simparity.comparisons.gate.bless import BLESS_ORDER_BAND, BLESS_RELATIVE_MARGIN, BLESS_SPREAD_FACTOR, bless
from simparity.comparisons.gate.check import check_table
from simparity.comparisons.gate.tolerances import load_tolerances
from simparity.core.model.errors import ToleranceError
from simparity.core.model.results import COLUMNS, ResultRow
from simparity.core.model.run_info import RunInfo

INFO = RunInfo(git_commit="abc123", created_utc="2026-11-27T00:00:00+00:00")


def _row(metric, value, status="ok", dt=0.01, integrator="rk4", detail=""):
    return ResultRow("my-scene", "mine", integrator, dt, metric, value, "m", "analytic:exact", status, detail)


ROWS = [_row("position_error_max", 2e-6), _row("position_error_max", 3.2e-5, dt=0.02),
        _row("order_position", 4.02, dt=math.nan), _row("time_per_step", 1e-5),
        _row("position_error_max", math.nan, "n/a", integrator="taylor2", detail="saturated"),
        *[_row(m, math.nan, "diverged", integrator="explicit_euler", detail="blew up at t = 2 s")
          for m in ("position_error_max", "energy_drift_max")]]


def _table(rows):
    return pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS))


def _blessed(tmp_path, rows, spread=None):
    text, count = bless(_table(rows), INFO, tmp_path / "run", spread)
    path = tmp_path / "blessed.toml"
    path.write_text(text, encoding="utf-8")
    return load_tolerances(path), text, count


def test_a_blessed_run_checks_clean_against_itself_and_every_row_is_held_to_a_value(tmp_path):
    bounds, text, count = _blessed(tmp_path, ROWS)
    assert count == 5  # two errors, the order, the n/a row, the diverged case; never the timing
    result = check_table(_table(ROWS), bounds)
    assert result.passed and result.unbounded_share == 0.0, [v.line() for v in result.violations]
    assert "time_per_step" not in text and 'extends = "default"' in text
    assert "blessed from run" in text and "abc123" in text and "expected — review" in text


@pytest.mark.parametrize("metric, factor", [("position_error_max", 1 + 2 * BLESS_RELATIVE_MARGIN),
                                            ("order_position", (4.02 - 2 * BLESS_ORDER_BAND) / 4.02)])
def test_a_degraded_copy_fails(tmp_path, metric, factor):
    bounds, _, _ = _blessed(tmp_path, ROWS)
    worse = [dataclasses.replace(r, value=r.value * factor) if r.metric == metric and r.status == "ok" else r
             for r in ROWS]
    result = check_table(_table(worse), bounds)
    assert not result.passed and {v.metric for v in result.violations} == {metric}


def test_a_diverged_case_that_stops_diverging_fails_and_an_error_that_shrinks_passes(tmp_path):
    bounds, _, _ = _blessed(tmp_path, ROWS)
    healed = [dataclasses.replace(r, status="ok", value=1e-3) if r.status == "diverged" else r for r in ROWS]
    assert not check_table(_table(healed), bounds).passed
    better = [dataclasses.replace(r, value=r.value / 10) if r.metric == "position_error_max" else r for r in ROWS]
    assert check_table(_table(better), bounds).passed


def test_a_failed_row_refuses_the_whole_file(tmp_path):
    with pytest.raises(ToleranceError) as caught:
        bless(_table(ROWS + [_row("velocity_error_max", math.nan, "failed", detail="raised")]), INFO, tmp_path)
    message = str(caught.value)
    assert "failed" in message and "nothing was blessed" in message and "\n" not in message


def test_a_second_run_widens_the_margin_to_its_spread(tmp_path):
    """A chaotic row that moved by 50 % between two runs is blessed with 3 x that spread, not 10 %."""
    other = [dataclasses.replace(r, value=r.value * 1.5) if r.metric == "position_error_max" and r.status == "ok"
             else r for r in ROWS]
    bounds, _, _ = _blessed(tmp_path, ROWS, spread=_table(other))
    assert check_table(_table(other), bounds).passed
    widest = max(b.max for b in bounds if b.max is not None and b.scene == "my-scene")
    assert widest == pytest.approx(3.2e-5 * (1 + 0.5 * BLESS_SPREAD_FACTOR))


def test_a_row_that_breaks_a_shipped_bound_refuses_the_file(tmp_path):
    """An RK4 (declared scheme rk4) whose order fell to 2 breaks the shipped order bound: blessing it would let the
    blessed bound win and pass the bug, so nothing is blessed."""
    broken = [dataclasses.replace(r, value=2.0, scheme="rk4") if r.metric == "order_position" else r for r in ROWS]
    with pytest.raises(ToleranceError) as caught:
        bless(_table(broken), INFO, tmp_path)
    assert "break the bounds the blessed file would extend" in str(caught.value) and "order_position" in str(caught.value)


@pytest.mark.parametrize("bad", ["spread-failed", "non-finite"])
def test_a_failed_spread_run_or_a_non_finite_ok_value_refuses_the_file(tmp_path, bad):
    if bad == "spread-failed":
        spread = _table([dataclasses.replace(r, status="failed") if r.metric == "time_per_step" else r for r in ROWS])
        call = lambda: bless(_table(ROWS), INFO, tmp_path, spread)  # noqa: E731
    else:
        rows = [dataclasses.replace(r, value=math.inf) if r.dt == 0.02 else r for r in ROWS]
        call = lambda: bless(_table(rows), INFO, tmp_path)  # noqa: E731
    with pytest.raises(ToleranceError, match="nothing was blessed"):
        call()
