"""A stored run is input (issue #39): results.csv, results.parquet, run.json, series.csv.gz and the history database
are held to one schema by one reader; what does not conform is refused in one line naming the file and the row,
column or key (exit 2), never a traceback and never a silent pass; a check that checks nothing fails."""

import csv
import dataclasses
import gzip
import io
import json
import math
import sqlite3

import pandas as pd
import pytest

from simparity.comparisons.cli.main import EXIT_FAILED_CASES, EXIT_USAGE, main
from simparity.comparisons.pipeline.run_info import describe_run
from simparity.reports.store import RunWriter
from simparity.comparisons.gate.check import check_table, compare_with_baseline
from simparity.comparisons.gate.history import record_run
from simparity.core.model import run_info
from simparity.core.model.errors import ResultsError
from simparity.core.model.json_input import MAX_INTEGER_DIGITS, MAX_JSON_DEPTH
from simparity.core.model.results import (
    COLUMNS,
    RESULTS_FILE,
    RESULTS_PARQUET_FILE,
    RUN_INFO_FILE,
    SERIES_FILE,
    ResultRow,
    SeriesRecord,
)
from simparity.reports import store
from simparity.reports.store import read_run, read_series
from tests.helpers import builtin

SCENE = "lecture-projectile"
ROWS = [
    ResultRow(SCENE, "core", "rk4", 0.01, "position_error_max", 1e-3, "m", "analytic:exact", "ok", "", "", "rk4"),
    ResultRow(SCENE, "mujoco", "rk4", 0.01, "position_error_max", 2e-3, "m", "analytic:exact", "ok", "a, \"b\"", "",
              "rk4"),
    ResultRow(SCENE, "core", "rk4", 0.01, "energy_drift_max", math.nan, "1", "analytic:exact", "n/a", "saturated",
              "saturated", "rk4"),
    ResultRow(SCENE, "core", "", math.nan, "order_position", math.nan, "1", "analytic:exact", "n/a", "no fit", "", ""),
    ResultRow(SCENE, "mujoco", "euler", 0.01, "position_error_max", math.inf, "m", "analytic:exact", "diverged",
              "blew up", "", "engine_euler"),
    ResultRow(SCENE, "mujoco", "euler", 0.01, "time_per_step", 1e-6, "s", "analytic:exact", "failed", "raised", "",
              "engine_euler"),
    ResultRow(SCENE, "core", "rk4", 0.01, "invariance_ratio_translate", math.inf, "1", "analytic:exact", "ok",
              "a difference where none is allowed", "", "rk4"),
]
"""A run of each status, a NaN dt, non-finite values where a status allows them (diverged; +inf on an ok invariance
ratio) and a quoted detail."""


def _run(folder, rows=ROWS, series=()):
    writer = RunWriter(folder, describe_run([], "simparity run", [builtin(SCENE)]))
    writer.append(rows, series)
    return folder


@pytest.fixture
def run(tmp_path):
    return _run(tmp_path / "run")


def _lines(run):
    return (run / RESULTS_FILE).read_text(encoding="utf-8").splitlines(keepends=True)


def _write(run, lines):
    (run / RESULTS_FILE).write_text("".join(lines), encoding="utf-8")


def _cells(line):
    return next(csv.reader([line]))


def _line(cells):
    text = io.StringIO()
    csv.writer(text, lineterminator="\n").writerow(cells)
    return text.getvalue()


def _replace_cell(run, row, column, text):
    """Row ``row`` (from 1; its line is row + 1) with ``column`` holding ``text``."""
    lines = _lines(run)
    cells = _cells(lines[row])
    cells[COLUMNS.index(column)] = text
    lines[row] = _line(cells)
    _write(run, lines)


