"""The stored run has one owner (reports/store.py) and a run reads it back once: ``simparity run --check`` with its
report and history gets its table from the writer, never from the folder again."""

import io

import pytest

from simparity.comparisons.cli.main import EXIT_OK, main
from simparity.reports import store

READS_PER_RUN = 1
"""The writer reads ``results.csv`` back once when the run ends (to type it and write ``results.parquet``); the
verdict, the history, the report and the CLI's check are handed that table."""


@pytest.mark.slow
def test_run_check_reads_the_stored_run_once(tmp_path, monkeypatch):
    """Every read of the results table (CSV or Parquet) is counted through a run with --check, a report and history."""
    reads = []

    def counted(reader):
        def read(*args, **kwargs):
            table = reader(*args, **kwargs)
            if table is not None:  # _read_parquet gives None where there is no Parquet to read
                reads.append(reader.__name__)
            return table
        return read

    monkeypatch.setattr(store, "_read_csv", counted(store._read_csv))
    monkeypatch.setattr(store, "_read_parquet", counted(store._read_parquet))
    out = io.StringIO()
    code = main(["run", "lecture-planar-arm", "--engines", "core", "--repeats", "0", "--jobs", "1", "--check",
                 "--out", str(tmp_path / "run"), "--history", str(tmp_path / "history.sqlite")], out=out)
    text = out.getvalue()
    assert code == EXIT_OK and "check passed" in text and (tmp_path / "run" / "report.md").is_file()
    assert len(reads) == READS_PER_RUN, f"the stored run was read {len(reads)} times: {reads}"
