"""The report's sweep sections: per swept scene (:class:`reports.sweep_summary.Sweep`), what a user picking one
scheme for the whole swept range needs, in place of a section per variant: every engine x integrator over all
the variants (its worst one decides), work against precision over them, the sweep's metric against the swept
values (a figure and a table), and links to the few variants shown with a section of their own. A run without a
sweep has none.
"""

from __future__ import annotations

import math
import re
from typing import Callable

import numpy as np
import pandas as pd

from simparity.core.model.results import GROUND_TRUTH_ENGINES, NOT_AVAILABLE, OK, SWEEP_PREFIX
from simparity.reports import figures, summary, sweep_compact, sweep_summary, tables
from simparity.reports.blocks import Block, Details, Heading, Paragraph, Table, number, scene_heading
from simparity.reports.sweep_compact import COMPACT_SWEEP_VARIANTS
from simparity.reports.sweep_summary import METRICS, Sweep
from simparity.reports.tables import swept_value

SWEEP_PANELS = 6
"""Panels the figure of the metric against the swept values has at most (one per combination of the other swept
values and dt): more would be too small to read. Past it the figure keeps the finest dt, then evenly spaced
combinations (both ends included); the table has every value."""

TABLE_ROWS = 40
"""Rows of the table of every value that report.md shows (a sweep of one key has one per engine x integrator x dt);
a larger one (a 10 x 10 sweep at two time steps has 20 per engine x integrator) is folded into report.html, and
results.csv has every value."""

_COST_LABELS = {"dynamics": "median cost [s/s]", "ik": "median time per solve [s]",
                "kinematics": "median time per FK [s]", "joint_dynamics": "median time per forward dynamics [s]"}
_ROLES = {sweep_summary.FIRST: "the first", sweep_summary.LAST: "the last",
          sweep_summary.HARDEST: "the hardest: its errors rank worst on average over the engines and time steps"}
_IK_ROLES = dict(_ROLES, **{sweep_summary.HARDEST: "the hardest: its solve rates rank worst on average over the "
                                                   "solvers"})


def heading(base: str) -> Heading:
    """The heading of the section of the sweep of ``base``; the summary and a variant's section link to it."""
    return Heading(3, f"Sweep of {base}")


def roles(sweep: Sweep, scene: str) -> str:
    """Why ``scene`` of ``sweep`` has a section of its own, in words ("the first, the hardest: ...")."""
    words = _IK_ROLES if sweep.kind == "ik" else _ROLES
    return ", ".join(words[role] for role in sweep.shown[scene])


def sweep_cases(rows: pd.DataFrame, keys: list[str], metric: str, kind: str) -> pd.DataFrame:
    """The ``metric`` rows of one sweep's variants: columns scene, engine, integrator, the sweep columns ``keys``,
    dt, status and value (NaN unless ok). A dynamics sweep keeps the per-time-step rows and leaves out the ground
    truths and the reference's own scheme (measured against itself)."""
    cases = rows[rows["metric"] == metric]
    if kind == "dynamics":
        cases = cases[cases["dt"].notna() & ~cases["engine"].isin(GROUND_TRUTH_ENGINES)
                      & (cases["engine"] + ":" + cases["integrator"] != cases["reference"])]
    cases = cases.assign(value=cases["value"].where(cases["status"] == OK))
    return cases[["scene", "engine", "integrator"] + keys + ["dt", "status", "value"]]


def _cell(cases: pd.DataFrame) -> str:
    """One table cell: the value where it was measured, else the case's status."""
    if cases.empty:
        return "—"
    row = cases.iloc[0]
    return number(row["value"]) if row["status"] == OK else row["status"]


def _grid(cases: pd.DataFrame, keys: list[str], dt_axis: bool) -> Table:
    """Rows engine x integrator x the other swept values (x dt), a column per value of the last swept key, in the
    order of ``cases`` (the sweep's); rows whose every cell is n/a or empty are left out."""
    last, others = keys[-1], keys[:-1] + (["dt"] if dt_axis else [])
    columns = list(dict.fromkeys(cases[last]))
    rows = []
    for (engine, integrator), scheme in cases.groupby(["engine", "integrator"], sort=False):
        for at, group in (scheme.groupby(others, sort=False) if others else [((), scheme)]):
            at = at if isinstance(at, tuple) else (at,)
            cells = [_cell(group[group[last] == value]) for value in columns]
            if any(cell not in (NOT_AVAILABLE, "—") for cell in cells):
                rows.append((engine, integrator, *(swept_value(v) for v in at), *cells))
    head = (["engine", "integrator"] + [k.removeprefix(SWEEP_PREFIX) for k in keys[:-1]]
            + (["dt [s]"] if dt_axis else [])
            + [f"{last.removeprefix(SWEEP_PREFIX)} = {swept_value(v)}" for v in columns])
    return Table(tuple(head), tuple(rows))