def _refusal(run, capsys, *argv):
    """read_run's one-line ResultsError, and `simparity check RUN` on the same run: exit 2, the same one line."""
    with pytest.raises(ResultsError) as caught:
        read_run(run)
    message = str(caught.value)
    assert "\n" not in message
    capsys.readouterr()
    assert main(["check", str(run), *argv]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and message in err
    return message


def test_a_run_written_by_simparity_reads_back_exactly(run):
    table, _ = read_run(run)
    assert list(table.columns) == list(COLUMNS) and len(table) == len(ROWS)
    assert table["value"].dtype == float and table["dt"].dtype == float
    expected = pd.DataFrame([r.as_dict() for r in ROWS], columns=list(COLUMNS))
    for column in COLUMNS:
        assert list(table[column].astype(object)) == pytest.approx(list(expected[column]), nan_ok=True, rel=0) \
            if column in ("dt", "value") else list(table[column]) == list(expected[column]), column


def _drop_column(lines, column):
    index = COLUMNS.index(column)
    return [_line([c for k, c in enumerate(_cells(line)) if k != index]) for line in lines]


HEADERS = {
    "scheme column dropped": (lambda lines: _drop_column(lines, "scheme"), "header: no column 'scheme'"),
    "value column dropped": (lambda lines: _drop_column(lines, "value"), "header: no column 'value'"),
    "extra column": (lambda lines: [line.rstrip("\n") + (",extra\n" if k == 0 else ",1\n")
                                    for k, line in enumerate(lines)], "column 'extra' is not one of simparity's"),
    "columns reordered": (lambda lines: [_line([c[0], c[3], c[2], c[1]] + c[4:]) for c in map(_cells, lines)],
                          "column 2 is 'dt' where 'engine' belongs"),
    "a column twice": (lambda lines: [line.rstrip("\n") + (",unit\n" if k == 0 else ",m\n")
                                      for k, line in enumerate(lines)], "column 'unit' appears 2 times"),
    "no header": (lambda lines: lines[1:], "header: no column 'scene'"),
    "not text": (lambda lines: ["\x00\x01\x02,\xff\n"] + lines[1:], "header: no column 'scene'"),
}


@pytest.mark.parametrize("name", HEADERS)
def test_a_header_that_is_not_simparity_s_is_refused(run, capsys, name):
    damage, expected = HEADERS[name]
    _write(run, damage(_lines(run)))
    message = _refusal(run, capsys)
    assert message.startswith(f"{run / RESULTS_FILE}: ") and expected in message, message
    assert "allowed: the columns scene,engine,integrator,dt,metric,value,unit,reference,status,detail,flag,scheme, " \
           "then for swept scenes sweep and sweep:KEY columns" in message


CELLS = {
    "text in value": ((1, "value", "abc"), "row 1 (line 2): value 'abc' is not a number"),
    "text in dt": ((3, "dt", "0.01s"), "row 3 (line 4): dt '0.01s' is not a number"),
    "dt negative": ((1, "dt", "-0.01"), "row 1 (line 2): dt -0.01 (allowed: a time step > 0 [s]"),
    "nan on an ok row": ((1, "value", "nan"), "row 1 (line 2): status ok with value nan"),
    "-inf on an ok row": ((1, "value", "-inf"), "row 1 (line 2): status ok with value -inf"),
    "+inf on an ok row of an error": ((1, "value", "inf"), "row 1 (line 2): status ok with value inf"),
    "a status not simparity's": ((1, "status", "passed"), "row 1 (line 2): status 'passed' (allowed: ok, n/a, failed,"),
    "an empty status": ((4, "status", ""), "row 4 (line 5): status '' (allowed: ok"),
    "a flag not simparity's": ((3, "flag", "fine"), "row 3 (line 4): flag 'fine' (allowed: none, or saturated"),
    "a scheme not a kind": ((1, "scheme", "rk"), "row 1 (line 2): scheme 'rk' (allowed: none, or kinds of scheme"),
    "an empty engine": ((1, "engine", ""), "row 1 (line 2): empty engine"),
}


@pytest.mark.parametrize("name", CELLS)
def test_a_cell_that_breaks_the_schema_is_refused_naming_row_line_and_column(run, capsys, name):
    (row, column, text), expected = CELLS[name]
    _replace_cell(run, row, column, text)
    message = _refusal(run, capsys)
    assert message.startswith(str(run / RESULTS_FILE) + ": ") and expected in message, message


ROW_DAMAGE = {
    "a repeated header row": (lambda lines: lines[:3] + [lines[0]] + lines[3:], "row 3 (line 4): repeats the header"),
    "the last row cut mid-line": (lambda lines: lines[:-1] + [lines[-1][:25]], f"row {len(ROWS)} (line "
                                                                                f"{len(ROWS) + 1}): "),
    "the last row cut after a field": (lambda lines: lines[:-1] + [lines[-1][:lines[-1].index(",ok,") + 4]],
                                       "cut mid-line"),
    "a row short of fields": (lambda lines: lines[:1] + [_line(_cells(lines[1])[:-2])] + lines[2:],
                              "row 1 (line 2): 10 fields where the header has 12"),
    "a row with a field too many": (lambda lines: lines[:2] + [lines[2].rstrip("\n") + ",x\n"] + lines[3:],
                                    "row 2 (line 3): 13 fields where the header has 12"),
    "a quoted detail never closed": (lambda lines: lines[:-1] + [lines[-1].replace("a difference", '"a difference')],
                                     f"row {len(ROWS)} (line {len(ROWS) + 1}): "),
    "the empty file": (lambda lines: [], "empty, not even a header"),
    "only the header": (lambda lines: lines[:1], "no rows (allowed: a run with at least one row"),
}


@pytest.mark.parametrize("name", ROW_DAMAGE)
def test_damaged_rows_are_refused_naming_the_row(run, capsys, name):
    damage, expected = ROW_DAMAGE[name]
    _write(run, damage(_lines(run)))
    message = _refusal(run, capsys)
    assert message.startswith(str(run / RESULTS_FILE) + ": ") and expected in message, message


def test_line_numbers_count_the_newlines_inside_quoted_details_and_blank_lines(tmp_path, capsys):
    run = _run(tmp_path / "run", [dataclasses.replace(ROWS[0], detail="two\nlines")] + ROWS[1:])
    _replace_cell(run, 4, "status", "bogus")  # row 3 of the file's lines: the detail took two
    assert "row 3 (line 5): status 'bogus'" in _refusal(run, capsys)
    lines = _lines(run)
    _write(run, lines[:2] + ["\n"] + lines[2:])  # a blank line is skipped (as pandas does), and counted
    assert "row 3 (line 6): status 'bogus'" in _refusal(run, capsys)
    _write(run, lines[:2] + ["\n"] + lines[2:4] + [lines[4].replace("bogus", "n/a")] + lines[5:])
    assert len(read_run(run)[0]) == len(ROWS)


def test_a_schema_1_run_reads_without_flag_and_scheme_but_a_schema_2_run_needs_them(run, capsys):
    lines = _drop_column(_drop_column(_lines(run), "scheme"), "flag")
    _write(run, lines)
    info = json.loads((run / RUN_INFO_FILE).read_text())
    (run / RUN_INFO_FILE).write_text(json.dumps(info | {"schema_version": 1}))
    table, _ = read_run(run)
    assert list(table.columns) == list(COLUMNS) and set(table["scheme"]) == {""}
    (run / RUN_INFO_FILE).write_text(json.dumps(info))
    assert "no column 'flag'" in _refusal(run, capsys)


def test_a_damaged_parquet_is_refused_as_the_csv_is(run, capsys):
    table, _ = read_run(run)
    table.loc[0, "status"] = "passed"
    table.to_parquet(run / RESULTS_PARQUET_FILE, index=False)
    message = _refusal(run, capsys)
    assert message.startswith(str(run / RESULTS_PARQUET_FILE)) and "row 1: status 'passed'" in message


def _info(run):
    return json.loads((run / RUN_INFO_FILE).read_text())


RUN_INFOS = {
    "nested 100,000 deep": ('{"schema_version": 2, "scenes": ' + "[" * 100_000 + "]" * 100_000 + "}",
                            f"nested 100,001 levels deep (allowed: at most {MAX_JSON_DEPTH}"),
    "a 5,001-digit integer": ('{"schema_version": 2, "peak_memory": {"this_process_bytes": ' + "9" * 5001 + "}}",
                              f"an integer of 5,001 digits (allowed: at most {MAX_INTEGER_DIGITS})"),
    "a scenes entry that is text": (lambda info: info | {"scenes": {SCENE: "dynamics"}},
                                    f"scenes.{SCENE}: text 'dynamics' (allowed: a table of what the run recorded"),
    "theoretical orders as text": (lambda info: info | {"theoretical_orders": {"core": {"rk4": "4"}}},
                                   "theoretical_orders.core.rk4: text '4' (allowed: a finite number > 0)"),
    "a theoretical order of -1": (lambda info: info | {"theoretical_orders": {"core": {"rk4": -1}}},
                                  "theoretical_orders.core.rk4: a number -1 (allowed: a finite number > 0)"),
    "a variant that is not a pair": (lambda info: info | {"integrator_variants": {"core": {"rk4": ["rk4"]}}},
                                     "integrator_variants.core.rk4: a list ['rk4'] (allowed: a list of 2 text)"),
    "bodies as a boolean": (lambda info: info | {"scenes": {SCENE: info["scenes"][SCENE] | {"bodies": True}}},
                            f"scenes.{SCENE}.bodies: a boolean True (allowed: a whole number >= 0)"),
    "suites holding a number": (lambda info: info | {"scenes": {SCENE: info["scenes"][SCENE] | {"suites": [1]}}},
                                f"scenes.{SCENE}.suites[0]: a number 1 (allowed: text)"),
    "schema version as a boolean": (lambda info: info | {"schema_version": True}, "schema_version: a boolean True"),
    "a list": ("[]", "a list [] (allowed: a table (JSON object)"),
    "not JSON": ("{'single': 'quotes'}", "not JSON: "),
    "not UTF-8": (b"{\"command\": \"\xff\"}", "unreadable: 'utf-8' codec can't decode"),
    "a NaN literal": ('{"schema_version": 2, "machine": {"cpus": NaN}}', "NaN, which is not JSON"),
    "a key given twice": ('{"schema_version": 99, "schema_version": 2}', "the key 'schema_version' given twice"),
    "a lone surrogate escape": ('{"schema_version": 2, "engine_versions": {"core": "\\udcff 1.0"}}',
                                "a lone surrogate escape"),
    "a headline no report ranks by": (
        lambda info: info | {"scenes": {SCENE: info["scenes"][SCENE] | {"headline_metric": "nope"}}},
        f"scenes.{SCENE}.headline_metric: text 'nope' (allowed: one of position_error_max"),
}


@pytest.mark.parametrize("name", RUN_INFOS)
def test_a_run_json_that_is_not_a_run_s_information_is_refused_naming_the_key(run, capsys, name):
    content, expected = RUN_INFOS[name]
    path = run / RUN_INFO_FILE
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content if isinstance(content, str) else json.dumps(content(_info(run))), encoding="utf-8")
    message = _refusal(run, capsys)
    assert message.startswith(f"{path}: ") and expected in message, message


