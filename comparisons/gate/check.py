"""The CI verdict on a stored run: every bounded metric inside its bound, and what moved since a baseline.

:func:`check_table` holds each row to the bound that decides it (:mod:`comparisons.gate.tolerances`); a row
no bound matches is unchecked (counted, never a pass in disguise: the count is printed). A status-only bound
that allows ``ok`` (the shipped catch-all) checks that a case ran, not what it found: a series (scene x
engine x integrator or solver) none of whose rows is held to a value or a verdict is *without a value
bound*, and a run where more than :data:`UNBOUNDED_SHARE_MAX` of the series measured are fails the gate
unless the user allows it. :func:`held_to` narrows the verdict to the engines the user holds (the others'
violations become findings, never blocking) and fails it for each required engine that measured nothing; a bound of
the user's file that matched no row is said (:func:`unmatched_bounds`). :func:`compare_with_baseline` lists every metric that moved by more than a
relative threshold since another run among the scenes x engines both runs ran, every row that appeared or
disappeared there, and timing changes apart, one summary per scene (non-blocking: these machines are noisy).
"""

from __future__ import annotations

import fnmatch
import math
from collections import Counter
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from simparity.comparisons.gate.cross_check import (
    CROSS_CHECK_FACTOR, JOINT_AGREEMENT_FACTOR, SOLVE_RATE_FRACTION, cross_check, held_series,
)
from simparity.comparisons.gate.violation import Violation, row_label
from simparity.comparisons.engines.registry import ENGINE_NAMES
from simparity.comparisons.gate.bound_index import unmatched_patterns
from simparity.comparisons.gate.bound_names import patterns_of, refuse_impossible
from simparity.comparisons.gate.tolerances import Bound, BoundIndex, EngineNames
from simparity.core.model.errors import SimparityError, one_line
from simparity.core.model.metric_catalogue import is_cost, is_timing
from simparity.core.model.results import (ALARM_FLAGS, DIMENSIONLESS, FAILED, NOT_AVAILABLE, OK, ROUNDING_FLOOR,
                                          reference_label)

CASE_KEYS = ("scene", "engine", "integrator", "dt")

UNBOUNDED_SHARE_MAX = 0.10
"""Share of a run's measured series (scene x engine x integrator or solver) that may have no bound on any
value before the gate fails: beyond one in ten, a passing check says little more than "it ran". The shipped
tolerances leave at most 5 % of the built-in suites' series so (docs/check.md)."""

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
    value_bounded: int = 0
    series: dict[tuple[str, str, str], bool] = field(default_factory=dict)
    unmeasured: dict[tuple, str] = field(default_factory=dict)
    engines: tuple[str, ...] = ()
    """Every engine with rows in the run, in the run's order."""
    held: tuple[str, ...] | None = None
    """The engines the gate holds (:func:`held_to`); None: every engine of the run."""
    findings: list[Violation] = field(default_factory=list)
    """Violations of the engines the gate does not hold: reported, never blocking."""
    absent: list[str] = field(default_factory=list)
    """One line per engine the gate requires that measured nothing (:func:`held_to`): each fails the gate."""
    measured_engines: set[str] = field(default_factory=set)
    """The engines with at least one ok row of a measured quantity (not a wall time or a declared cost)."""
    checked_of: Counter[str] = field(default_factory=Counter)
    """Per engine, its rows held to a bound."""
    refusals: dict[str, str] = field(default_factory=dict)
    """Per engine, the detail of its first n/a or failed row: why it measured nothing, in its own words."""
    unmatched: list[str] = field(default_factory=list)
    """One line per bound of a user's tolerances file that matched no row of the run (printed, not blocking)."""

    @property
    def passed(self) -> bool:
        return not self.violations and not self.absent and not self.nothing_checked

    @property
    def nothing_checked(self) -> str:
        """A one-line reason when the gate held no row of the engines it holds to a bound, else "": a check that
        checked 0 metrics checked nothing, and fails (exit 1; a run of no rows is refused before, exit 2)."""
        if self.held_checked if self.held is not None else self.checked:
            return ""
        held = ", ".join(self.held_engines) or "none"
        return (f"0 metrics checked: no bound applies to any of the run's {self.checked + self.unchecked} rows of the "
                f"engines held ({held}); a check that checks nothing does not pass (allowed: bounds whose scene, "
                "engine, integrator, scheme and metric match the run's rows; 'simparity check RUN --explain ENGINE')")

    @property
    def held_engines(self) -> tuple[str, ...]:
        """The run's engines the gate holds, in the run's order."""
        return self.engines if self.held is None else tuple(e for e in self.engines if e in self.held)

    @property
    def held_checked(self) -> int:
        """Rows of the engines the gate holds that were held to a bound."""
        return sum(self.checked_of[e] for e in self.held_engines)

    def is_held(self, engine: str) -> bool:
        return self.held is None or engine in self.held

    @property
    def unbounded_series(self) -> list[tuple[str, str, str]]:
        """The measured series (scene, engine, integrator) none of whose rows is held to a value or a verdict."""
        return [key for key, bounded in self.series.items() if not bounded]

    @property
    def unbounded_share(self) -> float:
        """Share of the measured series without a value bound (0 for a run that measured nothing)."""
        return len(self.unbounded_series) / len(self.series) if self.series else 0.0

    def too_unbounded(self, allowed_share: float = UNBOUNDED_SHARE_MAX) -> str:
        """A one-line reason when more than ``allowed_share`` of the series have no value bound, else ""."""
        unbounded = self.unbounded_series
        if self.unbounded_share <= allowed_share:
            return ""
        first = " ".join(part or "-" for part in unbounded[0])
        return (f"{len(unbounded)} of {len(self.series)} series (scene x engine x integrator) have no bound on any "
                f"value, only on their status (first: {first}); more than {allowed_share:.0%} checks too little to "
                "pass (allowed: bounds in a tolerances file, 'simparity check RUN --bless FILE', or --allow-unbounded)")


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
    if not math.isfinite(value):
        return f"{value} (an ok row without a finite value)", bound.describe(dt)
    low, high = bound.limits(dt)
    if flag == ROUNDING_FLOOR and low <= value:
        return None  # exact up to rounding: what any upper bound asks, however tight it was written
    if not (low <= value <= high):
        unit = "" if row["unit"] == DIMENSIONLESS else f" {row['unit']}"
        return f"{value:.4g}{unit}", bound.describe(dt)
    return None


