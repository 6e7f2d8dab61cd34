"""Run history: every stored run also goes into an embedded SQLite database.

The database (default ``simparity-results/history.sqlite``; the ``SIMPARITY_HISTORY``
environment variable or ``--history PATH`` moves it) holds each run's metadata (time, commit,
command, machine, engine versions) and all its rows. ``simparity history`` reads how a metric
moved across runs, and ``simparity check --baseline latest`` compares with the run before.

The CSV and ``run.json`` of a run stay the record: the history is a copy. A database that is
missing, locked beyond :data:`LOCK_TIMEOUT`, unwritable or corrupt raises
:class:`core.errors.HistoryError`, which ``simparity run`` reports on one line before carrying on.
Concurrent writers are serialised by SQLite's own locking (one transaction per run).
"""

from __future__ import annotations

import json
import os
import sqlite3
from pathlib import Path
from typing import cast

import pandas as pd

from simparity.comparisons.common.out_folder import DEFAULT_OUT_ROOT
from simparity.core.model.errors import HistoryError
from simparity.core.model.results import COLUMNS
from simparity.core.model.run_info import RunInfo
from simparity.reports.run_schema import RowProblem, conformed, refuse, require_text

HISTORY_ENV = "SIMPARITY_HISTORY"
DEFAULT_HISTORY = DEFAULT_OUT_ROOT / "history.sqlite"
LOCK_TIMEOUT = 30.0
"""[s] How long a writer waits for another run's transaction before giving up."""

_SCHEMA = """
CREATE TABLE IF NOT EXISTS runs (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    run_dir TEXT NOT NULL,
    created_utc TEXT NOT NULL,
    git_commit TEXT,
    command TEXT,
    machine TEXT,
    engine_versions TEXT,
    profile TEXT DEFAULT ''
);
CREATE TABLE IF NOT EXISTS results (
    run_id INTEGER NOT NULL REFERENCES runs(id),
    scene TEXT, engine TEXT, integrator TEXT, dt REAL, metric TEXT,
    value REAL, unit TEXT, reference TEXT, status TEXT, detail TEXT, flag TEXT, scheme TEXT
);
CREATE INDEX IF NOT EXISTS results_by_metric ON results (scene, engine, metric);
"""


def history_path(option: str | None = None) -> Path:
    """The database path: the option, else ``$SIMPARITY_HISTORY``, else the default."""
    return Path(option or os.environ.get(HISTORY_ENV) or DEFAULT_HISTORY)


def check_usable(path: Path) -> None:
    """Raise :class:`HistoryError` (one line) when ``path`` exists and is no history database this simparity can
    record in (a folder, a text file, a damaged database): said before a run, never after it."""
    if path.exists() or path.is_symlink():
        if not path.is_file():
            raise HistoryError(f"{path}: not a regular file (allowed: an SQLite file simparity wrote, or a new path)")
        _connect(path, create=False).close()


def _connect(path: Path, create: bool) -> sqlite3.Connection:
    if not create and not path.is_file():
        raise HistoryError(f"{path}: no run history here (allowed: a database 'simparity run' wrote; --history PATH or $SIMPARITY_HISTORY points at it)")
    try:
        if create:
            path.parent.mkdir(parents=True, exist_ok=True)
        connection = sqlite3.connect(path, timeout=LOCK_TIMEOUT)
        connection.executescript(_SCHEMA)
        _add_missing_columns(connection)
        return connection
    except (sqlite3.Error, OSError) as err:
        raise HistoryError(f"{path}: run history unusable: {type(err).__name__}: {err} (allowed: an SQLite file simparity wrote, or a new path)") from None


def _add_missing_columns(connection: sqlite3.Connection) -> None:
    """Bring a database an older simparity wrote up to this one's columns: a results column it lacks (the
    ``flag`` and ``scheme`` of schema 2) is added, empty for the runs recorded before."""
    present = {row[1] for row in connection.execute("PRAGMA table_info(results)")}
    for column in (c for c in COLUMNS if c not in present):
        with connection:
            connection.execute(f"ALTER TABLE results ADD COLUMN {column} TEXT DEFAULT ''")
    if "profile" not in {row[1] for row in connection.execute("PRAGMA table_info(runs)")}:
        with connection:  # the runs' profile (schema 3): unknown ("") for the runs recorded before
            connection.execute("ALTER TABLE runs ADD COLUMN profile TEXT DEFAULT ''")


def record_run(path: Path, run_dir: Path, info: RunInfo, table: pd.DataFrame) -> int:
    """Store one run (its ``run.json`` contents and rows) in one transaction; returns its id."""
    connection = _connect(path, create=True)
    try:
        with connection:
            cursor = connection.execute(
                "INSERT INTO runs (run_dir, created_utc, git_commit, command, machine, engine_versions, profile) "
                "VALUES (?, ?, ?, ?, ?, ?, ?)",
                (str(run_dir), info.created_utc, info.git_commit, info.command,
                 json.dumps(info.machine), json.dumps(info.engine_versions), info.profile))
            run_id = cast(int, cursor.lastrowid)  # set by the INSERT just made
            records = [(run_id, *(None if pd.isna(v) else v for v in row))
                       for row in table[list(COLUMNS)].itertuples(index=False, name=None)]
            connection.executemany(f"INSERT INTO results (run_id, {', '.join(COLUMNS)}) "
                                   f"VALUES ({', '.join('?' * (len(COLUMNS) + 1))})", records)
        return run_id
    except (sqlite3.Error, OSError) as err:
        raise HistoryError(f"{path}: could not record the run: {type(err).__name__}: {err} (allowed: a writable SQLite file simparity wrote)") from None
    finally:
        connection.close()