def test_a_run_json_past_its_size_is_refused_before_it_is_parsed(run, capsys, monkeypatch):
    monkeypatch.setattr(run_info, "MAX_RUN_INFO_BYTES", 100)
    assert "more than 100 bytes" in _refusal(run, capsys)


def _series_run(tmp_path):
    record = SeriesRecord(SCENE, "core", "rk4", 0.01, "energy_change", "1", [0.0, 0.5, 1.0], [0.0, 1e-9, 2e-9])
    return _run(tmp_path / "run", ROWS, [record])


SERIES = {
    "empty": (b"", "unreadable series: "),
    "not gzip": (b"scene,engine\n", "unreadable series: "),
    "cut short": (None, "unreadable series: "),
    "other columns": (gzip.compress(b"scene,engine,x\ns,core,1\n"), "columns scene,engine,x (allowed: the "),
    "text where a number belongs": (gzip.compress(b"scene,engine,integrator,dt,quantity,unit,x,value\n"
                                                  b"s,core,rk4,0.01,energy_change,1,0.5,big\n"),
                                    "row 1: value 'big' is not a number"),
    "a row short of fields": (gzip.compress(b"scene,engine,integrator,dt,quantity,unit,x,value\ns,core,rk4\n"),
                              "row 1: quantity '' (allowed: energy_change"),
}