def check_table(table: pd.DataFrame, bounds: list[Bound], cross_checked: bool = True) -> CheckResult:
    """Hold every row of a results table to the bound that decides it, and (``cross_checked``) every user engine's
    row to the built-in schemes of its kind (:mod:`comparisons.gate.cross_check`)."""
    result, index = CheckResult(engines=tuple(dict.fromkeys(table["engine"]))), BoundIndex(bounds)
    measured: dict[tuple, str | None] = {}  # case -> the reason nothing was measured (None: something was)
    for row in table.to_dict("records"):
        key = _case_key(row["scene"], row["engine"], row["integrator"], float(row["dt"]))
        result.cases.setdefault(key, [])
        if row["status"] != NOT_AVAILABLE:
            measured[key] = None
        elif key not in measured:
            measured[key] = str(row["detail"] or NOT_AVAILABLE)
        _note_engine(result, row)
        bound = index.decider(*_row_key(row))
        _count_series(result, row, bound)
        if bound is None:
            result.unchecked += 1
            continue
        result.checked += 1
        result.checked_of[row["engine"]] += 1
        result.value_bounded += bound.bounds_the_value
        broken = _judge(bound, row)
        if broken:
            found, text = broken
            flag = row.get("flag", "")
            verdict = row["status"] if row["status"] != OK else flag if flag in ALARM_FLAGS else ""
            violation = Violation(row["scene"], row["engine"], row["integrator"], float(row["dt"]), row["metric"],
                                  found, text, bound.reason, verdict)
            result.violations.append(violation)
            result.cases[key].append(violation)
    for violation in cross_check(table, ENGINE_NAMES) if cross_checked else ():
        result.violations.append(violation)
        result.cases.setdefault(_case_key(violation.scene, violation.engine, violation.integrator, violation.dt),
                                []).append(violation)
    for series in held_series(table, ENGINE_NAMES) if cross_checked else ():  # held to another engine's value
        if series in result.series:
            result.series[series] = True
    result.unmeasured = {key: reason for key, reason in measured.items() if reason is not None and not result.cases[key]}
    values = _run_values(table)
    refuse_impossible([b for b in bounds if not b.shipped], values)  # each pattern of a list, matched or not
    result.unmatched = unmatched_bounds(table, [b for b in index.unmatched() if not b.shipped], values)
    return result


