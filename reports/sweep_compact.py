"""A sweep of many variants in the report (issue #29): distributions over the variants instead of a row per variant.

Past :data:`COMPACT_SWEEP_VARIANTS` variants, a sweep's section (:mod:`reports.sweep_sections`) replaces its tables of
every variant with: per metric the quantiles over the variants (min, 5 %, median, 95 %, max) of each engine x
integrator (x dt), the :data:`WORST_VARIANTS` worst variants, and a figure of each headline metric against each swept
key. Each is bounded by the schemes and the keys, not by the variants, so report.md stays within its line budget
(:data:`reports.markdown.MAX_LINES`) at :data:`comparisons.scenes.sweep.MAX_VARIANTS`. Every value of every variant is
in ``results.csv``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from simparity.core.model.metric_catalogue import CATALOGUE, headline_metrics
from simparity.core.model.results import GROUND_TRUTH_ENGINES, OK, SWEEP_PREFIX
from simparity.reports.blocks import Details, Table, number
from simparity.reports.sweep_summary import Sweep
from simparity.reports.tables import swept_value

COMPACT_SWEEP_VARIANTS = 24
"""Variants up to which a sweep's section keeps its table of every variant (a row per engine x integrator x other
swept values (x dt), a column per value of the last key, and every metric of every variant in report.html): a 4 x 6
sweep's grid still fits on a screen. Past it the section shows the distribution over the variants instead: a grid of
a 1,000-variant sweep would be thousands of rows in report.html and a report no one reads through."""

QUANTILES = (0.0, 0.05, 0.5, 0.95, 1.0)
"""The quantiles over the variants each metric is summarised by: the extremes, the range of the middle 90 % (one
bad variant in twenty shows up in the 95 % quantile before the max) and the median."""
QUANTILE_LABELS = ("min", "5 %", "median", "95 %", "max")

WORST_VARIANTS = 5
"""Variants listed as the worst (by the sweep's metric, ranked within each engine x integrator x dt and averaged over
them): enough to see whether the hard corner of the swept range is one point or a region, few enough to read."""


def metric_cases(sweep: Sweep) -> pd.DataFrame:
    """The ok, finite values of every metric of the sweep's per-case rows: columns scene, engine, integrator, dt,
    metric, value. A dynamics sweep keeps the rows of each time step (not the observed orders) and leaves out the
    ground truths and the reference's own scheme (measured against itself)."""
    rows = sweep.rows
    if sweep.kind == "dynamics":
        rows = rows[rows["dt"].notna() & ~rows["engine"].isin(GROUND_TRUTH_ENGINES)
                    & (rows["engine"] + ":" + rows["integrator"] != rows["reference"])]
    rows = rows[(rows["status"] == OK) & np.isfinite(rows["value"].astype(float))]
    return rows[["scene", "engine", "integrator", "dt", "metric", "value"]]


def quantiles(values: pd.DataFrame) -> pd.DataFrame:
    """Per metric x engine x integrator x dt of :func:`metric_cases`, in the order they first come: the
    :data:`QUANTILES` of the value over the variants (columns :data:`QUANTILE_LABELS`) and ``variants``, how many were
    measured."""
    keys = ["metric", "engine", "integrator", "dt"]
    grouped = values.groupby(keys, sort=False, dropna=False)["value"]
    table = grouped.quantile(list(QUANTILES)).unstack().set_axis(list(QUANTILE_LABELS), axis=1)
    return table.join(grouped.size().rename("variants")).reset_index()


def shown_metrics(values: pd.DataFrame) -> list[str]:
    """The headline metrics (the catalogue's: what a report ranks by) the sweep measured, in the catalogue's order; one
    that is 0 in every case (the orientation error of a ball that never turns) shows nothing and is left out."""
    nonzero = set(values.loc[values["value"] != 0, "metric"])
    return [m for m in headline_metrics() if m in nonzero]


def metric_label(metric: str) -> str:
    """A metric as a table or an axis labels it: its name in words and its unit ("position error max [m]")."""
    unit = CATALOGUE[metric].unit if metric in CATALOGUE else ""
    name = metric.replace("_", " ")
    return f"{name} [{unit}]" if unit and unit != "1" else name