@pytest.mark.parametrize("name", SERIES)
def test_a_damaged_series_file_is_refused_in_one_line(tmp_path, capsys, name):
    run = _series_run(tmp_path)
    series = read_series(run)
    assert list(series["value"]) == [0.0, 1e-9, 2e-9] and series["x"].dtype == float
    content, expected = SERIES[name]
    path = run / SERIES_FILE
    path.write_bytes(path.read_bytes()[:-9] if content is None else content)
    with pytest.raises(ResultsError) as caught:
        read_series(run)
    message = str(caught.value)
    assert "\n" not in message and message.startswith(f"{path}: ") and expected in message, message
    capsys.readouterr()
    assert main(["report", str(run)]) == EXIT_USAGE  # the report draws the series: it needs them whole
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err


def _history(tmp_path, run):
    db = tmp_path / "history.sqlite"
    table, info = read_run(run)
    record_run(db, run.resolve(), info, table)
    return db


HISTORIES = {
    "a blob where a value belongs": ("UPDATE results SET value = X'00ff' WHERE rowid = 1",
                                     "run history: run #1, row 1: value b'\\x00\\xff' is not a number"),
    "text where a dt belongs": ("UPDATE results SET dt = 'soon' WHERE rowid = 2",
                                "run history: run #1, row 2: dt 'soon' is not a number"),
    "a blob where a status belongs": ("UPDATE results SET status = X'6f6b' WHERE rowid = 1",
                                      "run history: run #1, row 1: status b'ok' is not text"),
    "a status not simparity's": ("UPDATE results SET status = 'fine' WHERE rowid = 1",
                                 "run #1, row 1: status 'fine' (allowed: ok"),
    "a blob where a time belongs": ("UPDATE runs SET created_utc = X'01'", "run #1: created"),
    "a run without rows": ("DELETE FROM results", "run #1 has no rows"),
    "no runs table columns": ("ALTER TABLE runs DROP COLUMN command", "unreadable run history"),
    "no value column": ("ALTER TABLE results DROP COLUMN value", "run #1, row 1: status ok with value nan"),
    "no runs table": ("DROP TABLE runs", "no earlier run"),
}