def held_to(result: CheckResult, check: EngineNames | None, require: EngineNames | None = None) -> CheckResult:
    """``result`` with the gate holding only ``check``'s engines (None: every engine of the run): the others'
    violations become findings (reported, never blocking) and their series leave the share without a value bound;
    and failing once for each of ``require``'s engines that measured nothing (no rows in the run, or none ok: every
    row n/a or failed, the engine's own words quoted). An engine ``check`` names that has no rows in the run is bad
    input: raises :class:`SimparityError` naming where it was named."""
    if check is not None:
        refuse_strangers(check, result.engines)
    narrowed = replace(result, held=None if check is None else check.names)
    absent = [] if require is None else [f"{name} ({require.where}): {_absence(result, name)}" for name in require.names
                                         if name not in result.measured_engines]
    return replace(narrowed, violations=[v for v in result.violations if narrowed.is_held(v.engine)],
                   findings=result.findings + [v for v in result.violations if not narrowed.is_held(v.engine)],
                   series={key: bounded for key, bounded in result.series.items() if narrowed.is_held(key[1])},
                   absent=absent)


def refuse_strangers(check: EngineNames, engines: tuple[str, ...]) -> None:
    """Raise :class:`SimparityError` when ``check`` names an engine not among ``engines`` (the run's): the gate would
    hold nothing of it."""
    strangers = [name for name in check.names if name not in engines]
    if strangers:
        raise SimparityError(f"{check.where}: {one_line(', '.join(strangers), 200)}: not an engine of the run, the "
                             f"gate would hold nothing of it (allowed: the run's engines, {', '.join(engines) or 'none'})")


def _absence(result: CheckResult, engine: str) -> str:
    """Why a required engine measured nothing, in one line."""
    if engine not in result.engines:
        return "no rows in this run (not run, or not installed)"
    return f"no measured ok row; {one_line(result.refusals.get(engine, 'none of its rows measured a quantity'), 300)}"


def _note_engine(result: CheckResult, row: dict) -> None:
    """Note whether ``row``'s engine measured something (an ok row of a quantity, not a wall time or a declared
    cost), else the first reason it gave for measuring nothing (an n/a or failed row's detail)."""
    engine = row["engine"]
    if row["status"] == OK and not (is_timing(row["metric"]) or is_cost(row["metric"])):
        result.measured_engines.add(engine)
    elif row["status"] in (NOT_AVAILABLE, FAILED) and engine not in result.refusals:
        detail = row["detail"] if isinstance(row["detail"], str) else ""
        result.refusals[engine] = f"{row['status']}: {detail or 'no detail'}"


UNMATCHED_KEYS = ("scene", "engine", "integrator", "scheme", "metric")
"""A bound's patterns a run's rows are searched for, in this order, to say why the bound matched no row."""


def _run_values(table: pd.DataFrame) -> dict[str, list[str]]:
    """The run's distinct values of each of :data:`UNMATCHED_KEYS`."""
    return {key: sorted(set(table[key].fillna("").astype(str))) if key in table else [""] for key in UNMATCHED_KEYS}


def unmatched_bounds(table: pd.DataFrame, bounds: list[Bound], values: dict[str, list[str]] | None = None) -> list[str]:
    """One line per bound (of a user's file) that matched no row: the first of its keys none of whose patterns matches
    any of the run's values of that column (``values``, default: read from ``table``), else that no row matches them
    together (a time step, a reference). A pattern that matches nothing that exists either is refused
    (:func:`refuse_impossible`, exit 2)."""
    values = _run_values(table) if values is None else values
    refuse_impossible(bounds, values)
    missing = {key: unmatched_patterns({p for bound in bounds for p in patterns_of(bound, key)}, values[key])
               for key in UNMATCHED_KEYS}
    lines = []
    for bound in bounds:
        why = "no row matches its keys together (scene, engine, integrator, scheme, metric, dt, reference)"
        for key in UNMATCHED_KEYS:
            patterns = patterns_of(bound, key)
            if all(p in missing[key] for p in patterns):
                shown = patterns[0] if len(patterns) == 1 else list(patterns)
                why = f"its {key} {shown!r:.80} matches none of the run's {len(values[key])} {key}s"
                break
        lines.append(f"{bound.where} matched no row of this run: {why}; it held nothing")
    return lines


def _count_series(result: CheckResult, row: dict, bound: Bound | None) -> None:
    """Note whether ``row``'s series is held to a value: timing rows never are (and do not count), nor are cost rows
    (a declared stage count over dt: a bound on it holds no numerics), a series whose every row is n/a measured
    nothing (and does not count)."""
    if is_timing(row["metric"]) or is_cost(row["metric"]):
        return
    if row["status"] == NOT_AVAILABLE:  # nothing measured: neither a series measured nor a value held
        return
    key = (row["scene"], row["engine"], row["integrator"] if isinstance(row["integrator"], str) else "")
    result.series[key] = result.series.get(key, False) or (bound is not None and bound.bounds_the_value)


