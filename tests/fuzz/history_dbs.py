"""Damaged history databases (issue #39, section 1): the valid run's database with blobs, text and non-finite numbers
where numbers belong, unknown statuses, tables dropped or of other columns, and files that are no database, read
through ``simparity history``, ``simparity check RUN --baseline latest`` and ``simparity check`` (the latest run)."""

from __future__ import annotations

import shutil
import sqlite3
from functools import partial
from pathlib import Path

import numpy as np

from tests.fuzz.files import copy_run, pick, seed_of
from tests.fuzz.oracle import EITHER, FAILS, REFUSED, VALID, Base, Call, Case

DB_NAME = "fuzzed-history.sqlite"
ROUTES = ("history", "baseline latest", "check latest")


def _update(sql: str, values: tuple = ()):
    """Runs ``sql`` (``?`` bound to ``values`` and then to a random rowid of its table) on the database."""

    def damage(db: Path, rng: np.random.Generator) -> None:
        table = "runs" if " runs " in f" {sql} " else "results"
        with sqlite3.connect(db) as connection:
            rowids = [r[0] for r in connection.execute(f"SELECT rowid FROM {table}")]
            if "status = 'ok'" in sql:
                rowids = [r[0] for r in connection.execute(f"SELECT rowid FROM {table} WHERE status = 'ok'")]
            connection.execute(sql, (*values, pick(rng, rowids)))
        connection.close()

    return damage


def _script(sql: str):
    def damage(db: Path, rng: np.random.Generator) -> None:
        with sqlite3.connect(db) as connection:
            connection.executescript(sql)
        connection.close()

    return damage


def _replace(make):
    def damage(db: Path, rng: np.random.Generator) -> None:
        db.unlink()
        make(db, rng)

    return damage


def _another_app(db: Path, rng) -> None:
    with sqlite3.connect(db) as connection:
        connection.execute("CREATE TABLE notes (id INTEGER, body TEXT)")
        connection.execute("INSERT INTO notes VALUES (1, 'not simparity')")
    connection.close()


ROWS = (REFUSED, REFUSED, EITHER)
"""A damaged row of the results table: read by ``history`` and by a baseline, not by ``check`` of the latest run's
folder (which reads the runs table only): refused by the first two, either there."""
NO_ROWS = (FAILS, FAILS, EITHER)
"""A database whose latest run has no rows: nothing to show (``history`` exits 1), a baseline of nothing fails."""

DAMAGES = {
    "text value": (_update("UPDATE results SET value = ? WHERE status = 'ok' AND rowid = ?", ("abc",)), ROWS),
    "blob value": (_update("UPDATE results SET value = ? WHERE status = 'ok' AND rowid = ?", (b"\x00\xff",)), ROWS),
    "text dt": (_update("UPDATE results SET dt = ? WHERE rowid = ?", ("0.01s",)), ROWS),
    "blob dt": (_update("UPDATE results SET dt = ? WHERE rowid = ?", (b"\x01",)), ROWS),
    "inf value with status ok": (_update("UPDATE results SET value = ? WHERE status = 'ok' AND rowid = ?",
                                         (float("inf"),)), ROWS),
    "null value with status ok": (_update("UPDATE results SET value = ? WHERE status = 'ok' AND rowid = ?", (None,)),
                                  ROWS),
    "unknown status": (_update("UPDATE results SET status = ? WHERE rowid = ?", ("passed",)), ROWS),
    "blob scene": (_update("UPDATE results SET scene = ? WHERE rowid = ?", (b"\x00scene",)), ROWS),
    "blob run_dir": (_update("UPDATE runs SET run_dir = ? WHERE rowid = ?", (b"\x00\xfe",)),
                     (EITHER, REFUSED, REFUSED)),
    "integer created_utc": (_update("UPDATE runs SET created_utc = ? WHERE rowid = ?", (12345,)), (EITHER,) * 3),
    "blob profile": (_update("UPDATE runs SET profile = ? WHERE rowid = ?", (b"quick",)), (EITHER, REFUSED, EITHER)),
    "results of another column set": (_script("DROP TABLE results; CREATE TABLE results (a TEXT, b BLOB);"
                                              "INSERT INTO results VALUES ('x', x'00');"), (REFUSED, REFUSED, EITHER)),
    "rows of no recorded run": (_script("UPDATE results SET run_id = 'nowhere';"), NO_ROWS),
    "results table dropped": (_script("DROP TABLE results;"), NO_ROWS),
    "runs table dropped": (_script("DROP TABLE runs;"), (FAILS, FAILS, FAILS)),
    "garbage file": (_replace(lambda db, rng: db.write_bytes(rng.integers(0, 256, 4096, dtype=np.uint8).tobytes())),
                     (REFUSED,) * 3),
    "empty file": (_replace(lambda db, rng: db.write_bytes(b"")), (FAILS,) * 3),
    "a folder": (_replace(lambda db, rng: db.mkdir()), (REFUSED,) * 3),
    "another application's database": (_replace(_another_app), (FAILS,) * 3),
}
"""name -> (damage, exit codes accepted through each of :data:`ROUTES`). FAILS: a database that holds no run to show
or compare with (exit 1 is ``simparity history``'s answer to "no recorded values"; a baseline of nothing must not
pass)."""


def _build(damage, seed: int, route: str, folder: Path, base: Base) -> Call:
    db = folder / DB_NAME
    shutil.copy2(base.history, db)
    damage(db, np.random.default_rng(seed))
    names = (DB_NAME,)
    if route == "history":
        return Call(argv=("history", "--history", str(db)), names=names)
    if route == "baseline latest":
        run = copy_run(base, folder)  # another folder: the recorded run is the latest one before it
        return Call(argv=("check", str(run), "--baseline", "latest", "--history", str(db)), names=names)
    return Call(argv=("check", "--history", str(db)), names=names + ("run.json", "results.csv"))


def cases(rng: np.random.Generator) -> list[Case]:
    found = []
    for name, (damage, accepts) in DAMAGES.items():
        for route, accept in zip(ROUTES, accepts):
            found.append(Case("history_dbs", f"{name} via {route}", partial(_build, damage, seed_of(rng), route),
                              accept))
    for route in ROUTES:
        found.append(Case("history_dbs", f"control: the valid database via {route}",
                          partial(_build, lambda db, rng: None, 0, route), VALID))
    return found