def _at(sweep: Sweep, scene) -> str:
    """A variant by its swept values ("9, -10"), in the order of the sweep's keys."""
    return ", ".join(_values_at(sweep, scene)) if isinstance(scene, str) else "—"


def _values_at(sweep: Sweep, scene: str) -> list[str]:
    """A variant's swept values as cells, in the order of the sweep's keys."""
    return [swept_value(v) for v in sweep.rows.loc[sweep.rows["scene"] == scene, sweep.keys].iloc[0]]


def _order_cell(orders: dict, theory: dict, engine: str, integrator: str) -> str:
    """The observed order's range over the variants, the theoretical order in brackets."""
    low, high = orders.get((engine, integrator), (math.nan, math.nan))
    fitted = number(low) if number(low) == number(high) else f"{number(low)} to {number(high)}"
    p = theory.get(engine, {}).get(integrator)
    return f"{fitted} ({p})" if p else fitted


def _across_table(sweep: Sweep, theory: dict) -> Table:
    """Per engine x integrator over every variant: (dynamics: the time step whose worst variant's value is best,
    then) the worst variant's value and which variant it is, the median over the variants, the median cost, the
    observed order's range over the variants (dynamics) and how every case of every variant ended. A scheme not
    ok in every variant at any time step has no values, only its cases."""
    name, unit = METRICS[sweep.metric]
    dynamics, kinematics = sweep.kind == "dynamics", sweep.kind in ("kinematics", "joint_dynamics")
    ranked = sweep.across[sweep.across["status"] == OK]
    ranked = ranked.assign(_rank=ranked["value"] if sweep.lower_is_better else -ranked["value"])
    best = ranked.sort_values(["_rank", "cost"]).drop_duplicates(["engine", "integrator"])
    best = best.set_index(["engine", "integrator"])
    statuses = sweep.cases.groupby(["engine", "integrator"], sort=False)["status"].agg(
        lambda s: ", ".join(f"{k} {n}" for k, n in s.value_counts().items()))
    orders = sweep_summary.order_ranges(sweep.rows, sweep.metric) if dynamics else {}
    rows = []
    for (engine, integrator), cases in statuses.items():
        if (engine, integrator) in best.index:
            b = best.loc[(engine, integrator)]
            cells = ([number(b["dt"])] if dynamics else []) + [
                number(b["value"]), _at(sweep, b["worst_scene"]), number(b["median"]), number(b["cost"])]
        else:
            cells = ["—"] * (5 if dynamics else 4)
        cells += [_order_cell(orders, theory, engine, integrator)] if dynamics else []
        rows.append((engine,) + ((integrator,) if not kinematics else ()) + tuple(cells) + (cases,))
    where = f"worst variant ({', '.join(f'`{k.removeprefix(SWEEP_PREFIX)}`' for k in sweep.keys)})"
    head = (["engine"] + ([] if kinematics else ["solver" if sweep.kind == "ik" else "integrator"])
            + (["best dt [s]"] if dynamics else [])
            + [f"worst {name}" + (f" [{unit}]" if unit else ""), where, f"median {name}", _COST_LABELS[sweep.kind]]
            + (["order (theory)"] if dynamics else []) + ["cases (variants × dt)" if dynamics else "cases"])
    return Table(tuple(head), tuple(rows))


def _figure_cases(cases: pd.DataFrame, panels: list[str]) -> tuple[pd.DataFrame, list[str], str]:
    """(the cases the figure of the metric against the swept values draws, its panel columns, what its caption
    says of them): every combination of ``panels`` when there are at most :data:`SWEEP_PANELS`; else the finest
    dt alone, and past that evenly spaced combinations of the other swept values, both ends included."""
    note = ""
    measured = cases[(cases["status"] == OK) & cases["value"].notna()]
    if "dt" in panels and measured.groupby(panels, sort=False).ngroups > SWEEP_PANELS:
        finest = measured["dt"].min()
        measured, panels = measured[measured["dt"] == finest], [p for p in panels if p != "dt"]
        note = f" At the finest time step, dt = {swept_value(finest)} s."
    combinations = measured[panels].drop_duplicates()
    if panels and len(combinations) > SWEEP_PANELS:
        spaced = np.linspace(0, len(combinations) - 1, SWEEP_PANELS).round().astype(int)
        kept = combinations.iloc[sorted(set(spaced))]
        measured = measured.merge(kept, on=panels)
        note += (f" {len(kept)} of the {len(combinations)} panels, evenly spaced with both ends; the table has "
                 "every one.")
    return measured, panels, note


