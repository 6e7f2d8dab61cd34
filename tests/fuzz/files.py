"""Small helpers the families share: a copy of the valid run to damage, CSV rows in and out, hostile numbers."""

from __future__ import annotations

import csv
import io
import shutil
from pathlib import Path

import numpy as np

from tests.fuzz.oracle import Base

RUN_FILES = ("results.csv", "run.json", "series.csv.gz")
"""What a stored run is read from (results.parquet, the typed copy, is left out: the CSV is the record)."""

HOSTILE_NUMBERS = ("nan", "inf", "-inf", "1e308", "-1e308", "5e-324", "-1", "0")
"""TOML spellings of the numbers every range check is tried with."""


def copy_run(base: Base, folder: Path, name: str = "run") -> Path:
    """A copy of the valid run's :data:`RUN_FILES` in ``folder / name``."""
    run = folder / name
    run.mkdir(parents=True)
    for file in RUN_FILES:
        shutil.copy2(base.run_dir / file, run / file)
    return run


def read_rows(path: Path) -> tuple[list[str], list[list[str]]]:
    """(header, rows) of a CSV file, every cell as text."""
    rows = list(csv.reader(io.StringIO(path.read_text(encoding="utf-8"))))
    return rows[0], rows[1:]


def write_rows(path: Path, header: list[str], rows: list[list[str]]) -> None:
    text = io.StringIO()
    csv.writer(text, lineterminator="\n").writerows([header, *rows])
    path.write_text(text.getvalue(), encoding="utf-8")


def pick(rng: np.random.Generator, items):
    """One of ``items``, drawn by ``rng``."""
    return items[int(rng.integers(len(items)))]


def seed_of(rng: np.random.Generator) -> int:
    """A seed drawn at generation for the damage a case does when it is built: the same inputs in every process."""
    return int(rng.integers(2**31))
