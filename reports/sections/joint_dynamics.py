"""The joint-space dynamics section: every joint-dynamics scene in one table (M, h, tau and qddot against the
reference, and the identities of each engine's own outputs), not a section each; and its line in the summary."""

from __future__ import annotations

import pandas as pd

from simparity.core.model.metric_catalogue import (
    BASE_MOMENTUM_RESIDUAL, BIAS_FORCE_ERROR_MAX, CENTRAL_DIFFERENCE_BEST_STEP, CENTRAL_DIFFERENCE_FLOOR,
    FORWARD_DIFFERENCE_BEST_STEP, FORWARD_DIFFERENCE_FLOOR, FORWARD_DYNAMICS_ERROR_MAX, GRAVITY_EQUIVALENCE_RESIDUAL, GRAVITY_IDENTITY_RESIDUAL,
    INVERSE_DYNAMICS_ERROR_MAX,
    KINETIC_ENERGY_RESIDUAL, MASS_COLUMN_RESIDUAL, MASS_MATRIX_ASYMMETRY, MASS_MATRIX_ERROR_MAX, ROUND_TRIP_RESIDUAL,
)
from simparity.core.model.results import OK
from simparity.reports import figures, tables
from simparity.reports.blocks import Block, Bullets, Details, Heading, Paragraph, Table, number
from simparity.reports.markdown import LINE_CHARS
from simparity.reports.sections.context import ReportContext
from simparity.reports.sections.shared import engine_notes

DYNAMICS_ERRORS = (MASS_MATRIX_ERROR_MAX, BIAS_FORCE_ERROR_MAX, INVERSE_DYNAMICS_ERROR_MAX, FORWARD_DYNAMICS_ERROR_MAX)
DYNAMICS_IDENTITIES = (GRAVITY_IDENTITY_RESIDUAL, MASS_COLUMN_RESIDUAL, ROUND_TRIP_RESIDUAL, MASS_MATRIX_ASYMMETRY,
               KINETIC_ENERGY_RESIDUAL, GRAVITY_EQUIVALENCE_RESIDUAL, BASE_MOMENTUM_RESIDUAL)


def _row_width(table: Table) -> int:
    """Characters of the table's widest markdown row ("| a | b |")."""
    return max(sum(len(str(cell)) + 3 for cell in row) + 1 for row in (table.head, *table.rows))


def _worst_cell(case: pd.DataFrame) -> str:
    """A joint-dynamics case in one cell: its worst error against the reference, then its worst identity residual
    ("id"); the case's status where nothing of either was measured; "—" where the case did not run."""
    if case.empty:
        return "—"
    ok = case[case["status"] == OK]
    parts = []
    for label, metrics in (("", DYNAMICS_ERRORS), ("id ", DYNAMICS_IDENTITIES)):
        values = ok[ok["metric"].isin(metrics)]["value"]
        parts.append(f"{label}{number(float(values.max()))}" if not values.empty else f"{label}n/a")
    if all(part.endswith("n/a") for part in parts):
        return str(case["status"].iloc[0]) if (case["status"] != OK).all() else "n/a"
    return " · ".join(parts)


def summary_line(ctx: ReportContext) -> list[Block]:
    """One line per engine and method over the run's joint-dynamics scenes (two or more): its worst error against the
    references and its worst identity residual (the section "Joint-space dynamics" has them per scene)."""
    rows = ctx.table[ctx.table["scene"].isin(ctx.joint_dynamics_scenes)]
    if len(ctx.joint_dynamics_scenes) < 2:  # one scene: its section's table says the same
        return []
    cells = [f"{engine} {method} {_worst_cell(case)}"
             for (engine, method), case in rows.groupby(["engine", "integrator"], sort=False)]
    return [Paragraph(f"**Joint-space dynamics** over {len(ctx.joint_dynamics_scenes)} scenes, each engine's "
                      "worst relative error of M, h, tau and qddot against the references, then (\"id\") its "
                      "worst identity residual: " + "; ".join(cells) + ".")]