def _every_value(sweep: Sweep) -> Details:
    """Every metric of every variant, folded into report.html: a row per variant's swept values x engine x
    integrator (x dt), as a scene's full table has per engine x integrator (x dt)."""
    order = {name: k for k, name in enumerate(sweep.variants)}
    keys = [key.removeprefix(SWEEP_PREFIX) for key in sweep.keys]
    rows = (sweep.rows.assign(_order=sweep.rows["scene"].map(order)).sort_values("_order", kind="stable")
            .rename(columns=dict(zip(sweep.keys, keys))))
    if sweep.kind == "dynamics":
        full = [tables.metric_table(rows[rows["dt"].notna()], tables.DYNAMICS_COLUMNS,
                                    keys + ["engine", "integrator", "dt"])]
        orders = rows[rows["dt"].isna()]
        if not orders.empty:
            full.append(tables.metric_table(orders, tables.ORDER_COLUMNS, keys + ["engine", "integrator"]))
    elif sweep.kind == "ik":
        plain = rows[~rows["metric"].str.startswith("hard_")].rename(columns={"integrator": "solver"})
        full = [tables.metric_table(plain, tables.IK_COLUMNS, keys + ["engine", "solver"])]
    else:
        full = [tables.metric_table(rows, tables.KINEMATICS_COLUMNS, keys + ["engine"])]
    return Details(f"{sweep.base}: every metric of every variant", tuple(full), markdown=False)


def _swept(sweep: Sweep, key: str) -> str:
    """The values ``key`` takes over the variants, in the sweep's order: every one, or in a compact sweep
    (:data:`COMPACT_SWEEP_VARIANTS`) how many from which to which."""
    values = list(dict.fromkeys(sweep.rows.drop_duplicates("scene").set_index("scene").loc[sweep.variants, key]))
    if len(sweep.variants) > COMPACT_SWEEP_VARIANTS and len(values) > 2:
        return f"{len(values)} values from {swept_value(min(values))} to {swept_value(max(values))}"
    return ", ".join(swept_value(v) for v in values)


def _intro(sweep: Sweep) -> Paragraph:
    """How many variants of which file, the values swept, the metric and its reference, and links to the variants
    with a section of their own."""
    label = sweep_summary.metric_label(sweep.metric)
    swept = "; ".join(f"`{key.removeprefix(SWEEP_PREFIX)}` {_swept(sweep, key)}" for key in sweep.keys)
    kind = summary.heading_kind(sweep.kind, sweep.metric)
    shown = ", ".join(f"[variant {k + 1}](#{scene_heading(name, kind).anchor}) ({roles(sweep, name)})"
                      for k, name in enumerate(sweep.variants) if name in sweep.shown)
    return Paragraph(f"{len(sweep.variants)} variants" + (f" of `{sweep.source}`" if sweep.source else "")
                     + f": {swept}. {label[:1].upper() + label[1:]} against `{sweep.reference}`."
                     + (f" Shown with a section of their own: {shown}." if shown else ""))


def _section(sweep: Sweep, figure: Callable[..., list[Block]], theory: dict, variants: dict | None) -> list[Block]:
    """The blocks of one sweep: its paragraph, the table over the variants, the figures and the table of every
    value."""
    label = sweep_summary.metric_label(sweep.metric)
    title = label[:1].upper() + label[1:]
    blocks: list[Block] = [heading(sweep.base), _intro(sweep), _across_table(sweep, theory)]
    if sweep.kind == "dynamics":
        count = len(sweep.variants)
        blocks += figure(figures.sweep_work_precision_figure(sweep.base, sweep.across, label, sweep.reference, count,
                                                             variants),
                         f"{sweep.base}-sweep-work-precision",
                         f"Work-precision over the {count} variants: {label} of each engine × integrator at its worst "
                         "variant against its median cost, one point per dt; the band reaches its best variant.")
    if len(sweep.variants) > COMPACT_SWEEP_VARIANTS:
        return blocks + _compact(sweep, figure)
    cases = sweep_cases(sweep.rows, sweep.keys, sweep.metric, sweep.kind)
    dt_axis = bool(sweep.kind == "dynamics" and (cases.groupby("scene")["dt"].nunique() > 1).any())
    order = {name: k for k, name in enumerate(sweep.variants)}
    cases = cases.assign(_order=cases["scene"].map(order)).sort_values(["_order", "dt"], kind="stable")
    drawn, panels, note = _figure_cases(cases, sweep.keys[:-1] + (["dt"] if dt_axis else []))
    last = sweep.keys[-1].removeprefix(SWEEP_PREFIX)
    per_panel = ", ".join(p.removeprefix(SWEEP_PREFIX) for p in panels)
    blocks += figure(figures.sweep_figure(sweep.base, drawn, sweep.keys[-1], panels, label, sweep.reference),
                     f"{sweep.base}-sweep", f"{title} against `{last}`"
                     + (f", one panel per value of {per_panel}." if per_panel else ".") + note)
    table = _grid(cases, sweep.keys, dt_axis)
    grid: Block = table
    if len(table.rows) > TABLE_ROWS:
        grid = Details(f"{sweep.base}: {label} of every engine × integrator × variant" + (" × dt" if dt_axis else "")
                       + f" ({len(table.rows)} rows)", (table,), markdown=False)
    return blocks + [grid, _every_value(sweep)]


