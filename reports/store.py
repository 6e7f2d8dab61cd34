"""The stored run's format, its one owner: writing a run as it goes (:class:`RunWriter`: ``results.csv`` and
``series.csv.gz`` appended scene by scene, ``run.json`` through :class:`RunInfo`, ``results.parquet`` when it ends,
the table it wrote handed back) and reading one (:func:`read_run`, from ``results.parquet`` when it is there and
pyarrow is installed, else from ``results.csv``; :func:`read_series`)."""

from __future__ import annotations

import csv
import functools
import math
import os
import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np
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
    ResultRow,
    SeriesRecord,
    sweep_column,
)
from simparity.reports.csv_records import records
from simparity.reports.run_schema import (
    NOT_A_NUMBER,
    NUMERIC_COLUMNS,
    SERIES_NUMBERS,
    RowProblem,
    conformed,
    conformed_series,
    fixed_columns,
    header_problem,
    refuse,
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


def read_run(run_dir: str | Path, empty: bool = False) -> tuple[pd.DataFrame, RunInfo]:
    """(results table, run information) of a stored run; raises ResultsError, in one line naming the file and the row,
    column or key, for a run that does not conform to its schema (:mod:`reports.run_schema`, ``RunInfo.read``).

    The table has :data:`core.results.COLUMNS` (``dt`` and ``value`` float64) and, for a run of swept scenes,
    the sweep columns: ``sweep`` (text, empty for scenes without a sweep) and each ``sweep:KEY`` as numbers
    (Int64 for whole-number keys, else float64; missing for rows of scenes that do not sweep the key). Read from
    ``results.parquet`` when the run has one, no older than the CSV, and pyarrow is installed (the same table, a
    fiftieth of the size for a large run; an unreadable one is passed over for the CSV), else from ``results.csv``.
    A run of no rows is refused unless ``empty`` (the session reading back the run it writes, interrupted before
    its first row)."""
    run_dir = Path(run_dir)
    results, info = run_dir / RESULTS_FILE, run_dir / RUN_INFO_FILE
    for path in (results, info):
        if not path.is_file():
            raise ResultsError(f"{one_line(path)}: missing (allowed: the output folder of 'simparity run', holding "
                               f"{RESULTS_FILE} and {RUN_INFO_FILE})")
    meta = RunInfo.read(info)
    table = _read_parquet(run_dir / RESULTS_PARQUET_FILE, results, empty)
    if table is None:
        table = _read_csv(results, fixed_columns(meta.schema_version), empty)
    return table, meta


def read_info(run_dir: str | Path) -> RunInfo:
    """``run.json`` of a stored run (its rows at hand: the writer handed them back); ResultsError as :func:`read_run`."""
    return RunInfo.read(Path(run_dir) / RUN_INFO_FILE)


_ALLOWED_CSV = f"the {RESULTS_FILE} 'simparity run' wrote"


def _header(results: Path) -> list[str]:
    """The column names on the first line of ``results`` (ResultsError if there is none to read)."""
    try:
        with open(results, encoding="utf-8", newline="") as handle:
            header = next(csv.reader(handle), None)
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise ResultsError(f"{one_line(results)}: unreadable header: {one_line(err)} (allowed: {_ALLOWED_CSV})") from None
    if not header:
        raise ResultsError(f"{one_line(results)}: empty, not even a header (allowed: {_ALLOWED_CSV})")
    return header


def _read_table(path: Path, text: list[str], numbers: tuple[str, ...], **options) -> pd.DataFrame:
    """A CSV file as pandas reads it, ``numbers`` columns with "", "nan" and "NaN" missing, every other cell as written
    (the status "n/a" is not missing); a ``text`` column pandas took for numbers (every unit "1", every scene named by
    a number) read again as text. Raises what ``pandas.read_csv`` raises."""
    na = {c: list(NOT_A_NUMBER) for c in numbers}
    table = pd.read_csv(path, keep_default_na=False, na_values=na, **options)
    retyped = [c for c in text if c in table.columns and not pd.api.types.is_string_dtype(table[c].dtype)]
    if retyped:  # naming dtype=str for every text column up front costs pandas 3 three times the time
        dtype = options.pop("dtype", {}) | {c: str for c in retyped}
        table = pd.read_csv(path, keep_default_na=False, na_values=na, dtype=dtype, **options)
    return table


def _ends_with_newline(path: Path) -> bool:
    """Whether the file ``path`` is empty or its last byte is a newline (only that byte is read)."""
    with open(path, "rb") as handle:
        if handle.seek(0, os.SEEK_END) == 0:
            return True
        handle.seek(-1, os.SEEK_END)
        return handle.read(1) == b"\n"


def _read_csv(results: Path, fixed: tuple[str, ...], empty: bool = False) -> pd.DataFrame:
    """``results.csv`` typed as :func:`read_run` describes, refused (ResultsError) where it breaks the schema of a
    run of the ``fixed`` columns (schema 1's missing ``flag`` and ``scheme`` then added empty): a header not
    simparity's, a row of another number of fields than the header (cut short, or two rows run together), a last row
    cut mid-line, a cell breaking :func:`reports.run_schema.conformed`. Blank lines are skipped, as pandas does."""
    header = _header(results)
    problem = header_problem(header, fixed)
    if problem:
        raise ResultsError(f"{one_line(results)}: header: {problem}")
    # Where each row is (its line, its fields) is read from the file's bytes only when a row is in doubt.
    content = functools.cache(results.read_bytes)
    scan = functools.cache(lambda: records(content()))
    refused = f"{one_line(results)}: row {{}} (line {{}}): {{}} (allowed: {_ALLOWED_CSV}{{}})"
    if not _ends_with_newline(results) and len(scan().lines) > 1:
        raise ResultsError(refused.format(len(scan().lines) - 1, scan().lines[-1], "cut mid-line, the file does not "
                                          "end with a newline", ", every row ended"))

    def refuse_uneven(doubted: np.ndarray) -> None:  # doubted: records, by index
        counts = scan().fields(content(), doubted)
        uneven = np.flatnonzero(counts != len(header))
        if len(uneven):
            record = int(doubted[uneven[0]])
            raise ResultsError(refused.format(record, scan().lines[record], f"{counts[uneven[0]]} fields where the "
                                              f"header has {len(header)}", ", a value in every column of every row"))

    try:
        # keep_default_na=False: pandas would read the status "n/a" as missing.
        swept = header[len(fixed):]
        table = _read_table(results, [c for c in fixed if c not in NUMERIC_COLUMNS], NUMERIC_COLUMNS,
                            **_EXACT_FLOATS, dtype={c: str for c in swept})
    except (pd.errors.ParserError, UnicodeDecodeError, ValueError) as err:
        refuse_uneven(scan().rows())  # a row of too many fields, named by its row and line
        raise ResultsError(f"{one_line(results)}: not a table of the header's {len(header)} columns: {one_line(err)} "
                           f"(allowed: {_ALLOWED_CSV})") from None
    padded = np.flatnonzero(table[header[-1]].to_numpy() == "") if len(table) else np.zeros(0, np.int64)
    if len(padded):  # pandas pads a row cut short with empty cells: only a row whose last cell is empty may be one
        refuse_uneven(scan().rows()[padded])
    if table.empty and empty:
        return _schema_1_filled(table)
    try:
        table = conformed(table)
        for column in header[len(fixed) + 1:]:
            table[column] = _swept_values(table[column])
    except RowProblem as err:
        raise refuse(err, one_line(results), lambda row: f"row {row + 1} (line {scan().lines[scan().rows()[row]]})",
                     ResultsError) from None
    return _schema_1_filled(table)


def _schema_1_filled(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` with the ``flag`` and ``scheme`` columns of schema 2, empty, where a schema-1 run has none."""
    for column in ("flag", "scheme"):  # schema 1: written before rows carried them
        if column not in table.columns:
            table.insert(table.columns.get_loc("detail") + 1 + (column == "scheme"), column, "")
    return table


def _read_parquet(path: Path, results: Path, empty: bool = False) -> pd.DataFrame | None:
    """``results.parquet`` with its categorical columns as text again; None when there is none, pyarrow is missing,
    it is older than ``results`` (the CSV, edited since it was written) or it cannot be read: then the CSV is read.
    One that is read is held to the schema as the CSV is (ResultsError naming it and the row)."""
    if not path.is_file() or not parquet_available() or path.stat().st_mtime_ns < results.stat().st_mtime_ns:
        return None
    import pyarrow

    try:
        table = pd.read_parquet(path, engine="pyarrow")
    except (OSError, ValueError, pyarrow.ArrowException):
        return None
    problem = header_problem([str(c) for c in table.columns], COLUMNS)
    swept = [c for c in table.columns[len(COLUMNS) + 1:] if not pd.api.types.is_numeric_dtype(table[c].dtype)]
    if problem or swept:
        raise ResultsError(f"{one_line(path)}: " + (f"columns: {problem}" if problem else f"column {swept[0]!r:.80} "
                           f"holds {table[swept[0]].dtype} (allowed: numbers in a {SWEEP_PREFIX}KEY column)"))
    text = pd.Series([""]).dtype  # what the CSV reader gives text columns: object, or str on pandas 3
    table = table.astype({c: text for c in CATEGORICAL_COLUMNS if c in table.columns})
    if table.empty and empty:
        return table
    try:
        return conformed(table)
    except RowProblem as err:
        raise refuse(err, one_line(path), lambda row: f"row {row + 1}", ResultsError) from None


def _write_parquet(table: pd.DataFrame, run_dir: Path) -> Path:
    """``results.parquet`` beside the run's ``results.csv``: ``table`` (as :func:`_read_csv` read the CSV, the same
    table :func:`read_run` reads from it), the :data:`CATEGORICAL_COLUMNS` dictionary-encoded, numbers typed. Written
    to a temporary name and renamed. Returns its path."""
    typed = table.astype({c: "category" for c in CATEGORICAL_COLUMNS if c in table.columns})
    path = run_dir / RESULTS_PARQUET_FILE
    partial = path.with_name(path.name + ".partial")
    typed.to_parquet(partial, engine="pyarrow", index=False)
    os.replace(partial, path)
    return path


def sweep_cells(info: RunInfo) -> tuple[list[str], dict[str, dict[str, object]]]:
    """(the columns a run's sweeps add to :data:`core.model.results.COLUMNS`, {scene name: {column: value}} of each
    swept scene of ``info.scenes``). No columns when no scene was swept; else :data:`core.model.results.SWEEP_COLUMN`
    (the base scene's name), then one column per swept key in the order the scenes first sweep it."""
    columns: list[str] = []
    cells = {}
    for name, scene in info.scenes.items():
        if "sweep" not in scene:
            continue
        sweep = scene["sweep"]
        cells[name] = {SWEEP_COLUMN: sweep["base"]} | {sweep_column(k): v for k, v in sweep["values"].items()}
        columns += [column for column in cells[name] if column not in columns]
    return columns, cells


def _series_frame(series: Sequence[SeriesRecord]) -> pd.DataFrame:
    """The points of ``series`` as rows of :data:`SERIES_COLUMNS`: each record's keys repeated along its points."""
    lengths = [len(record.x) for record in series]
    keys = {column: np.repeat([getattr(record, column) for record in series], lengths)
            for column in SERIES_COLUMNS if column not in ("x", "value")}
    return pd.DataFrame(keys | {"x": np.concatenate([r.x for r in series]),
                                "value": np.concatenate([r.value for r in series])}, columns=list(SERIES_COLUMNS))


class RunWriter:
    """Appends rows to ``results.csv`` and series to ``series.csv.gz`` as they are produced, so nothing
    computed is lost; :meth:`finish` reads the CSV back once, adds ``results.parquet`` (pyarrow installed) and hands
    the table back. ``info`` is written as ``run.json``; a run of swept scenes (``info.scenes`` with a ``sweep``) has
    the sweep columns of :func:`sweep_cells` after the fixed ones, filled from each row's scene."""

    def __init__(self, out_dir: Path, info: RunInfo) -> None:
        self.out_dir, self.info = Path(out_dir), info
        self.out_dir.mkdir(parents=True, exist_ok=True)
        self.results_path = self.out_dir / RESULTS_FILE
        self.series_path = self.out_dir / SERIES_FILE
        (self.out_dir / RESULTS_PARQUET_FILE).unlink(missing_ok=True)  # a new (or resumed) run's CSV starts afresh
        self._sweep_columns, self._sweep_cells = sweep_cells(info)
        pd.DataFrame(columns=list(COLUMNS) + self._sweep_columns).to_csv(self.results_path, index=False)
        pd.DataFrame(columns=list(SERIES_COLUMNS)).to_csv(self.series_path, index=False)
        info.write(self.out_dir / RUN_INFO_FILE)

    def append(self, rows: list[ResultRow], series: Sequence[SeriesRecord] = ()) -> None:
        frame = pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS))
        for column in self._sweep_columns:
            # object cells: an int stays an int, a float is written as its shortest exact text, "" is no value
            frame[column] = pd.Series([self._sweep_cells.get(r.scene, {}).get(column, "") for r in rows], dtype=object)
        frame.to_csv(self.results_path, mode="a", header=False, index=False, float_format="%.17g")
        if series:
            # Each append is one more gzip member; readers (gzip, pandas) read the members as one file.
            points = _series_frame(series)
            points.to_csv(self.series_path, mode="a", header=False, index=False, float_format="%.9g")

    def finish(self) -> pd.DataFrame:
        """The run's rows are all appended (it ended, or was interrupted): ``results.csv`` read back, the one read of
        it a run makes (typed as :func:`read_run` gives it, empty when no row was appended), written as
        ``results.parquet`` when pyarrow is installed, and handed back."""
        table = _read_csv(self.results_path, fixed_columns(self.info.schema_version), empty=True)
        if parquet_available():
            _write_parquet(table, self.out_dir)
        return table


_WHOLE = re.compile(r"-?[0-9]+")


def _swept_values(column: pd.Series) -> pd.Series:
    """A sweep column's text as numbers: Int64 when every value given is whole (a seed, a count), else float64
    (read by Python's float, exact); an empty cell (a row of a scene that does not sweep the key) is missing.
    RowProblem at the first cell that is not a number."""
    given = column[column != ""]
    bad = np.flatnonzero(pd.to_numeric(given, errors="coerce").isna().to_numpy())
    if len(bad):
        row = column.index.get_loc(given.index[bad[0]])
        raise RowProblem(int(row), f"{one_line(column.name)} {given.iloc[bad[0]]!r:.80} is not a number (allowed: the "
                                   "swept key's value, or empty on a row of a scene that does not sweep it)")
    if given.map(lambda text: _WHOLE.fullmatch(text) is not None).all():
        return pd.Series([int(text) if text else pd.NA for text in column], index=column.index, dtype="Int64")
    return pd.Series([float(text) if text else math.nan for text in column], index=column.index, dtype=float)


_ALLOWED_SERIES = f"the {SERIES_FILE} 'simparity run' wrote: gzip-compressed CSV with {','.join(SERIES_COLUMNS)}"


def read_series(run_dir: str | Path) -> pd.DataFrame:
    """The sampled series of a stored run (columns :data:`core.results.SERIES_COLUMNS`, ``dt``, ``x`` and ``value``
    float64); empty for a run stored without them. Raises ResultsError, in one line naming the file and the row or
    column, for a file that is not gzip, not CSV, has other columns, text where a number belongs or a row cut short."""
    path = Path(run_dir) / SERIES_FILE
    if not path.exists():
        return pd.DataFrame(columns=list(SERIES_COLUMNS))
    if not path.is_file():
        raise ResultsError(f"{one_line(path)}: not a regular file (allowed: {_ALLOWED_SERIES}, or no such file: a run "
                           "stored without series)")
    try:
        series = _read_table(path, [c for c in SERIES_COLUMNS if c not in SERIES_NUMBERS], SERIES_NUMBERS,
                             compression="gzip")
    except (pd.errors.ParserError, UnicodeDecodeError, OSError, EOFError, ValueError) as err:
        raise ResultsError(f"{one_line(path)}: unreadable series: {one_line(err)} (allowed: {_ALLOWED_SERIES})") from None
    if tuple(series.columns) != SERIES_COLUMNS:
        raise ResultsError(f"{one_line(path)}: columns {one_line(','.join(map(str, series.columns)), 120)} (allowed: "
                           f"{_ALLOWED_SERIES})")
    try:
        return conformed_series(series)
    except RowProblem as err:
        raise refuse(err, one_line(path), lambda row: f"row {row + 1}", ResultsError) from None
