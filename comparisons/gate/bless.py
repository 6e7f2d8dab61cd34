"""``simparity check RUN --bless FILE``: a tolerances file that holds later runs to what this run measured.

Like pytest-regressions' ``--force-regen``, for numerics: every row of the run becomes a bound keyed by its
scene, engine, integrator, time step and metric, with the run and commit it came from in its reason. The file
extends the shipped tolerances (``extends = "default"``), and its bounds win where they match.

- An error, a drift or a state's deviation (lower is better) is held to at most its value plus
  :data:`BLESS_RELATIVE_MARGIN`; any other number (an order, a rate, a measured restitution, a stability limit,
  a cost in force evaluations per second)
  to its value plus or minus that margin (:data:`BLESS_ORDER_BAND` for an order). A row at its rounding floor
  stays a pass whatever its bound (the check lets a ``rounding-floor`` row through any upper bound), so no
  blessed bound sits below a metric's rounding floor.
- With a second run of the same scenes (``--spread RUN2``: another machine, another BLAS, a perturbed scene),
  each margin is at least :data:`BLESS_SPREAD_FACTOR` times the two runs' difference, so a chaotic scene gets
  the wider bound it needs; a status that differs between the runs is blessed as either.
- Timing rows are never blessed (wall time is not numerics). A ``failed`` row, one flagged with an alarm, an
  ``ok`` row without a finite value (in the run or the ``--spread`` run), or a value that breaks a bound of the
  tolerances the file extends (the shipped ones: an RK4 of order 2) refuses the whole file: the blessed bound
  would win over the broken one, and a bug must not become a passing gate by one command. A ``diverged`` case is blessed as
  the expected verdict, with "expected — review" in its reason; an ``n/a`` row as n/a, with its reason.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pandas as pd

from simparity.comparisons.gate.check import check_table
from simparity.comparisons.gate.tolerances import DEFAULT_TOLERANCES, Bound, load_tolerances
from simparity.comparisons.gate.violation import row_label
from simparity.core.model.errors import ToleranceError, one_line
from simparity.core.model.metric_catalogue import CATALOGUE, DRIFT, ERROR, ORDER, VALIDITY, family_of, is_timing
from simparity.core.model.results import ALARM_FLAGS, DIVERGED, FAILED, OK
from simparity.core.model.run_info import RunInfo

BLESS_RELATIVE_MARGIN = 0.1
"""Headroom over a blessed value: a rerun on this machine reproduces it bit for bit, another BLAS or libm moves an
error by far less than 10 %, and a scheme that lost an order (or a planted bug) moves it by far more."""

BLESS_ORDER_BAND = 0.25
"""Half-width of a blessed observed order: a fit moves by a few hundredths between machines; half the step
between two whole orders (0.5) would let a scheme of the next order pass."""

BLESS_SPREAD_FACTOR = 3.0
"""A blessed margin is at least this many times the difference between the run and a second run of the same
scenes (``--spread``): three times the spread seen once covers most reruns of a chaotic scene."""

LOWER_IS_BETTER = (ERROR, DRIFT, VALIDITY)
"""Kinds of metric held only from above: an error, a drift or a deviation that shrinks is an improvement."""


def _kind(metric: str) -> str:
    family = family_of(metric)
    return CATALOGUE[metric].kind if metric in CATALOGUE else family.kind if family is not None else ""


def _text(value: str) -> str:
    """A TOML basic string (JSON's escapes are TOML's)."""
    return json.dumps(value, ensure_ascii=False)


def _key_lines(row: dict, metric: str) -> list[str]:
    lines = [f"scene = {_text(row['scene'])}", f"engine = {_text(row['engine'])}",
             f"integrator = {_text(row['integrator'] or '*')}"]
    if not math.isnan(float(row["dt"])):
        lines.append(f"dt = {float(row['dt'])!r}")
    return lines + [f"metric = {_text(metric)}"]


def _refuse(run_dir: Path, table: pd.DataFrame) -> None:
    """Raise ToleranceError naming the first failed, alarmed or non-finite ok row of ``table``, if any."""
    flags = table["flag"].fillna("") if "flag" in table else pd.Series("", index=table.index)
    values = pd.to_numeric(table["value"], errors="coerce")
    bad = table[(table["status"] == FAILED) | flags.isin(ALARM_FLAGS)
                | ((table["status"] == OK) & ~values.apply(math.isfinite))]
    if bad.empty:
        return
    row = bad.iloc[0]
    what = f"status {row['status']}" + (f", flag {row['flag']}" if row.get("flag") in ALARM_FLAGS else "") + (
        f", value {row['value']}" if row["status"] == OK else "")
    raise ToleranceError(str(run_dir), row_label(row["scene"], row["engine"], row["integrator"], float(row["dt"]),
                                                   row["metric"]),
                         f"{len(bad)} row(s) failed, flagged an alarm or are ok without a finite value, first {what}: "
                         "nothing was blessed",
                         "a run whose rows are ok with a number, n/a or diverged (fix or drop what failed, then bless)")


def _refuse_violations(run_dir: Path, table: pd.DataFrame, extended: list[Bound]) -> None:
    """Raise ToleranceError when a row breaks a bound of the tolerances the blessed file extends (a value or a
    cross-check; a case that diverged is blessed, marked for review): the blessed file would win over that bound
    and turn the violation into a pass."""
    broken = [v for v in check_table(table, extended).violations if v.verdict != DIVERGED]
    if broken:
        raise ToleranceError(str(run_dir), "--bless", f"{len(broken)} metric(s) break the bounds the blessed file "
                             f"would extend, first {one_line(broken[0].line(), 300)}: nothing was blessed",
                             "a run that passes 'simparity check' but for diverged cases (fix it, or write that "
                             "bound yourself with its reason)")


def _numbers(row: dict, other: dict | None) -> list[str]:
    """The numeric keys of one ok row's bound (``other``: the same row in the spread run, or None)."""
    value = float(row["value"])
    spread = BLESS_SPREAD_FACTOR * abs(value - float(other["value"])) if other is not None and other["status"] == OK \
        else 0.0
    kind = _kind(row["metric"])
    if kind in LOWER_IS_BETTER:
        return [f"max = {max(value * (1 + BLESS_RELATIVE_MARGIN), value + spread)!r}"]
    band = max(BLESS_ORDER_BAND if kind == ORDER else BLESS_RELATIVE_MARGIN * abs(value), spread)
    return [f"expected = {value!r}", f"band = {band!r}"]


