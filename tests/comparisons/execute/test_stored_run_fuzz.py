"""A fuzz pass over stored runs and history databases (issue #39's done-when): a few hundred seeded, damaged inputs,
each refused in one line (ResultsError, HistoryError) or read as the run it still is; never a traceback, and never a
silent pass of damage the schema forbids (every mutation marked ``damaging`` must be refused)."""

import json
import math
import sqlite3

import numpy as np
import pytest

from simparity.comparisons.cli.main import EXIT_USAGE, main
from simparity.comparisons.gate.history import metric_history, record_run, run_table, runs
from simparity.core.model.errors import HistoryError, ResultsError
from simparity.core.model.engine import is_scheme_label
from simparity.core.model.results import COLUMNS, FLAGS, RESULTS_FILE, RUN_INFO_FILE, STATUSES
from simparity.reports.store import read_run
from tests.comparisons.execute.test_stored_run_input import ROWS, _cells, _line, _run

pytestmark = [pytest.mark.slow, pytest.mark.sweep]

SEED = 39
CASES = 200
"""Damaged results.csv files; as many run.json files and half as many history databases follow."""
TOKENS = ["", "nan", "NaN", "inf", "-inf", "1e309", "-0", "abc", "ok", "n/a", "failed", "diverged", "value", "9" * 5001,
          "0x10", "1,2", '"', "\x00", "é", "rk4+", "saturated", "-1", "1e-320"]
"""Cell contents a fuzzer tries: numbers at the edges of float64, statuses, text, a huge integer, separators."""


def _number(text):
    """What a numeric cell holds: a float, NaN for none, or None for text (a 5,001-digit number is text to pandas)."""
    if text in ("", "nan", "NaN"):
        return math.nan
    try:
        return float(text) if len(text) < 400 else None
    except ValueError:
        return None


def _measured(status, value, metric):
    """Whether an ok row may hold ``value``: finite, or +inf on an invariance ratio."""
    return status != "ok" or (value is not None and (math.isfinite(value) or (
        value == math.inf and metric.startswith("invariance_ratio_"))))


def _damaging(column, token, cells):
    """Whether row ``cells`` with ``column`` holding ``token`` breaks the stored run's schema (docs/check.md)."""
    row = dict(zip(COLUMNS, cells)) | {column: token}
    dt, value = _number(row["dt"]), _number(row["value"])
    return (dt is None or not (math.isnan(dt) or (math.isfinite(dt) and dt > 0)) or value is None
            or row["status"] not in STATUSES or not _measured(row["status"], value, row["metric"])
            or row["flag"] not in ("",) + tuple(FLAGS) or not is_scheme_label(row["scheme"])
            or "" in (row["scene"], row["engine"], row["metric"]))


def _mutate(lines, rng):
    """(damaged lines, whether the schema must refuse them)."""
    kind = rng.integers(7)
    lines = list(lines)
    if kind == 0:  # one cell replaced
        row, column = int(rng.integers(1, len(lines))), str(rng.choice(COLUMNS))
        token = str(rng.choice(TOKENS))
        cells = _cells(lines[row])
        damaging = _damaging(column, token, cells)
        cells[COLUMNS.index(column)] = token
        lines[row] = _line(cells)
        return lines, damaging
    if kind == 1:  # cut: mid-line, or after a line (only the header left: no rows)
        text = "".join(lines)
        cut = int(rng.integers(1, len(text) - 1))
        return [text[:cut]], text[cut - 1] != "\n" or cut == len(lines[0])
    if kind == 2:  # a line repeated (the header, or a row: a repeated row is still rows)
        row = int(rng.integers(0, len(lines)))
        return lines[:row + 1] + lines[row:], row == 0
    if kind == 3:  # a column dropped
        drop = int(rng.integers(len(COLUMNS)))
        return [_line([c for k, c in enumerate(_cells(line)) if k != drop]) for line in lines], True
    if kind == 4:  # random bytes inserted
        text = "".join(lines)
        at = int(rng.integers(0, len(text)))
        noise = "".join(chr(int(c)) for c in rng.integers(1, 0x250, size=int(rng.integers(1, 8))))
        return [text[:at] + noise + text[at:]], False  # may land in a detail: then still a run
    if kind == 5:  # only the header
        return lines[:1], True
    row = int(rng.integers(0, len(lines)))  # a line of another separator: one field
    return lines[:row] + [lines[row].replace(",", ";")] + lines[row + 1:], True