def _quantile_table(table: pd.DataFrame, dt_column: bool) -> Table:
    head = ("metric", "engine", "integrator") + (("dt [s]",) if dt_column else ()) + QUANTILE_LABELS + ("variants",)
    rows = tuple((metric_label(r["metric"]), r["engine"], r["integrator"]) + ((number(r["dt"]),) if dt_column else ())
                 + tuple(number(r[q]) for q in QUANTILE_LABELS) + (str(r["variants"]),) for _, r in table.iterrows())
    return Table(head, rows)


def quantile_blocks(sweep: Sweep, values: pd.DataFrame) -> list:
    """report.md's table of the headline metrics' quantiles over the variants, per engine x integrator (dynamics: at
    the finest time step of the ladder, the most accurate), and, folded into report.html, every metric's at every
    time step."""
    table = quantiles(values)
    dynamics = sweep.kind == "dynamics"
    headline = table[table["metric"].isin(shown_metrics(values))]
    if dynamics and not headline.empty:
        headline = headline[headline["dt"] == headline.groupby(["engine", "integrator"])["dt"].transform("min")]
    shown = [_quantile_table(headline, False)] if not headline.empty else []
    return shown + [Details(
        f"{sweep.base}: every metric's quantiles over the {len(sweep.variants)} variants"
        + (", at every time step" if dynamics else ""), (_quantile_table(table, dynamics),), markdown=False)]


def worst_variants(sweep: Sweep) -> pd.DataFrame:
    """The :data:`WORST_VARIANTS` worst variants by the sweep's metric: each case's value ranked among the variants
    within its engine x integrator (x dt), the ranks averaged per variant (1: worst in every case). Columns scene,
    rank (that average, 0 to 1), value (the variant's worst value of the metric) and where (the case it came from:
    "engine integrator", with "dt = ..." for dynamics), worst first; ties keep the sweep's order."""
    keys = ["engine", "integrator"] + (["dt"] if sweep.kind == "dynamics" else [])
    measured = sweep.cases[sweep.cases["value"].notna()]
    if measured.empty:
        return pd.DataFrame(columns=["scene", "rank", "value", "where"])
    lower = sweep.lower_is_better
    rank = measured.groupby(keys, sort=False, dropna=False)["value"].rank(pct=True, ascending=lower)
    order = {name: k for k, name in enumerate(sweep.variants)}
    mean = rank.groupby(measured["scene"]).mean().rename("rank").reset_index()
    mean = mean.assign(_order=mean["scene"].map(order)).sort_values(["rank", "_order"], ascending=[False, True])
    worst = mean.head(WORST_VARIANTS)
    picked = measured[measured["scene"].isin(worst["scene"])]
    at = picked.loc[picked.groupby("scene")["value"].idxmax() if lower else picked.groupby("scene")["value"].idxmin()]
    where = at["engine"] + " " + at["integrator"] + (
        at["dt"].map(lambda dt: f", dt = {swept_value(dt)} s") if sweep.kind == "dynamics" else "")
    found = pd.DataFrame({"scene": at["scene"], "value": at["value"], "where": where})
    return worst[["scene", "rank"]].merge(found, on="scene")


def worst_table(sweep: Sweep, at_values) -> Table:
    """The :func:`worst_variants` as a table: their swept values (``at_values(scene)``: a cell per key), how they
    rank, their worst value and the case it came from."""
    worst = worst_variants(sweep)
    name = sweep.metric.replace("_", " ")
    head = (("variant",) + tuple(f"`{k.removeprefix(SWEEP_PREFIX)}`" for k in sweep.keys)
            + ("rank (1: worst in every case)", f"its {'worst' if sweep.lower_is_better else 'lowest'} {name}",
               "in"))
    rows = tuple((str(sweep.variants.index(r["scene"]) + 1),) + tuple(at_values(r["scene"]))
                 + (f"{r['rank']:.2f}", number(r["value"]), r["where"]) for _, r in worst.iterrows())
    return Table(head, rows)


def parameter_cases(sweep: Sweep, values: pd.DataFrame, metric: str) -> pd.DataFrame:
    """The values of ``metric`` with each variant's swept values (the sweep's key columns) beside them: a dynamics
    sweep at each scheme's finest time step (the figure's one panel per metric)."""
    mine = values[values["metric"] == metric]
    if sweep.kind == "dynamics" and not mine.empty:
        mine = mine[mine["dt"] == mine.groupby(["engine", "integrator"])["dt"].transform("min")]
    swept = sweep.rows.drop_duplicates("scene").set_index("scene")[sweep.keys]
    return mine.join(swept, on="scene")