def bless(table: pd.DataFrame, info: RunInfo, run_dir: Path, spread: pd.DataFrame | None = None,
          extended: list[Bound] | None = None, extends: str = "default") -> tuple[str, int]:
    """(the tolerances file's text, the bounds in it) blessing every row of ``table`` (module docstring);
    ToleranceError when a row of ``table`` or ``spread`` failed, flagged an alarm or is ok without a finite value,
    or (``extended``: the bounds the file extends, default the shipped ones; ``extends``: the file's ``extends``
    value naming them) a row breaks one of those bounds."""
    _refuse(run_dir, table)
    if spread is not None:
        _refuse(run_dir, spread)
    _refuse_violations(run_dir, table, load_tolerances() if extended is None else extended)
    origin = f"blessed from run {run_dir} at commit {info.git_commit or 'unknown'} ({info.created_utc or 'undated'})"
    others = _indexed(spread) if spread is not None else {}
    blocks, diverged_cases = [], set()
    for row in table.to_dict("records"):
        if is_timing(row["metric"]):
            continue
        key = _row_key(row)
        other = others.get(key)
        statuses = sorted({row["status"]} | ({other["status"]} if other is not None else set()))
        if row["status"] == DIVERGED:
            case = key[:4]
            if case in diverged_cases:
                continue
            diverged_cases.add(case)
            blocks.append(_key_lines(row, "*") + [f"status = {json.dumps(statuses)}", "reason = " + _text(
                f"expected — review: diverged in the run this was {origin} ({str(row['detail'])[:200]})")])
            continue
        lines = _key_lines(row, row["metric"])
        if row["status"] == OK and statuses == [OK]:
            lines += _numbers(row, other)
            why = f"{origin}: measured {float(row['value']):.6g}"
        else:
            why = f"{origin}: {row['status']} ({str(row['detail'])[:200]})"
        if statuses != [OK]:
            lines.append(f"status = {json.dumps(statuses)}")
        if other is not None and statuses != [row["status"]]:
            why += f"; {' or '.join(statuses)} between the two runs (--spread): review"
        blocks.append(lines + [f"reason = {_text(why)}"])
    header = [f"# simparity tolerances {origin}.", "# Review before committing: a blessed 'diverged' or 'n/a' is what "
              "that run did, not necessarily what it should do.", f"extends = {_text(extends)}", "", ""]
    body = ["[[bound]]\n" + "\n".join(lines) + "\n" for lines in blocks]
    return "\n".join(header) + "\n".join(body), len(blocks)


def _row_key(row: dict) -> tuple:
    dt = float(row["dt"])
    return row["scene"], row["engine"], row["integrator"] or "", "nan" if math.isnan(dt) else repr(dt), row["metric"]


def _indexed(table: pd.DataFrame) -> dict[tuple, dict]:
    return {_row_key(row): row for row in table.to_dict("records")}


def write_blessed(path: Path, text: str) -> None:
    """Write the blessed file; refuses to overwrite the shipped tolerances."""
    if path.resolve() == DEFAULT_TOLERANCES.resolve():
        raise ToleranceError(str(path), "--bless", "is the shipped tolerances file", "a file of your own")
    try:
        path.write_text(text, encoding="utf-8")
    except OSError as err:
        raise ToleranceError(str(path), "--bless", f"cannot write: {err.strerror or err}",
                             "a writable path for the new tolerances file") from None

