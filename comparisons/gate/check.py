"""The CI verdict on a stored run: every bounded metric inside its bound, and what moved since a baseline.

:func:`check_table` holds each row to the most specific bound of the tolerances
(:mod:`comparisons.tolerances`); a row no bound matches is unchecked (counted, never a pass in
disguise: the count is printed). :func:`compare_with_baseline` lists every metric that moved by
more than a relative threshold since another run, every case that appeared or disappeared, and
timing changes apart (non-blocking: these machines are noisy).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from simparity.comparisons.gate.cross_check import CROSS_CHECK_FACTOR, SOLVE_RATE_FRACTION, cross_check
from simparity.comparisons.gate.violation import Violation, row_label
from simparity.comparisons.engines.registry import ENGINE_NAMES
from simparity.comparisons.gate.tolerances import Bound, bound_for
from simparity.core.model.metric_catalogue import is_timing
from simparity.core.model.results import ALARM_FLAGS, DIMENSIONLESS, NOT_AVAILABLE, OK, ROUNDING_FLOOR

CASE_KEYS = ("scene", "engine", "integrator", "dt")
ROW_KEYS = CASE_KEYS + ("metric",)

BASELINE_RELATIVE = 1e-6
"""Default relative change of a metric since the baseline that counts as a move: far above the
1e-15 a recompiled BLAS may shift a result by, far below any tolerance, so a change in numerics
shows even when it stays inside its bound."""


@dataclass
class CheckResult:
    """The verdict on one run.

    ``cases`` maps each case key (scene, engine, integrator, dt) to its violations (empty: passed).
    """

    checked: int = 0
    unchecked: int = 0
    violations: list[Violation] = field(default_factory=list)
    cases: dict[tuple, list[Violation]] = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return not self.violations


def _judge(bound: Bound, row) -> tuple[str, str] | None:
    """(what was found, the bound) when ``row`` breaks ``bound``, else None."""
    status, value, dt, flag = row["status"], float(row["value"]), float(row["dt"]), row.get("flag", "")
    flag = flag if isinstance(flag, str) else ""  # a table without flags (read by pandas alone: NaN)
    if flag in ALARM_FLAGS and flag not in bound.na_when:
        return f"status {status}, flag {flag}; {row['detail']}"[:300], f"no {flag} flag"
    if status == NOT_AVAILABLE and flag and flag in bound.na_when:
        return None
    if status not in bound.statuses:
        allowed = " or ".join(bound.statuses)
        why = f"; {row['detail']}" if row["detail"] and status != OK else ""
        return f"status {status}{why}"[:300], f"status {allowed}"
    if status != OK or not bound.bounds_a_number:
        return None
    low, high = bound.limits(dt)
    if flag == ROUNDING_FLOOR and low <= value:
        return None  # exact up to rounding: what any upper bound asks, however tight it was written
    if not (low <= value <= high):
        unit = "" if row["unit"] == DIMENSIONLESS else f" {row['unit']}"
        return f"{value:.4g}{unit}", bound.describe(dt)
    return None


def check_table(table: pd.DataFrame, bounds: list[Bound], cross_checked: bool = True) -> CheckResult:
    """Hold every row of a results table to its most specific bound, and (``cross_checked``) every user engine's
    row to the built-in schemes of its kind (:mod:`comparisons.cross_check`)."""
    result = CheckResult()
    for row in table.to_dict("records"):
        key = _case_key(row["scene"], row["engine"], row["integrator"], float(row["dt"]))
        result.cases.setdefault(key, [])
        bound = _row_bound(bounds, row)
        if bound is None:
            result.unchecked += 1
            continue
        result.checked += 1
        broken = _judge(bound, row)
        if broken:
            found, text = broken
            violation = Violation(row["scene"], row["engine"], row["integrator"], float(row["dt"]), row["metric"],
                                  found, text, bound.reason)
            result.violations.append(violation)
            result.cases[key].append(violation)
    for violation in cross_check(table, ENGINE_NAMES) if cross_checked else ():
        result.violations.append(violation)
        result.cases.setdefault(_case_key(violation.scene, violation.engine, violation.integrator, violation.dt),
                                []).append(violation)
    return result


def _case_key(scene: str, engine: str, integrator: str, dt: float) -> tuple:
    """A case's key in :attr:`CheckResult.cases` (NaN dt as "nan", so that order rows share one key)."""
    return (scene, engine, integrator, "nan" if math.isnan(dt) else dt)


def _row_bound(bounds: list[Bound], row: dict) -> Bound | None:
    """The bound that decides ``row`` (a results table's record; a table without a scheme column: "")."""
    scheme = row.get("scheme", "")
    return bound_for(bounds, row["scene"], row["engine"], row["integrator"], row["metric"], float(row["dt"]),
                     scheme if isinstance(scheme, str) else "")