def test_fuzzed_results_files_are_refused_in_one_line_or_read_and_damage_never_passes(tmp_path, capsys):
    rng = np.random.default_rng(SEED)
    clean = _run(tmp_path / "clean")
    lines = (clean / RESULTS_FILE).read_text(encoding="utf-8").splitlines(keepends=True)
    info = (clean / RUN_INFO_FILE).read_text(encoding="utf-8")
    refused = silent = 0
    for case in range(CASES):
        damaged, damaging = _mutate(lines, rng)
        run = tmp_path / f"r{case}"
        run.mkdir()
        (run / RUN_INFO_FILE).write_text(info, encoding="utf-8")
        (run / RESULTS_FILE).write_text("".join(damaged), encoding="utf-8")
        try:
            read_run(run)
        except ResultsError as err:
            refused += 1
            assert "\n" not in str(err) and str(err).startswith(str(run)), str(err)
            continue
        silent += damaging
        assert not damaging, (case, "".join(damaged))
        if case % 20 == 0:  # the command on what the reader read: a verdict, or one line
            code = main(["check", str(run), "--allow-unbounded"])
            err = capsys.readouterr().err
            assert "Traceback" not in err and (code != EXIT_USAGE or err.count("\n") == 1), err
    assert silent == 0 and refused > CASES // 2


SHAPES = [None, True, 0, -1, 1.5, math.inf, "text", [], [1, "a"], {}, {"a": 1}, 10 ** 30, "9" * 50]


def _paths(data, prefix=()):
    yield prefix
    if isinstance(data, dict):
        for key, value in data.items():
            yield from _paths(value, prefix + (key,))
    elif isinstance(data, list):
        for index, value in enumerate(data):
            yield from _paths(value, prefix + (index,))


def test_fuzzed_run_json_is_refused_in_one_line_or_read(tmp_path):
    rng = np.random.default_rng(SEED)
    clean = _run(tmp_path / "clean")
    text = (clean / RUN_INFO_FILE).read_text(encoding="utf-8")
    paths = [p for p in _paths(json.loads(text)) if p]
    refused = 0
    for case in range(CASES):
        data = json.loads(text)
        path = paths[int(rng.integers(len(paths)))]
        holder = data
        for key in path[:-1]:
            holder = holder[key]
        holder[path[-1]] = SHAPES[int(rng.integers(len(SHAPES)))]
        raw = json.dumps(data, allow_nan=True)
        if case % 4 == 0:  # and damage to the text itself
            cut = int(rng.integers(1, len(raw)))
            raw = raw[:cut] + "[" * int(rng.integers(0, 200)) + raw[cut:]
        (clean / RUN_INFO_FILE).write_text(raw, encoding="utf-8")
        try:
            read_run(clean)
        except ResultsError as err:
            refused += 1
            assert "\n" not in str(err) and str(err).startswith(str(clean / RUN_INFO_FILE)), str(err)
    assert refused > CASES // 4


def _cell(value):
    return "" if isinstance(value, float) and math.isnan(value) else repr(value) if isinstance(value, float) else value


def _as_stored(column, value):
    """What SQLite keeps of ``value`` in ``column`` as results.csv would spell it: a number in a REAL column, text
    in a TEXT one (numbers turned into text), NULL as none ("" where text may be empty); a blob as text no schema
    allows (it is refused as not text or not a number)."""
    if isinstance(value, bytes):
        return "\x00blob"
    if value is None:
        return "" if column in ("integrator", "detail", "flag", "scheme") else "\x00null" if column not in (
            "dt", "value") else ""
    return repr(float(value)) if isinstance(value, (int, float)) else value


HISTORY_VALUES = [None, 0, 1.5, "text", "ok", "nan", b"\x00\xff", b"", float("inf"), -1, "n/a", 2 ** 62]


def test_fuzzed_history_databases_are_refused_in_one_line_or_read(tmp_path):
    rng = np.random.default_rng(SEED)
    run = _run(tmp_path / "run")
    table, info = read_run(run)
    refused = 0
    for case in range(CASES // 2):
        db = tmp_path / f"h{case}.sqlite"
        record_run(db, run, info, table)
        column = str(rng.choice(("scene", "engine", "integrator", "dt", "metric", "value", "unit", "status", "detail",
                                 "flag", "scheme")))
        value = HISTORY_VALUES[int(rng.integers(len(HISTORY_VALUES)))]
        row = int(rng.integers(1, len(ROWS) + 1))
        with sqlite3.connect(db) as connection:
            connection.execute(f"UPDATE results SET {column} = ? WHERE rowid = ?", (value, row))
        connection.close()
        damaging = _damaging(column, _as_stored(column, value), list(map(_cell, ROWS[row - 1].as_dict().values())))
        try:
            runs(db), run_table(db, 1), metric_history(db)
        except HistoryError as err:
            refused += 1
            assert "\n" not in str(err) and str(err).startswith(str(db)), str(err)
            continue
        assert not damaging, (column, value, row)
    assert refused > 0