def _query(path: Path, sql: str, params=()) -> pd.DataFrame:
    """The result of one read-only query of an existing history database (HistoryError if unreadable)."""
    connection = _connect(path, create=False)
    try:
        return pd.read_sql_query(sql, connection, params=params)
    except (sqlite3.Error, pd.errors.DatabaseError) as err:
        raise HistoryError(f"{path}: unreadable run history: {err} (allowed: an SQLite file simparity wrote)") from None
    finally:
        connection.close()


_OPTIONAL_TEXT = ("integrator", "detail", "flag", "scheme", "git_commit", "command", "profile")
"""Text columns a database may leave NULL (read as ""): a kinematics scene's integrator, the runs' columns added
later."""


def _conformed(path: Path, table: pd.DataFrame, row_name, text: tuple[str, ...] = ()) -> pd.DataFrame:
    """``table`` read from the history held to the stored run's schema (:mod:`reports.run_schema`): the results'
    columns it has, and ``text`` columns holding text; HistoryError naming the database and ``row_name(row)``."""
    table = table.fillna({c: "" for c in _OPTIONAL_TEXT if c in table.columns})
    try:
        require_text(table, text)
        return conformed(table) if "status" in table.columns and not table.empty else table
    except RowProblem as err:
        raise refuse(err, f"{path}: run history", row_name, HistoryError) from None


def runs(path: Path) -> pd.DataFrame:
    """The recorded runs, oldest first: id, run_dir, created_utc, git_commit, command, profile ("": unknown)."""
    recorded = _query(path, "SELECT id, run_dir, created_utc, git_commit, command, profile FROM runs ORDER BY id")
    if len(recorded) and not pd.api.types.is_integer_dtype(recorded["id"].dtype):  # an id is SQLite's rowid: nothing else reads so
        raise HistoryError(f"{path}: run history: runs.id holds {recorded['id'].dtype} (allowed: whole numbers)")
    return _conformed(path, recorded, lambda row: f"run #{recorded['id'].iloc[row]}",
                      ("run_dir", "created_utc", "git_commit", "command", "profile"))


def run_table(path: Path, run_id: int) -> pd.DataFrame:
    """The rows of one recorded run, in the columns of ``results.csv`` (``dt`` and ``value`` float64); HistoryError
    for a run of no rows or one that breaks the stored run's schema."""
    table = _query(path, f"SELECT {', '.join(COLUMNS)} FROM results WHERE run_id = ?", (run_id,))
    if table.empty:
        raise HistoryError(f"{path}: run #{run_id} has no rows (allowed: a run recorded with its rows, as 'simparity "
                           "run' records it)")
    return _conformed(path, table, lambda row: f"run #{run_id}, row {row + 1}")


def latest_before(path: Path, run_dir: Path | None = None, profile: str = "") -> tuple[int, str]:
    """(id, folder) of the latest recorded run other than ``run_dir`` (of ``profile``, when given: a run recorded
    without one counts as any); HistoryError if there is none."""
    recorded = runs(path)
    if run_dir is not None:
        recorded = recorded[recorded["run_dir"] != str(run_dir)]
    if profile:
        recorded = recorded[recorded["profile"].fillna("").isin(["", profile])]
    if recorded.empty:
        of = f" of the {profile} profile" if profile else ""
        raise HistoryError(f"{path}: no earlier run{of} recorded to compare with (allowed: --baseline DIR of a "
                           "stored run)")
    last = recorded.iloc[-1]
    return int(last["id"]), str(last["run_dir"])


def metric_history(path: Path, scene: str | None = None, engine: str | None = None,
                   metric: str | None = None) -> pd.DataFrame:
    """One row per scene x engine x integrator x dt x metric, one column per run (``#id created``)."""
    where, params = [], []
    for column, value in (("scene", scene), ("engine", engine), ("metric", metric)):
        if value is not None:
            where.append(f"r.{column} = ?")
            params.append(value)
    query = ("SELECT runs.id AS run, runs.created_utc AS created, r.scene, r.engine, r.integrator, r.dt, "
             "r.metric, r.value, r.status FROM results r JOIN runs ON runs.id = r.run_id"
             + (" WHERE " + " AND ".join(where) if where else "") + " ORDER BY runs.id")
    long = _query(path, query, params)
    if long.empty:
        return long
    long = _conformed(path, long, lambda row: f"run #{long['run'].iloc[row]}", ("created",))
    long["run"] = "#" + long["run"].astype(str) + " " + long["created"]
    long["dt"] = long["dt"].map(lambda d: "" if pd.isna(d) else f"{d:g}")
    long["shown"] = [f"{v:.6g}" if s == "ok" else s for v, s in zip(long["value"], long["status"])]
    return long.pivot_table(index=["scene", "engine", "integrator", "dt", "metric"], columns="run", values="shown",
                            aggfunc="last", sort=False).reset_index()


def recorded_scenes(path: Path) -> list[str]:
    """The scenes of which the history holds rows, sorted."""
    return sorted(_query(path, "SELECT DISTINCT scene FROM results")["scene"].dropna())