@dataclass(frozen=True)
class Applied:
    """A bound and the rows of one scene it decides: what the gate holds an engine to there."""

    scene: str
    bound: Bound
    metrics: tuple[str, ...]
    rows: int


def explain(table: pd.DataFrame, bounds: list[Bound], engine: str) -> list[Applied]:
    """Per scene, every bound that decides one of ``engine``'s rows (the most specific that matches), with the
    metrics it decides and how many rows, in the scene's order; rows no bound matches are left out (the check
    counts them as without a bound)."""
    decided: dict[tuple[str, str], tuple[Bound, dict[str, None], int]] = {}
    for row in table[table["engine"] == engine].to_dict("records"):
        bound = _row_bound(bounds, row)
        if bound is None:
            continue
        key = (row["scene"], bound.where)
        held, metrics, count = decided.get(key, (bound, {}, 0))
        metrics[row["metric"]] = None
        decided[key] = (held, metrics, count + 1)
    return [Applied(scene, bound, tuple(metrics), count) for (scene, _), (bound, metrics, count) in decided.items()]


def explain_lines(applied: list[Applied], builtin: bool) -> list[str]:
    """One line per scene and bound: ``scene: file bound[i] holds N rows (metrics...) to the bound (reason)``, and
    for an engine that is not ``builtin`` a last line on the cross-checks it is also held to."""
    lines = []
    for item in applied:
        shown = ", ".join(item.metrics[:4]) + (f", ... ({len(item.metrics)} metrics)" if len(item.metrics) > 4 else "")
        held = item.bound.describe(math.nan) if item.bound.bounds_a_number else "status " + " or ".join(
            item.bound.statuses)
        if item.bound.bounds_a_number and item.bound.dt_power is not None:
            held += f" x dt^{item.bound.dt_power:g}"
        where = item.bound.where.rsplit("/", 1)[-1]
        lines.append(f"{item.scene}: {where} holds {item.rows} rows ({shown}) to {held} ({item.bound.reason})")
    if not builtin:
        lines.append("and every row to the built-in schemes of its kind in the same run (cross-checks: errors within "
                     f"{CROSS_CHECK_FACTOR:g} x the largest built-in's, IK solve rates at least "
                     f"{SOLVE_RATE_FRACTION:.0%} of the best built-in's, null-space terms that help; docs/check.md)")
    return lines


@dataclass
class BaselineDiff:
    """What changed since a baseline run: moves block, timing changes do not."""

    moved: list[str] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    new: list[str] = field(default_factory=list)
    timing: list[str] = field(default_factory=list)

    @property
    def blocking(self) -> bool:
        return bool(self.moved or self.missing)


_INDEX = ("scene", "engine", "integrator", "dt_key", "metric")


def _keyed(table: pd.DataFrame) -> pd.DataFrame:
    """The table indexed by row (dt as its exact repr, so 0.1 and 0.1000000001 stay apart)."""
    keyed = table.copy()
    keyed["dt_key"] = keyed["dt"].map(lambda d: "nan" if pd.isna(d) else repr(float(d)))
    keyed["integrator"] = keyed["integrator"].fillna("")
    keyed = keyed.drop_duplicates(list(_INDEX), keep="last")
    return keyed.set_index(list(_INDEX))


def _key_label(key: tuple) -> str:
    scene, engine, integrator, dt_key, metric = key
    return row_label(scene, engine, integrator, float(dt_key), metric)


def compare_with_baseline(table: pd.DataFrame, baseline: pd.DataFrame,
                          relative: float = BASELINE_RELATIVE) -> BaselineDiff:
    """Rows whose status changed or whose value moved by more than ``relative`` (of the baseline's
    magnitude) since ``baseline``; rows only one run has; timing changes apart."""
    now, before = _keyed(table), _keyed(baseline)
    diff = BaselineDiff(missing=[_key_label(k) for k in before.index.difference(now.index)],
                        new=[_key_label(k) for k in now.index.difference(before.index)])
    common = now.index.intersection(before.index)
    a, b = now.loc[common], before.loc[common]
    x, y = a["value"].to_numpy(dtype=float), b["value"].to_numpy(dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        change = np.where(y != 0, np.abs(x - y) / np.abs(y), np.where(x == 0, 0.0, np.inf))
    status_now, status_before = a["status"].to_numpy(), b["status"].to_numpy()
    retagged = status_now != status_before
    moved = ~retagged & ~(np.isnan(x) & np.isnan(y)) & ~(change <= relative)
    for i in np.flatnonzero(retagged | moved):
        key = common[i]
        text = (f"status {status_before[i]} -> {status_now[i]}" if retagged[i]
                else f"{y[i]:.6g} -> {x[i]:.6g} ({change[i]:.2g} relative)")
        (diff.timing if is_timing(key[-1]) else diff.moved).append(f"{_key_label(key)}: {text}")
    return diff