def _case_key(scene: str, engine: str, integrator: str, dt: float) -> tuple:
    """A case's key in :attr:`CheckResult.cases` (NaN dt as "nan", so that order rows share one key)."""
    return (scene, engine, integrator, "nan" if math.isnan(dt) else dt)


def _row_key(row: dict) -> tuple[str, str, str, str, float, str, bool]:
    """What a bound matches of a results table's record (a table without a scheme column: scheme ""), and whether
    the row is measured against itself (its engine and integrator are its reference)."""
    scheme, integrator = row.get("scheme", ""), row["integrator"] if isinstance(row["integrator"], str) else ""
    own_reference = row.get("reference") == reference_label(row["engine"], integrator)
    return (row["scene"], row["engine"], integrator, row["metric"], float(row["dt"]),
            scheme if isinstance(scheme, str) else "", own_reference)


def _row_bound(index: BoundIndex, row: dict) -> Bound | None:
    """The bound that decides ``row`` (a results table's record)."""
    return index.decider(*_row_key(row))


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
    index = BoundIndex(bounds)
    for row in table[table["engine"] == engine].to_dict("records"):
        bound = _row_bound(index, row)
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
                     f"{CROSS_CHECK_FACTOR:g} x the largest built-in's, a chain in motion's within "
                     f"{JOINT_AGREEMENT_FACTOR:g} x, {CROSS_CHECK_FACTOR:g} x its family's where none of its kind ran "
                     f"(engine_rk4, engine_euler), IK solve rates at least {SOLVE_RATE_FRACTION:.0%} of the best "
                     "built-in's, null-space terms that help; docs/check.md)")
    return lines


EXPLAINED_ROWS_MAX = 50
"""Rows ``--explain`` details at most (narrow with --scene, --integrator, --metric); the rest are counted."""


def explain_rows(table: pd.DataFrame, bounds: list[Bound], engine: str, scene: str = "*", integrator: str = "*",
                 metric: str = "*") -> list[str]:
    """For each of ``engine``'s rows matching the fnmatch patterns: the row, then every bound that matched it, the
    deciding one first, each with its file and why it decides or does not (at most :data:`EXPLAINED_ROWS_MAX`
    rows)."""
    rows = [row for row in table[table["engine"] == engine].to_dict("records")
            if fnmatch.fnmatchcase(row["scene"], scene) and fnmatch.fnmatchcase(row["integrator"] or "", integrator)
            and fnmatch.fnmatchcase(row["metric"], metric)]
    lines, index = [], BoundIndex(bounds)
    for row in rows[:EXPLAINED_ROWS_MAX]:
        matched = index.matching(*_row_key(row))
        label = row_label(row["scene"], row["engine"], row["integrator"], float(row["dt"]), row["metric"])
        value = f"{float(row['value']):.4g}" if row["status"] == OK else row["status"]
        lines.append(f"{label} = {value}: " + (f"{len(matched)} bound(s) matched" if matched else
                                                "no bound matched (counted as without a bound)"))
        for rank, bound in enumerate(matched):
            verdict = "decides" if rank == 0 else "overridden: " + _why_not(bound, matched[0])
            lines.append(f"  {verdict}: {bound.where} holds it to {_held(bound, float(row['dt']))} ({bound.reason})")
    if len(rows) > EXPLAINED_ROWS_MAX:
        lines.append(f"... and {len(rows) - EXPLAINED_ROWS_MAX} more rows (narrow with --scene, --integrator, --metric)")
    return lines


def _held(bound: Bound, dt: float) -> str:
    return (bound.describe(dt) + ", " if bound.bounds_a_number else "") + bound.status_text()


def _why_not(bound: Bound, decider: Bound) -> str:
    """Why ``bound`` does not decide a row ``decider`` decides."""
    if bound.layer < decider.layer:
        return "the deciding bound's file extends this one, and the extending file wins"
    if bound.specificity < decider.specificity:
        return f"less specific ({bound.specificity} against {decider.specificity})"
    return "as specific, but earlier in its file"


