"""Reading a stored run."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd

from simparity.core.errors import ResultsError, one_line
from simparity.core.results import COLUMNS, RESULTS_FILE, RUN_INFO_FILE, SCHEMA_VERSION, SERIES_COLUMNS, SERIES_FILE


# pandas < 3 parses floats inexactly unless asked; pandas 3 is exact and deprecates the option.
_EXACT_FLOATS = {"float_precision": "round_trip"} if int(pd.__version__.split(".")[0]) < 3 else {}


def read_run(run_dir: str | Path) -> tuple[pd.DataFrame, dict]:
    """(results table, run information) of a stored run; raises ResultsError if unusable."""
    run_dir = Path(run_dir)
    results, info = run_dir / RESULTS_FILE, run_dir / RUN_INFO_FILE
    for path in (results, info):
        if not path.is_file():
            raise ResultsError(f"{one_line(path)}: missing (allowed: the output folder of 'simparity run', holding "
                               f"{RESULTS_FILE} and {RUN_INFO_FILE})")
    try:
        meta = json.loads(info.read_text(encoding="utf-8"))
        # keep_default_na=False: pandas would read the status "n/a" as missing.
        table = pd.read_csv(results, keep_default_na=False, **_EXACT_FLOATS,
                            na_values={"value": ["", "nan", "NaN"], "dt": ["", "nan", "NaN"]})
    except (json.JSONDecodeError, pd.errors.ParserError, UnicodeDecodeError) as err:
        raise ResultsError(f"{one_line(run_dir)}: unreadable stored run: {one_line(err)} (allowed: a folder written by "
                           "'simparity run')") from None
    if meta.get("schema_version") != SCHEMA_VERSION:
        raise ResultsError(f"{info}: schema_version {meta.get('schema_version')!r:.20} (allowed: {SCHEMA_VERSION}, the "
                           "version this simparity reads)")
    missing = [c for c in COLUMNS if c not in table.columns]
    if missing:
        raise ResultsError(f"{results}: missing columns {missing} (allowed: a results.csv with {', '.join(COLUMNS)})")
    return table, meta


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
