"""Reading a stored run, from ``results.parquet`` when it is there and pyarrow is installed, else from ``results.csv``;
and writing that typed copy of the CSV (:func:`write_parquet`)."""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import pandas as pd

from simparity.core.model.errors import ResultsError, one_line
from simparity.core.model.run_info import RunInfo
from simparity.core.model.results import (
    COLUMNS,
    RESULTS_FILE,
    RESULTS_PARQUET_FILE,
    RUN_INFO_FILE,
    SERIES_COLUMNS,
    SERIES_FILE,
    SWEEP_COLUMN,
    SWEEP_PREFIX,
)


# pandas < 3 parses floats inexactly unless asked; pandas 3 is exact and deprecates the option.
_EXACT_FLOATS = {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}


CATEGORICAL_COLUMNS = ("scene", "engine", "integrator", "metric", "unit", "reference", "status", "flag", "scheme",
                       SWEEP_COLUMN)
"""Columns of few distinct values, dictionary-encoded in ``results.parquet``: a sweep of 1,000 variants repeats each
engine's, integrator's and metric's name in tens of thousands of rows. ``read_run`` gives them back as text, as the
CSV does."""


def parquet_available() -> bool:
    """Whether pyarrow (``simparity[parquet]``) can be imported: without it runs are stored and read as CSV only."""
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return False
    return True


def read_run(run_dir: str | Path) -> tuple[pd.DataFrame, RunInfo]:
    """(results table, run information) of a stored run; raises ResultsError if unusable.

    The table has :data:`core.results.COLUMNS` (``dt`` and ``value`` float64) and, for a run of swept scenes,
    the sweep columns: ``sweep`` (text, empty for scenes without a sweep) and each ``sweep:KEY`` as numbers
    (Int64 for whole-number keys, else float64; missing for rows of scenes that do not sweep the key). Read from
    ``results.parquet`` when the run has one, no older than the CSV, and pyarrow is installed (the same table, a
    fiftieth of the size for a large run; an unreadable one is passed over for the CSV), else from ``results.csv``."""
    run_dir = Path(run_dir)
    results, info = run_dir / RESULTS_FILE, run_dir / RUN_INFO_FILE
    for path in (results, info):
        if not path.is_file():
            raise ResultsError(f"{one_line(path)}: missing (allowed: the output folder of 'simparity run', holding "
                               f"{RESULTS_FILE} and {RUN_INFO_FILE})")
    meta = RunInfo.read(info)
    table = _read_parquet(run_dir / RESULTS_PARQUET_FILE, results)
    if table is None:
        table = _read_csv(results, run_dir)
    missing = [c for c in COLUMNS if c not in table.columns]
    if missing:
        raise ResultsError(f"{results}: missing columns {missing} (allowed: a results.csv with {', '.join(COLUMNS)})")
    return table, meta


def _read_csv(results: Path, run_dir: Path) -> pd.DataFrame:
    """``results.csv`` typed as :func:`read_run` describes (schema 1's missing ``flag`` and ``scheme`` empty)."""
    try:
        swept = [c for c in pd.read_csv(results, nrows=0).columns if c == SWEEP_COLUMN or c.startswith(SWEEP_PREFIX)]
        # keep_default_na=False: pandas would read the status "n/a" as missing.
        table = pd.read_csv(results, keep_default_na=False, **_EXACT_FLOATS, dtype={c: str for c in swept},
                            na_values={"value": ["", "nan", "NaN"], "dt": ["", "nan", "NaN"]})
        for column in (c for c in swept if c != SWEEP_COLUMN):
            table[column] = _swept_values(table[column])
    except (pd.errors.ParserError, UnicodeDecodeError, ValueError) as err:
        raise ResultsError(f"{one_line(run_dir)}: unreadable stored run: {one_line(err)} (allowed: a folder written by "
                           "'simparity run')") from None
    for column in ("flag", "scheme"):  # schema 1: written before rows carried them
        if column not in table.columns:
            table.insert(table.columns.get_loc("detail") + 1 + (column == "scheme"), column, "")
    return table


def _read_parquet(path: Path, results: Path) -> pd.DataFrame | None:
    """``results.parquet`` with its categorical columns as text again; None when there is none, pyarrow is missing,
    it is older than ``results`` (the CSV, edited since it was written) or it cannot be read: then the CSV is read."""
    if not path.is_file() or not parquet_available() or path.stat().st_mtime_ns < results.stat().st_mtime_ns:
        return None
    import pyarrow

    try:
        table = pd.read_parquet(path, engine="pyarrow")
    except (OSError, ValueError, pyarrow.ArrowException):
        return None
    text = pd.Series([""]).dtype  # what the CSV reader gives text columns: object, or str on pandas 3
    return table.astype({c: text for c in CATEGORICAL_COLUMNS if c in table.columns})


def write_parquet(run_dir: str | Path) -> Path | None:
    """``results.parquet`` beside the run's ``results.csv``: the same table as :func:`read_run` reads from the CSV,
    the :data:`CATEGORICAL_COLUMNS` dictionary-encoded, numbers typed. Written to a temporary name and renamed. Returns
    its path; None (and nothing written) without pyarrow."""
    if not parquet_available():
        return None
    run_dir = Path(run_dir)
    table = _read_csv(run_dir / RESULTS_FILE, run_dir)
    typed = table.astype({c: "category" for c in CATEGORICAL_COLUMNS if c in table.columns})
    path = run_dir / RESULTS_PARQUET_FILE
    partial = path.with_name(path.name + ".partial")
    typed.to_parquet(partial, engine="pyarrow", index=False)
    os.replace(partial, path)
    return path


_WHOLE = re.compile(r"-?[0-9]+")


def _swept_values(column: pd.Series) -> pd.Series:
    """A sweep column's text as numbers: Int64 when every value given is whole (a seed, a count), else float64
    (read by Python's float, exact); an empty cell (a row of a scene that does not sweep the key) is missing."""
    given = column[column != ""]
    if given.map(lambda text: _WHOLE.fullmatch(text) is not None).all():
        return pd.Series([int(text) if text else pd.NA for text in column], index=column.index, dtype="Int64")
    return pd.Series([float(text) if text else math.nan for text in column], index=column.index, dtype=float)


def read_series(run_dir: str | Path) -> pd.DataFrame:
    """The sampled series of a stored run (columns :data:`core.results.SERIES_COLUMNS`); empty for a run
    stored without them. Raises ResultsError if the file is unreadable."""
    path = Path(run_dir) / SERIES_FILE
    if not path.is_file():
        return pd.DataFrame(columns=list(SERIES_COLUMNS))
    try:
        series = pd.read_csv(path, keep_default_na=False, na_values={c: ["", "nan", "NaN"] for c in ("dt", "x", "value")})
    except (pd.errors.ParserError, UnicodeDecodeError, OSError, EOFError) as err:
        raise ResultsError(f"{one_line(path)}: unreadable series: {one_line(err)} (allowed: the {SERIES_FILE} "
                           "written by 'simparity run')") from None
    missing = [c for c in SERIES_COLUMNS if c not in series.columns]
    if missing:
        raise ResultsError(f"{path}: missing columns {missing} (allowed: {', '.join(SERIES_COLUMNS)})")
    return series