@dataclass
class BaselineDiff:
    """What changed since a baseline run among the scenes x engines both ran: moves block, timing changes do not.

    ``timing``: one summary per scene whose timings changed; ``out_of_scope``: baseline rows of scenes x engines
    this run did not ask for (not compared, not missing); ``not_in_baseline``: this run's rows of scenes x engines
    the baseline did not run."""

    moved: list[str] = field(default_factory=list)
    missing: list[str] = field(default_factory=list)
    new: list[str] = field(default_factory=list)
    timing: list[str] = field(default_factory=list)
    out_of_scope: int = 0
    not_in_baseline: int = 0
    compared: int = 0
    """Rows both runs have (same scene, engine, integrator, dt and metric): what the comparison compared."""

    @property
    def blocking(self) -> bool:
        return bool(self.moved or self.missing or self.nothing_compared)

    @property
    def nothing_compared(self) -> str:
        """A one-line reason when no row of this run has its counterpart in the baseline, else "": a comparison
        that compared nothing does not pass."""
        if self.compared:
            return ""
        return (f"0 rows compared: none of this run's {self.not_in_baseline + len(self.new)} rows has its scene, "
                f"engine, integrator, dt and metric in the baseline's {self.out_of_scope + len(self.missing)} "
                "(allowed: a baseline of the same scenes and engines)")

    def scope_line(self) -> str:
        """What the comparison left out, in one line ("" when both runs ran the same scenes x engines)."""
        parts = ([f"{self.out_of_scope} baseline rows of scenes x engines this run did not run"]
                 if self.out_of_scope else []) + (
            [f"{self.not_in_baseline} rows of scenes x engines the baseline did not run"] if self.not_in_baseline else [])
        return "not compared: " + "; ".join(parts) if parts else ""


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


def _shared(now: pd.DataFrame, before: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Both tables cut to the (scene, engine) pairs both have rows of."""
    def pairs(table: pd.DataFrame) -> pd.Index:
        return pd.MultiIndex.from_arrays([table.index.get_level_values("scene"), table.index.get_level_values("engine")])
    now_pairs, before_pairs = pairs(now), pairs(before)
    return now[now_pairs.isin(before_pairs)], before[before_pairs.isin(now_pairs)]


def compare_with_baseline(table: pd.DataFrame, baseline: pd.DataFrame,
                          relative: float = BASELINE_RELATIVE) -> BaselineDiff:
    """Among the scenes x engines both runs ran: rows whose status changed or whose value moved by more than
    ``relative`` (of the baseline's magnitude) since ``baseline``, rows only one run has, and per scene a summary
    of its timing changes. Rows of scenes x engines only one run ran are counted apart, never missing."""
    all_now, all_before = _keyed(table), _keyed(baseline)
    now, before = _shared(all_now, all_before)
    diff = BaselineDiff(missing=[_key_label(k) for k in before.index.difference(now.index)],
                        new=[_key_label(k) for k in now.index.difference(before.index)],
                        out_of_scope=len(all_before) - len(before), not_in_baseline=len(all_now) - len(now))
    common = now.index.intersection(before.index)
    diff.compared = len(common)
    a, b = now.loc[common], before.loc[common]
    x, y = a["value"].to_numpy(dtype=float), b["value"].to_numpy(dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        change = np.where(y != 0, np.abs(x - y) / np.abs(y), np.where(x == 0, 0.0, np.inf))
    status_now, status_before = a["status"].to_numpy(), b["status"].to_numpy()
    retagged = status_now != status_before
    moved = ~retagged & ~(x == y) & ~(np.isnan(x) & np.isnan(y)) & ~(change <= relative)  # inf -> inf: unchanged
    timing: dict[str, list[float]] = {}
    for i in np.flatnonzero(retagged | moved):
        key = common[i]
        if is_timing(key[-1]):
            timing.setdefault(key[0], []).append(x[i] / y[i] if y[i] > 0 and not retagged[i] else math.nan)
            continue
        text = (f"status {status_before[i]} -> {status_now[i]}" if retagged[i]
                else f"{y[i]:.6g} -> {x[i]:.6g} ({change[i]:.2g} relative)")
        diff.moved.append(f"{_key_label(key)}: {text}")
    timed = Counter(key[0] for key in common if is_timing(key[-1]))
    diff.timing = [_timing_line(scene, ratios, timed[scene]) for scene, ratios in timing.items()]
    return diff


def _timing_line(scene: str, ratios: list[float], timed: int) -> str:
    """One scene's timing changes in one line: how many, and the range of now / before."""
    finite = [r for r in ratios if math.isfinite(r)]
    spread = f", now / before x{min(finite):.2g} to x{max(finite):.2g}" if finite else ""
    return f"{scene}: {len(ratios)} of {timed} timings changed{spread}"