@pytest.mark.parametrize("name", HISTORIES)
def test_a_damaged_history_is_refused_in_one_line(tmp_path, capsys, name):
    run = _run(tmp_path / "run")
    db = _history(tmp_path, run)
    sql, expected = HISTORIES[name]
    with sqlite3.connect(db) as connection:
        connection.execute(sql)
    connection.close()
    other = _run(tmp_path / "now")
    capsys.readouterr()
    history = main(["history", "--history", str(db)])
    history_err = capsys.readouterr().err
    code = main(["check", str(other), "--baseline", "latest", "--history", str(db)])
    err = capsys.readouterr().err
    assert code == EXIT_USAGE and err.count("\n") == 1 and str(db) in err and expected in err, err
    assert history_err.count("\n") <= 1 and "Traceback" not in history_err


@pytest.mark.parametrize("content", [b"not a database at all, just text" * 100, b"SQLite format 3\x00" + b"\x00" * 90])
def test_a_file_that_is_not_a_history_database_is_refused_in_one_line(tmp_path, capsys, content):
    db = tmp_path / "history.sqlite"
    db.write_bytes(content)
    run = _run(tmp_path / "run")
    capsys.readouterr()
    for argv in (["history", "--history", str(db)], ["check", str(run), "--baseline", "latest", "--history", str(db)]):
        code = main(argv)
        err = capsys.readouterr().err
        assert code == EXIT_USAGE and err.count("\n") == 1 and str(db) in err, (argv, err)


def test_a_check_that_checks_nothing_fails(run, capsys, tmp_path):
    """No row held to any bound: not "check passed: 0 metrics checked" but a failed check (exit 1) saying why; a run
    of no rows never gets that far (exit 2, above)."""
    table, _ = read_run(run)
    assert not check_table(table, [], cross_checked=False).passed
    assert "0 metrics checked" in check_table(table, [], cross_checked=False).nothing_checked
    tolerances = tmp_path / "core-only.toml"
    tolerances.write_text('extends = "none"\n[[bound]]\nengine = "core"\nmetric = "*"\nstatus = ["ok", "n/a", "failed", '
                          '"diverged"]\nreason = "every core row ran"\n', encoding="utf-8")
    capsys.readouterr()
    code = main(["check", str(run), "--tolerances", str(tolerances), "--check-engines", "mujoco",
                 "--allow-unbounded"])
    out = capsys.readouterr().out
    assert code == EXIT_FAILED_CASES and "nothing checked: 0 metrics checked" in out and "check FAILED" in out, out


def test_a_baseline_that_compares_nothing_fails(tmp_path, capsys):
    run = _run(tmp_path / "run")
    other = [ResultRow("elsewhere", *list(row.as_dict().values())[1:]) for row in ROWS]
    baseline = _run(tmp_path / "baseline", other)
    table, _ = read_run(run)
    diff = compare_with_baseline(table, read_run(baseline)[0])
    assert diff.blocking and "0 rows compared" in diff.nothing_compared
    assert not compare_with_baseline(table, table).blocking
    capsys.readouterr()
    code = main(["check", str(run), "--baseline", str(baseline), "--allow-unbounded"])
    out = capsys.readouterr().out
    assert code == EXIT_FAILED_CASES and "nothing checked: 0 rows compared" in out, out
    _write(baseline, _lines(baseline)[:1])  # a baseline of no rows: damaged input
    assert main(["check", str(run), "--baseline", str(baseline)]) == EXIT_USAGE
    assert "no rows" in capsys.readouterr().err


def test_a_session_reads_back_a_run_interrupted_before_its_first_row(tmp_path):
    run = _run(tmp_path / "run", [])
    assert read_run(run, empty=True)[0].empty
    with pytest.raises(ResultsError, match="no rows"):
        read_run(run)
    writer = RunWriter(run, describe_run([], "simparity run", [builtin(SCENE)]))
    assert writer.finish().empty and (run / store.RESULTS_PARQUET_FILE).is_file()  # the typed copy of no rows