def _compact(sweep: Sweep, figure: Callable[..., list[Block]]) -> list[Block]:
    """A sweep of more than :data:`COMPACT_SWEEP_VARIANTS` variants after its table over them: the quantiles of its
    metrics over the variants, its worst variants, and per swept key a figure of the headline metrics against it."""
    values = sweep_compact.metric_cases(sweep)
    metrics = sweep_compact.shown_metrics(values)
    names = ", ".join(m.replace("_", " ") for m in metrics) or "no headline metric"
    dynamics = " at each scheme's finest time step" if sweep.kind == "dynamics" else ""
    blocks: list[Block] = [
        Paragraph(f"Over the {len(sweep.variants)} variants (more than {COMPACT_SWEEP_VARIANTS}: their distribution, "
                  f"not a row each): the quantiles of {names}{dynamics} per engine × integrator; every metric's are "
                  "in report.html, every value in `results.csv`."),
        *sweep_compact.quantile_blocks(sweep, values),
        Paragraph(f"The {sweep_compact.WORST_VARIANTS} worst variants: each case's "
                  f"{sweep.metric.replace('_', ' ')} ranked among the variants within its engine × integrator"
                  + (" × dt" if sweep.kind == "dynamics" else "") + ", the ranks averaged."),
        sweep_compact.worst_table(sweep, lambda scene: _values_at(sweep, scene))]
    panels = [(sweep_compact.metric_label(m), m) for m in metrics]
    for key in sweep.keys:
        name = key.removeprefix(SWEEP_PREFIX)
        blocks += figure(figures.sweep_parameter_figure(
            sweep.base, [(label, sweep_compact.parameter_cases(sweep, values, m)) for label, m in panels], key,
            sweep.reference), f"{sweep.base}-sweep-{_file_part(name)}",
            f"{names[:1].upper() + names[1:]} against `{name}`{dynamics}: per engine × integrator the median over the "
            "variants at each value, the band from the least to the largest.")
    return blocks


def _file_part(key: str) -> str:
    """A swept key as part of a figure's file name (letters, digits, ``-``, ``_``, ``.``)."""
    return re.sub(r"[^A-Za-z0-9_.-]", "_", key)


def sections(all_sweeps: list[Sweep], figure: Callable[..., list[Block]], theory: dict,
             variants: dict | None = None) -> list[Block]:
    """The "Sweeps" section of a report: per swept scene its blocks (:func:`_section`; ``figure(fig, name,
    caption)`` draws and names a figure, ``theory`` the engines' theoretical orders, ``variants`` run.json's
    ``integrator_variants``, which the work-precision figure groups); nothing for a run without a sweep."""
    if not all_sweeps:
        return []
    blocks: list[Block] = [
        Heading(2, "Sweeps"),
        Paragraph("A scene file's `[sweep]` runs its scene once per combination of the swept values (docs/scenes.md, "
                  "\"Sweeps\"). Per swept scene, for picking one scheme for the whole swept range: each engine × "
                  "integrator over every variant (dynamics: at the time step whose worst variant's error is least) "
                  "with its worst variant's value and which variant that is, the median over the variants, its "
                  "median cost, the range of its observed order and how every case ended; the work-precision "
                  "figure over the variants; and the headline metric against the swept values (dynamics: at each "
                  f"time step of the ladder, ground truths ({', '.join(GROUND_TRUTH_ENGINES)}) and the reference's "
                  "own scheme left out), where a cell is the value where it was measured, else the case's status, "
                  "and a row that is n/a throughout is left out. The summary ranks a sweep by its worst variant. "
                  "Only the first, the last and the hardest variant have a section of their own; every value of "
                  "every variant is in `results.csv`, its swept values in the `sweep:KEY` columns (the numbers "
                  f"written into the file, in its length unit). A sweep of more than {COMPACT_SWEEP_VARIANTS} variants "
                  "shows their distribution (quantiles, the worst variants, the headline metrics against each swept "
                  "key) instead of a row or a cell per variant.")]
    for sweep in all_sweeps:
        blocks += _section(sweep, figure, theory, variants)
    return blocks
