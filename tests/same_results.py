"""Whether two stored runs have the same results, timing aside: ``python -m tests.same_results BEFORE AFTER``.

The proof that a change which must not move a number did not (a redesign, a move of modules): run the same
suites before and after it (``simparity run --suite S --quick --out DIR`` at each commit) and compare. Every
column of ``results.csv`` must be equal, row for row and in the same order, except the value and detail of the
timing metrics (``time_per_*``: wall time), and where a detail names a file an engine read from an installed package
(``.../site-packages/pybullet_data/...``) or a built-in scene's file in simparity's checkout: two environments install
them in two places. The sampled series
(``series.csv.gz``) must be equal too, every value as written. Prints one line per difference (at most :data:`SHOWN`) and a count;
exit 0 when the runs are the same, 1 when not.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import pandas as pd

from simparity.core.model.results import RESULTS_FILE, SERIES_FILE

TIMING_PREFIX = "time_per_"
"""Metrics measuring wall time: their value and detail differ between any two runs."""

INSTALLED = re.compile(r"\S*/site-packages/")
"""Where an environment installed a package (a detail names the robot file an engine read)."""

CHECKOUT = re.compile(r"\S*?/(?=comparisons/scenes/)")
"""Where simparity itself lives (a detail names a built-in scene's URDF file): two checkouts, two places."""

SHOWN = 20
"""Differences printed at most (the count covers all)."""


def _read(run_dir: Path) -> pd.DataFrame:
    # Every column as text: numbers are compared as written (repr round-trips float64 exactly).
    table = pd.read_csv(Path(run_dir) / RESULTS_FILE, dtype=str, keep_default_na=False)
    table["detail"] = (table["detail"].str.replace(INSTALLED, "<site-packages>/", regex=True)
                       .str.replace(CHECKOUT, "<simparity>/", regex=True))
    return table


def differences(before_dir: Path, after_dir: Path) -> list[str]:
    """Every difference between the two runs' results, timing aside, as one line each."""
    before, after = _read(before_dir), _read(after_dir)
    if list(before.columns) != list(after.columns):
        return [f"columns differ: {list(before.columns)} vs {list(after.columns)}"]
    if len(before) != len(after):
        return [f"{len(before)} rows before, {len(after)} after"]
    timed = before["metric"].str.startswith(TIMING_PREFIX) & after["metric"].str.startswith(TIMING_PREFIX)
    found = []
    for column in before.columns:
        unequal = before[column] != after[column]
        if column in ("value", "detail"):
            unequal &= ~timed
        for index in unequal[unequal].index:
            row = before.loc[index]
            found.append(f"row {index} ({row['scene']} {row['engine']} {row['integrator']} dt={row['dt']} "
                         f"{row['metric']}) {column}: {before.loc[index, column]!r} -> {after.loc[index, column]!r}")
    return found


def series_differences(before_dir: Path, after_dir: Path) -> list[str]:
    """Every difference between the two runs' sampled series, as one line each (none when neither has any)."""
    found = [Path(d) / SERIES_FILE for d in (before_dir, after_dir) if (Path(d) / SERIES_FILE).exists()]
    if not found:
        return []
    if len(found) == 1:
        return [f"only {found[0].parent} has {SERIES_FILE}"]
    before, after = (pd.read_csv(path, dtype=str, keep_default_na=False) for path in found)
    if list(before.columns) != list(after.columns) or len(before) != len(after):
        return [f"series differ in shape: {before.shape} vs {after.shape}"]
    out = []
    for column in before.columns:
        for index in (before[column] != after[column]).to_numpy().nonzero()[0]:
            row = before.iloc[index]
            out.append(f"series row {index} ({' '.join(str(v) for v in row.iloc[:5])}) {column}: "
                       f"{before[column].iloc[index]!r} -> {after[column].iloc[index]!r}")
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.same_results", description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    args = parser.parse_args(argv)
    found = differences(args.before, args.after) + series_differences(args.before, args.after)
    for line in found[:SHOWN]:
        print(line)
    rows = len(_read(args.before))
    print(f"{rows} rows and their series compared, {len(found)} differences (timing aside)")
    return 0 if not found else 1


if __name__ == "__main__":
    sys.exit(main())
