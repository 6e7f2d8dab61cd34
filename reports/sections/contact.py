"""What a contact scene's section adds to a dynamics scene's (:mod:`reports.sections.dynamics`): the height figure,
per engine its measured restitution's range and worst penetration, the contact table and the penalty method's
measured stability limits."""

from __future__ import annotations

from dataclasses import dataclass

import pandas as pd

from simparity.core.model.metric_catalogue import (
    APEX_HEIGHT_ERROR, ENERGY_GAIN_MAX, IMPACT_TIME_ERROR, PENETRATION_MAX, REST_TIME_ERROR, RESTITUTION_MEASURED,
    STOPPING_DISTANCE,
)
from simparity.core.model.results import OK
from simparity.reports import figures, summary
from simparity.reports.blocks import Block, Bullets, Details, Paragraph, Table, number
from simparity.reports.sections.context import ReportContext


@dataclass(frozen=True)
class Contact:
    """What a contact scene's section adds: its height figure, per engine (its measured restitution's range, its
    worst penetration) as cells, and its blocks after the tables."""

    figure: list[Block]
    per_engine: dict[str, tuple[str, str]]
    blocks: list[Block]


def _value_range(values: pd.Series) -> str:
    """``0.486-0.601``: the range of the measured values; one value as itself; none as an em dash."""
    measured = values.dropna()
    if measured.empty:
        return "—"
    low, high = number(float(measured.min())), number(float(measured.max()))
    return low if low == high else f"{low}-{high}"


def section(ctx: ReportContext, scene, rows, about, reference, series) -> Contact:
    """The height figure; per engine its measured restitution's range and worst penetration; in report.html the
    contact table (restitution at every dt, the worst penetration and energy gain, errors at the finest dt); the
    penalty method's measured stability limits (one line in report.md, with how each was found in the HTML)."""
    figure = ctx.figure(figures.contact_height_figure(scene, series, reference), f"{scene}-height",
                        "Height of the lowest point above the plane against time, from the stored series.")
    cases = summary.contact_cases(rows)
    dts = sorted(cases["dt"].unique())
    requested = sorted({k for row in about["contact"]["restitution"] for k in row})
    table = []
    for (engine, integrator), g in cases.groupby(["engine", "integrator"], sort=False):
        g = g.sort_values("dt")
        finest = g[g["status"] == OK].head(1)
        at = (lambda m: number(float(finest[m].iloc[0])) if not finest.empty else "—")
        table.append((engine, integrator)
                     + tuple(number(float(g.loc[g["dt"] == dt, RESTITUTION_MEASURED].max())) for dt in dts)
                     + (number(float(g[PENETRATION_MAX].max())), number(float(g[ENERGY_GAIN_MAX].max())),
                        at("dt"), at(IMPACT_TIME_ERROR), at(APEX_HEIGHT_ERROR), at(REST_TIME_ERROR),
                        at(STOPPING_DISTANCE), " · ".join(dict.fromkeys(g["status"]))))
    per_engine = {engine: (_value_range(g[RESTITUTION_MEASURED]), number(float(g[PENETRATION_MAX].max())))
                  for engine, g in cases.groupby("engine", sort=False)}
    blocks: list[Block] = [Details(
        f"Contact, per engine × integrator: requested restitution {', '.join(f'{k:g}' for k in requested)}",
        (Paragraph("Restitution measured from each run's first rebound (v_out / |v_in|, extrapolated along the "
                   "free flight from the samples either side), at each dt. Penetration and energy gained: the "
                   "worst over the time steps; the errors after them at the finest time step measured (named)."),
         Table(("engine", "integrator") + tuple(f"restitution at dt {dt:g}" for dt in dts)
               + ("penetration max [m]", "energy gained max (rel.)", "finest ok dt [s]", "impact time error [s]",
                  "apex height error [m]", "rest time error [s]", "stopping distance [m]", "time steps"),
               tuple(table))), markdown=False, open=True)]
    limits = summary.stability_limits(rows)
    if not limits.empty:
        values = "; ".join(f"{r['engine']} {r['integrator']} "
                           + (f"{number(r['value'])} s" if r["status"] == OK else r["status"])
                           for _, r in limits.iterrows())
        items = tuple(f"{r['engine']} {r['integrator']}: {r['detail']}" for _, r in limits.iterrows())
        blocks += [Paragraph("Penalty method, measured stability limit (the largest step that neither blows up "
                             f"nor gains energy at an impact): {values}."),
                   Details("How each stability limit was found", (Bullets(items),), markdown=False)]
    return Contact(figure, per_engine, blocks)
