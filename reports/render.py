"""Writing a stored run's report: ``report.md``, ``report.html`` and ``figures/`` (SVG and PNG),
from its results (``results.parquet`` or ``results.csv``, :func:`reports.store.read_run`), ``series.csv.gz`` and
``run.json`` alone."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from simparity.core.model.results import REPORT_FILE, REPORT_HTML_FILE
from simparity.reports.content import FIGURES_DIR, build
from simparity.reports.html import to_html
from simparity.reports.markdown import to_markdown
from simparity.reports.store import read_info, read_run, read_series
from simparity.reports.tolerance_verdict import ToleranceVerdict


FIGURE_SUFFIXES = (".svg", ".png")
"""What a figure is written as (:func:`reports.figure_writer.save`)."""


def _remove_stale_figures(folder: Path, drawn: set[str]) -> None:
    """Delete the figures in ``folder`` an earlier rendering wrote that this one did not (``drawn``: names)."""
    if folder.is_dir():
        for path in folder.iterdir():
            if path.suffix in FIGURE_SUFFIXES and path.stem not in drawn and path.is_file():
                path.unlink()


def write_report(run_dir: str | Path, verdict: ToleranceVerdict | None = None,
                 table: pd.DataFrame | None = None) -> tuple[Path, Path]:
    """Render the run in ``run_dir``; return the paths of (report.md, report.html).

    ``verdict``: the run held to tolerances (None: it was not); ``table``: its rows when the caller has them (the
    writer handed them back), else read from the folder."""
    run_dir = Path(run_dir)
    table, info = read_run(run_dir) if table is None else (table, read_info(run_dir))
    blocks, svgs = build(table, info, read_series(run_dir), verdict, run_dir)
    _remove_stale_figures(run_dir / FIGURES_DIR, set(svgs))
    markdown, page = run_dir / REPORT_FILE, run_dir / REPORT_HTML_FILE
    markdown.write_text(to_markdown(blocks), encoding="utf-8")
    page.write_text(to_html(blocks, svgs, f"simparity report {info.created_utc}".strip()), encoding="utf-8")
    return markdown, page
