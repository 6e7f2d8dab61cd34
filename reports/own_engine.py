"""Is my engine right? (issue #38): the report's first section for each engine of the user's the gate holds (a plugin:
not core, not an engine simparity compares against, not a ground truth): each of its schemes beside the built-in
schemes of the same kind (the ``scheme`` the engines declare) at each time step, and every finding of the gate about
it. Reads a stored run's rows and the gate's verdict; runs nothing.
"""

from __future__ import annotations

import math

import pandas as pd

from simparity.core.model.metric_catalogue import POSITION_ERROR_MAX
from simparity.core.model.results import GROUND_TRUTH_ENGINES, OK
from simparity.reports.blocks import Block, Bullets, Heading, Paragraph, Table, number
from simparity.reports.engine_summary import THIRD_PARTY_ENGINES, engine_order

BUILT_IN_ENGINES = ("core",) + THIRD_PARTY_ENGINES
"""The engines a user's is set beside: core's textbook schemes and the engines simparity compares against."""

ROWS_SHOWN = 20
"""Scene x scheme rows an engine's table shows in report.md, the worst against the built-ins first; the rest are
counted (results.csv has every one)."""

FINDINGS_SHOWN = 12
"""Findings about an engine its section lists, in the gate's order; the rest are counted (the section "Flagged
findings" folds every one)."""

TRIM_ORDER = 3
"""Where an engine's table stands among those report.md may shorten to stay within its line budget
(:attr:`reports.blocks.Table.trim_order`): after the cases without a result and the flagged findings (its rows are
sorted worst first, so what it keeps is what matters most)."""

DT_MATCH = 1e-9
"""Relative difference under which two rows' time steps are one [s]."""


def users_engines(engines, held: tuple[str, ...] | None) -> list[str]:
    """The user's engines among ``engines`` that the gate holds (``held`` None: every engine), in run order."""
    return [e for e in engine_order(engines) if e not in BUILT_IN_ENGINES and e not in GROUND_TRUTH_ENGINES
            and (held is None or e in held)]


def sections(table: pd.DataFrame, headlines: dict[str, str], held: tuple[str, ...] | None,
             findings: dict[str, tuple[str, ...]] | None) -> list[Block]:
    """One section per user's engine the gate holds: its schemes beside the built-ins' (``headlines``: each scene's
    headline error metric, default ``position_error_max``) and the gate's findings about it (``findings``: the lines
    per engine; None: the run was not checked)."""
    blocks: list[Block] = []
    for engine in users_engines(table["engine"], held):
        blocks += [Heading(2, f"Is {engine} right?")] + beside_builtins(table, engine, headlines)
        blocks += _findings(engine, None if findings is None else findings.get(engine, ()))
    return blocks


def beside_builtins(table: pd.DataFrame, engine: str, headlines: dict[str, str]) -> list[Block]:
    """A row per scene x scheme of ``engine``: at each time step its headline error beside the built-in schemes' of
    the same kind (their least to largest), and the worst ratio of its error to the largest of theirs; the worst
    rows first, at most :data:`ROWS_SHOWN`."""
    rows: list[tuple[float, tuple[str, ...]]] = []
    for scene, scene_rows in table[table["dt"].notna()].groupby("scene", sort=False):
        headline = scene_rows[scene_rows["metric"] == headlines.get(scene, POSITION_ERROR_MAX)]
        builtins = headline[headline["engine"].isin(BUILT_IN_ENGINES)]
        for integrator, own in headline[headline["engine"] == engine].groupby("integrator", sort=False):
            kind = own["scheme"].iloc[0] if isinstance(own["scheme"].iloc[0], str) else ""
            same = builtins[builtins["scheme"] == kind] if kind else builtins.iloc[0:0]
            rows.append(_row(scene, integrator, kind, own, same))
    if not rows:
        return [Paragraph(f"{engine} has no time-stepped rows in this run to set beside the built-in schemes.")]
    rows.sort(key=lambda r: -r[0] if math.isfinite(r[0]) else math.inf)
    more = len(rows) - ROWS_SHOWN
    counted: list[Block] = [Paragraph(f"... and {more} more scene × scheme rows (results.csv).")] if more > 0 else []
    return [Paragraph(f"Your engine's schemes beside the built-in schemes of the same kind, on each scene's headline "
                      f"error at each time step ({engine}'s value, then the built-ins' least–largest); the worst "
                      f"ratio of {engine}'s error to the largest built-in's at the same step first. A ratio far above "
                      "1 is a scheme that errs more than any built-in of its kind."),
            Table(("scene", "scheme (kind) vs built-in", f"dt [s]: {engine} vs built-in", "worst ratio"),
                  tuple(cells for _, cells in rows[:ROWS_SHOWN]), trim_order=TRIM_ORDER), *counted]


def _row(scene: str, integrator: str, kind: str, own: pd.DataFrame, same: pd.DataFrame) -> tuple[float, tuple[str, ...]]:
    """(the worst ratio, the cells) of one scene x scheme of the user's engine against ``same``, the built-ins' rows
    of its kind."""
    named = sorted(set(same["engine"] + " " + same["integrator"]))
    versus = f"{integrator} ({kind or 'no kind declared'})" + (
        f" vs {', '.join(named[:3])}" + (f" +{len(named) - 3}" if len(named) > 3 else "") if named else
        ": no built-in of its kind")
    cells, ratios = [], []
    for _, mine in own.sort_values("dt", ascending=False).iterrows():
        at = same[(same["dt"] - mine["dt"]).abs() <= DT_MATCH * mine["dt"]]
        theirs = at[at["status"] == OK]["value"]
        value = number(mine["value"]) if mine["status"] == OK else mine["status"]
        cells.append(f"{mine['dt']:g}: {value}" + (f" vs {_span(theirs)}" if len(theirs) else ""))
        if mine["status"] == OK and len(theirs) and theirs.max() > 0:
            ratios.append(mine["value"] / theirs.max())
    worst = max(ratios, default=math.nan)
    return worst, (scene, versus, "; ".join(cells), f"×{number(worst)}" if ratios else "—")


def _span(values: pd.Series) -> str:
    low, high = number(values.min()), number(values.max())
    return low if low == high else f"{low}–{high}"


def _findings(engine: str, lines: tuple[str, ...] | None) -> list[Block]:
    """The gate's findings about ``engine`` (every violation of a bound or a cross-check), or that there are none."""
    if lines is None:
        return [Paragraph(f"**Findings about {engine}**: the run was not held to tolerances in this report.")]
    if not lines:
        return [Paragraph(f"**Findings about {engine}**: none; every metric of {engine} the gate holds is inside its "
                          "bound, and its cross-checks against the built-in schemes pass.")]
    more = len(lines) - FINDINGS_SHOWN
    return [Paragraph(f"**Findings about {engine}**: {len(lines)} (one per case and reason):"),
            Bullets(tuple(f"`{line}`" for line in lines[:FINDINGS_SHOWN])
                    + ((f"... and {more} more (Flagged findings, below)",) if more > 0 else ()))]