def section(ctx: ReportContext, rows: pd.DataFrame) -> list[Block]:
    """One section for every joint-dynamics scene: in report.md each scene's worst relative error (of M, h, tau
    and qddot against the reference) per engine and method, and its worst identity residual; in report.html every
    metric per scene x engine x method."""
    scenes = list(dict.fromkeys(rows["scene"]))
    cases = list(dict.fromkeys(zip(rows["engine"], rows["integrator"])))
    cells = {(scene, case): _worst_cell(rows[(rows["scene"] == scene) & (rows["engine"] == case[0])
                                             & (rows["integrator"] == case[1])])
             for scene in scenes for case in cases}
    labels = [f"{e} {m}" for e, m in cases]
    by_scene = Table(("scene", *labels), tuple((scene, *(cells[scene, c] for c in cases)) for scene in scenes))
    by_engine = Table(("engine method", *scenes), tuple((label, *(cells[s, c] for s in scenes))
                                                        for label, c in zip(labels, cases)))
    # a row per scene when its row fits a line (few lines in a default run), else the fewer of the two across
    fits = _row_width(by_scene) <= LINE_CHARS
    table = by_scene if fits or len(cases) <= len(scenes) else by_engine
    full = tables.metric_table(rows, tables.JOINT_DYNAMICS_COLUMNS, ["scene", "engine", "integrator"])
    blocks: list[Block] = [Heading(2, "Joint-space dynamics"),
                           Bullets(tuple(f"**{scene}**: {ctx.introduction(scene, rows[rows['scene'] == scene])}"
                                         for scene in scenes)
                                   + ("Each cell: the largest relative error of M, h, tau (RNEA) and qddot (ABA) "
                                      "against the reference, then ('id') the largest residual of the identities of "
                                      "the engine's own outputs; each metric, times and the reasons for n/a: the HTML "
                                      "report (docs/metrics.md).",)),
                           table, Details("Every joint-dynamics metric", (full,), markdown=False, open=True)]
    blocks += _differences(ctx, rows, scenes)
    return blocks + engine_notes(rows)


def _differences(ctx: ReportContext, rows: pd.DataFrame, scenes: list[str]) -> list[Block]:
    """The finite-difference step sweep: its figure, and each engine's best steps in one line per scheme (the
    smallest error over the scenes and the range of the steps that gave it)."""
    series = ctx.series[ctx.series["scene"].isin(scenes)] if not ctx.series.empty else ctx.series
    figure = ctx.figure(figures.difference_step_figure(series), "finite-difference-steps",
                        "Finite differences as users take them: the error of dtau/dq against the step, from the "
                        "stored series (comparisons/measure/finite_differences.py).")
    if not figure:
        return []
    lines = []
    for label, step_metric, error_metric in (("forward", FORWARD_DIFFERENCE_BEST_STEP, FORWARD_DIFFERENCE_FLOOR),
                                             ("centred", CENTRAL_DIFFERENCE_BEST_STEP, CENTRAL_DIFFERENCE_FLOOR)):
        cells = []
        for (engine, method), case in rows[rows["status"] == OK].groupby(["engine", "integrator"], sort=False):
            steps = case[case["metric"] == step_metric]["value"]
            errors = case[case["metric"] == error_metric]["value"]
            if not steps.empty:
                low, high = number(float(steps.min())), number(float(steps.max()))
                cells.append(f"{engine} {method} {low if low == high else f'{low}-{high}'} "
                             f"(error {number(float(errors.min()))}-{number(float(errors.max()))})")
        if cells:
            lines.append(f"**Best {label}-difference step** per engine over the scenes (error there): "
                         + "; ".join(cells) + ".")
    return [Heading(3, "Finite differences against the step"), *figure, *(Paragraph(line) for line in lines)]
