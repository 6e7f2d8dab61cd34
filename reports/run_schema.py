"""The schema of a stored run's results table, and the one check every reader of one applies: ``results.csv``,
``results.parquet`` and a run copied into the history database are held to it alike (:func:`conformed`).

A table conforms when it has simparity's columns in simparity's order (the fixed ones of its schema version, then
for a run of swept scenes ``sweep`` and its ``sweep:KEY`` columns), at least one row, text where text belongs, a
number in ``dt`` (a time step > 0 [s], or none) and ``value``, a status of :data:`core.model.results.STATUSES`, a
number on every ok row (finite: an ok row is a measurement; +inf only for an invariance ratio, a difference where
none is allowed), a flag of :data:`core.model.results.FLAGS` or none, and a kind of scheme
(:data:`core.model.engine.SCHEME_KINDS`, joined by ``+``) or none. Every check is vectorised over the rows; where a
check fails, the first row that fails it is named, with what it holds and what is allowed.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pandas as pd

from simparity.core.model.engine import is_scheme_label
from simparity.core.model.errors import echo
from simparity.core.model.metric_catalogue import INVARIANCE_RATIO
from simparity.core.model.results import (
    COLUMNS,
    FLAGS,
    OK,
    SERIES_COLUMNS,
    SERIES_QUANTITIES,
    STATUSES,
    SWEEP_COLUMN,
    SWEEP_PREFIX,
)

NUMERIC_COLUMNS = ("dt", "value")
"""The fixed columns holding numbers (float64); every other fixed column holds text."""
SCHEMA_1_COLUMNS = tuple(c for c in COLUMNS if c not in ("flag", "scheme"))
"""The fixed columns of a run of schema version 1, written before rows carried a flag and a scheme."""
REQUIRED_TEXT = ("scene", "engine", "metric")
"""Text columns no row may leave empty."""
NOT_A_NUMBER = ("", "nan", "NaN")
"""What a numeric cell holds for "no number" (a kinematics scene's dt, an n/a row's value)."""
_TEXT_COLUMNS = tuple(c for c in COLUMNS if c not in NUMERIC_COLUMNS)
SERIES_NUMBERS = ("dt", "x", "value")
"""The columns of ``series.csv.gz`` holding numbers (float64); the others hold text."""


def fixed_columns(schema_version: int) -> tuple[str, ...]:
    """The fixed columns of a run of ``schema_version`` (run.json's), in their order."""
    return SCHEMA_1_COLUMNS if schema_version == 1 else COLUMNS


def allowed_columns(fixed: tuple[str, ...]) -> str:
    return f"the columns {','.join(fixed)}, then for swept scenes {SWEEP_COLUMN} and {SWEEP_PREFIX}KEY columns"


def header_problem(header: list[str], fixed: tuple[str, ...]) -> str | None:
    """What is wrong with a table's column names (``fixed`` columns first, in order, then the sweep columns), or
    None when they conform."""
    allowed = f"(allowed: {allowed_columns(fixed)})"
    repeated = [name for name in dict.fromkeys(header) if header.count(name) > 1]
    missing = [name for name in fixed if name not in header]
    strangers = [name for name in header[len(fixed):] if name != SWEEP_COLUMN and not name.startswith(SWEEP_PREFIX)]
    if missing:
        return f"no column {', '.join(map(echo, missing))} {allowed}"
    if repeated:
        return f"column {echo(repeated[0])} appears {header.count(repeated[0])} times {allowed}"
    if strangers:
        return f"column {echo(strangers[0])} is not one of simparity's {allowed}"
    for position, (name, expected) in enumerate(zip(header, fixed), start=1):
        if name != expected:
            return f"column {position} is {echo(name)} where {echo(expected)} belongs {allowed}"
    swept = header[len(fixed):]
    if swept and swept[0] != SWEEP_COLUMN:
        return f"column {echo(swept[0])} without a {SWEEP_COLUMN} column before it {allowed}"
    return None


class RowProblem(Exception):
    """A table that does not conform: ``row`` (its position, from 0; None for the table as a whole) and what."""

    def __init__(self, row: int | None, problem: str) -> None:
        super().__init__(problem)
        self.row, self.problem = row, problem


def _first(mask: np.ndarray | pd.Series) -> int | None:
    hits = np.flatnonzero(np.asarray(mask, dtype=bool))
    return int(hits[0]) if len(hits) else None


def _numbers(table: pd.DataFrame, column: str) -> np.ndarray:
    """``column`` as float64; RowProblem at its first cell that is not a number (text, bytes, a repeated header)."""
    cells = table[column]
    if pd.api.types.is_float_dtype(cells.dtype) or pd.api.types.is_integer_dtype(cells.dtype):
        return cells.to_numpy(dtype=float)  # whole numbers (a column of them reads as int64) exactly as floats
    text = cells.map(lambda v: v if isinstance(v, str) else None)
    converted = pd.to_numeric(cells.where(text.isna() | ~text.isin(NOT_A_NUMBER)), errors="coerce")
    bad = _first(converted.isna() & cells.notna() & ~text.isin(NOT_A_NUMBER))
    if bad is not None:
        raise RowProblem(bad, f"{column} {echo(cells.iloc[bad])} is not a number (allowed: a number, or "
                              f"{', '.join(map(repr, NOT_A_NUMBER))} for none)")
    return converted.to_numpy(dtype=float)


def require_text(table: pd.DataFrame, columns: tuple[str, ...]) -> None:
    """RowProblem at the first row with no value in one of the text ``columns`` (a row cut short), or a value that
    is not text."""
    present = [c for c in columns if c in table.columns]
    missing = table[present].isna().to_numpy()
    if missing.any():
        row = int(np.flatnonzero(missing.any(axis=1))[0])
        column = present[int(np.flatnonzero(missing[row])[0])]
        raise RowProblem(row, f"no {column} (a row cut short, or an empty cell; allowed: a value in every column, "
                              "text where text belongs)")
    for column in present:
        if pd.api.types.infer_dtype(table[column], skipna=False) not in ("string", "empty"):
            bad = _first(~table[column].map(lambda v: isinstance(v, str))) or 0  # the slow search, for a refusal only
            raise RowProblem(bad, f"{column} {echo(table[column].iloc[bad])} is not text (allowed: text)")


def conformed_series(series: pd.DataFrame) -> pd.DataFrame:
    """``series`` (``series.csv.gz``, its columns checked) with its numbers as float64; RowProblem at the first row
    cut short or holding text where a number belongs."""
    require_text(series, tuple(c for c in SERIES_COLUMNS if c not in SERIES_NUMBERS))
    bad = _first(~series["quantity"].isin(tuple(SERIES_QUANTITIES)))  # also a row cut short: its quantity is empty
    if bad is not None:
        raise RowProblem(bad, f"quantity {echo(series['quantity'].iloc[bad])} (allowed: {', '.join(SERIES_QUANTITIES)})")
    numbers = {column: _numbers(series, column) for column in SERIES_NUMBERS}
    if any(series[c].dtype != float for c in SERIES_NUMBERS):
        series = series.assign(**numbers)
    return series


def _check_rows(table: pd.DataFrame) -> None:
    """RowProblem at the first row of ``table`` (the fixed columns present) that breaks the schema."""
    if table.empty:
        raise RowProblem(None, "no rows (allowed: a run with at least one row; a run that measured nothing is not "
                               "a run the gate or a report can read)")
    header = (table["scene"] == "scene") & (table["status"] == "status")
    if header.any():
        raise RowProblem(_first(header), "repeats the header (allowed: one header line, then rows)")
    require_text(table, _TEXT_COLUMNS)
    for column in REQUIRED_TEXT:
        bad = _first(table[column] == "")
        if bad is not None:
            raise RowProblem(bad, f"empty {column} (allowed: a {column} name)")


def _check_values(table: pd.DataFrame, dt: np.ndarray, value: np.ndarray) -> None:
    """RowProblem at the first row whose status, time step, value, flag or scheme breaks the schema."""
    status = table["status"]
    bad = _first(~status.isin(STATUSES))
    if bad is not None:
        raise RowProblem(bad, f"status {echo(status.iloc[bad])} (allowed: {', '.join(STATUSES)})")
    bad = _first(~(np.isnan(dt) | (np.isfinite(dt) & (dt > 0))))
    if bad is not None:
        raise RowProblem(bad, f"dt {float(dt[bad])!r} (allowed: a time step > 0 [s], or none for a scene without one)")
    ok = (status == OK).to_numpy()
    unmeasured = np.flatnonzero(ok & ~np.isfinite(value))
    bad = next((int(row) for row in unmeasured
                if not (np.isposinf(value[row]) and INVARIANCE_RATIO.matches(table["metric"].iloc[row]))), None)
    if bad is not None:
        raise RowProblem(bad, f"status ok with value {float(value[bad])!r} (allowed: a finite value on an ok row, +inf only "
                              f"for an {INVARIANCE_RATIO.prefix}* ratio; nan or inf on {', '.join(STATUSES[1:])} rows)")
    if "flag" in table.columns:
        bad = _first(~table["flag"].isin(("",) + tuple(FLAGS)))
        if bad is not None:
            raise RowProblem(bad, f"flag {echo(table['flag'].iloc[bad])} (allowed: none, or {', '.join(FLAGS)})")
    if "scheme" in table.columns:
        labels = [label for label in table["scheme"].unique() if is_scheme_label(label)]
        bad = _first(~table["scheme"].isin(labels))
        if bad is not None:
            raise RowProblem(bad, f"scheme {echo(table['scheme'].iloc[bad])} (allowed: none, or kinds of scheme "
                                  "joined by '+', as core.model.engine.SCHEME_KINDS names them)")


def conformed(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` (its column names already checked by :func:`header_problem`) with ``dt`` and ``value`` as float64,
    when every row conforms to the schema; raises :class:`RowProblem` at the first row that does not."""
    _check_rows(table)
    dt, value = (_numbers(table, column) for column in NUMERIC_COLUMNS)
    _check_values(table, dt, value)
    if table["dt"].dtype != float or table["value"].dtype != float:
        table = table.assign(dt=dt, value=value)
    return table


def refuse(err: RowProblem, source: str, row_name: Callable[[int], str], error: type[Exception]) -> Exception:
    """The one-line error of ``err``: ``source: row_name(row): problem`` (``source: problem`` for the whole table)."""
    where = f"{row_name(err.row)}: " if err.row is not None else ""
    return error(f"{source}: {where}{err.problem}")
