"""An IK scene's section: its figures, a row per engine in report.md (its best solver and its fastest reliable one),
in report.html the row per solver, every metric and the hard targets; and how a solver is said wherever the report
ranks one (the summary, a sweep's row, the hard cases)."""

from __future__ import annotations

import pandas as pd

from simparity.core.model.metric_catalogue import (
    CROSS_EVAL_SOLVE_RATE_MIN, ITERATIONS_MEDIAN, LIMIT_VIOLATIONS, OWN_STOP_POSITION_TOLERANCE,
    POSITION_RESIDUAL_MEDIAN, SOLVE_RATE, SOLVE_RATE_OWN_STOP, TIME_PER_SOLVE,
)
from simparity.core.model.results import HARD_VERDICT_SUFFIXES, NOT_AVAILABLE, OK
from simparity.reports import engine_summary, figures, summary, tables
from simparity.reports.blocks import SCENE_TABLE_TRIM_ORDER, Block, Bullets, Details, Paragraph, Table, number
from simparity.reports.sections.context import ReportContext
from simparity.reports.sections.shared import names

PROTOCOL = (
    "Protocol (TRAC-IK): seeded random reachable targets (end-effector poses of seeded random configurations "
    "within the limits), every solve from the scene's one start pose, success when the residuals are within "
    "the scene's tolerances and the joint values within their limits (an engine's solver that leaves them "
    "fails with `outside_limits`), time per solve = batch time / batch size with failed solves included. Each "
    "solution is also put through every engine's forward kinematics (worst solve rate and largest "
    "disagreement shown), so no solver passes on its own kinematics alone."
)
"""How every IK scene is measured, in the report's definitions."""

_COMPACT = (SOLVE_RATE, POSITION_RESIDUAL_MEDIAN, ITERATIONS_MEDIAN, TIME_PER_SOLVE, LIMIT_VIOLATIONS,
            CROSS_EVAL_SOLVE_RATE_MIN)


def hard_solved(rows: pd.DataFrame) -> tuple[int, int]:
    """(hard IK solves that succeeded, hard IK solves measured) of a scene's rows."""
    verdicts = rows[rows["metric"].str.startswith("hard_") & rows["metric"].str.endswith("_solved")
                    & (rows["status"] == OK)]
    return int(verdicts["value"].sum()), len(verdicts)


def _hard_cell(row) -> str:
    if row["status"] != OK:
        return row["status"]
    verdict = row["detail"].split(";")[0]
    return f"{'✓' if verdict == 'solved' else '✗ ' + verdict.removeprefix('failed: ')} {number(row['value'])} m"


def hard_table(rows: pd.DataFrame) -> list[Block]:
    """Engine x solver against each hard target: solved or the reason, with the position residual."""
    hard = rows[rows["metric"].str.startswith("hard_") & ~rows["metric"].str.endswith(HARD_VERDICT_SUFFIXES)]
    if hard.empty:
        return []
    metrics = list(dict.fromkeys(hard["metric"]))
    table_rows = []
    for (engine, solver), group in hard.groupby(["engine", "integrator"], sort=False):
        cells = {r["metric"]: _hard_cell(r) for _, r in group.iterrows()}
        table_rows.append(tuple([engine, solver] + [cells.get(n, "—") for n in metrics]))
    notes = hard[hard["status"] == OK].drop_duplicates("metric")
    return [Paragraph("Hard targets (✓ solved, ✗ the reason; position residual):"),
            Table(tuple(["engine", "solver"] + [n.removeprefix("hard_") for n in metrics]), tuple(table_rows)),
            Bullets(tuple(f"`{r['metric'].removeprefix('hard_')}`: {r['detail'].split('; ')[-1]}"
                          for _, r in notes.iterrows()))]


def section(ctx: ReportContext, scene, rows, about, reference, series) -> tuple[str, list[Block]]:
    """(the scene's verdict in one line, its blocks): figures, a row per engine in report.md (its best solver and
    its fastest reliable one), and in report.html the row per solver, every metric and the hard targets."""
    solvers = summary.ik_solvers(rows[~rows["metric"].str.startswith("hard_")])
    tolerance = about.get("position_tolerance")
    blocks = ctx.figure(figures.ik_rate_figure(scene, solvers, reference), f"{scene}-solve-rate",
                        "Solve rate against time per solve.")
    blocks += ctx.figure(figures.ik_distribution_figure(scene, series, tolerance),
                         f"{scene}-residuals", "Distributions of the position residual [m] and the iterations.")
    blocks += ctx.figure(figures.fk_matrix_figure(scene, series), f"{scene}-fk-agreement",
                         "Cross-engine FK agreement on every solution [m].")
    per_engine = []
    for engine in engine_summary.engine_order(solvers["engine"], truths=True):
        own = solvers[solvers["engine"] == engine]
        best, fastest = summary.best_ik(own)
        solved = int((own[SOLVE_RATE] > 0).sum())
        per_engine.append((engine, _rate_and_time(best), _rate_and_time(fastest),
                           f"{solved} of {len(own)} solve any target"))
    blocks.append(Table(("engine", "best solve rate, time per solve", f"fastest at ≥ {summary.SOLVED_ENOUGH:.0%}",
                         "solvers"),
                        tuple(per_engine), trim_order=SCENE_TABLE_TRIM_ORDER, keep_at_least=0))
    plain = rows[~rows["metric"].str.startswith("hard_")].rename(columns={"integrator": "solver"})
    measured = plain.groupby(["engine", "solver"], sort=False)["status"].transform(lambda s: (s != NOT_AVAILABLE).any())
    compact = [c for c in tables.IK_COLUMNS if c[0] in _COMPACT]
    blocks.append(Details("Per engine × solver", (*_own_rules(solvers, tolerance),
                                                  tables.metric_table(plain[measured], compact, ["engine", "solver"])),
                          markdown=False, open=True))
    hard = hard_table(rows)
    blocks.append(Details(f"{scene}: every metric and hard target",
                          (tables.metric_table(plain, tables.IK_COLUMNS, ["engine", "solver"]), *hard),
                          markdown=False))
    return _verdict(solvers, tolerance, hard_solved(rows), ctx.findings_of(scene)), blocks


def _rate_and_time(solver: pd.Series | None) -> str:
    """A solver in an engine's row: ``dls: 90.0 %, 0.000949 s``."""
    return "none" if solver is None else f"{solver['integrator']}: {solver[SOLVE_RATE]:.1%}, {number(solver[TIME_PER_SOLVE])} s"


def _verdict(solvers: pd.DataFrame, tolerance: float | None, hard: tuple[int, int], findings: int) -> str:
    """An IK scene in one line: its best solver, its fastest reliable one, the solvers that solve nothing at the
    scene's tolerance, the hard targets solved and the findings."""
    best, fastest = summary.best_ik(solvers)
    reliable = f"fastest at ≥ {summary.SOLVED_ENOUGH:.0%}: " + ("the same" if fastest is not None and best is not None
                                                               and fastest.name == best.name
                                                               else solver_text(fastest, tolerance))
    parts = [f"best {solver_text(best, tolerance)}", reliable]
    none = [f"{r['engine']} {r['integrator']}" for _, r in solvers.iterrows() if r[SOLVE_RATE] == 0]
    if none:
        parts.append(f"{len(none)} solve none at the scene's tolerance ({names(none, 2)})")
    if hard[1]:
        parts.append(f"hard targets: {hard[0]} of {hard[1]} solves succeeded")
    return "; ".join(parts + [f"{findings} finding{'s' if findings != 1 else ''}"])


def solver_text(row: pd.Series | None, position_tolerance: float | None) -> str:
    """A ranked solver: its rate at the scene's ``position_tolerance`` [m] (None: not known), time per solve,
    and its rate at its own stopping rule where that rule is not the scene's."""
    if row is None:
        return "none"
    return f"{row['engine']} {row['integrator']}: {rates(row, position_tolerance)}, {number(row[TIME_PER_SOLVE])} s"


def rates(row: pd.Series, position_tolerance: float | None) -> str:
    """``97.0 %`` or ``0.0 % at 1e-06 m, 97.0 % at its own 0.0001 m``: the solve rate at the scene's tolerance
    [m], and at the solver's own stopping rule where it has one."""
    at = "" if position_tolerance is None else f" at {position_tolerance:g} m"
    text = f"{row[SOLVE_RATE]:.1%}{at}"
    if summary.own_rule_differs(row, position_tolerance):
        own = row[SOLVE_RATE_OWN_STOP]
        text += f", {'n/a' if pd.isna(own) else f'{own:.1%}'} at its own {row[OWN_STOP_POSITION_TOLERANCE]:g} m"
    return text


def _own_rules(solvers: pd.DataFrame, position_tolerance: float | None) -> list[Block]:
    """The solvers of an IK scene that stop by a rule of their own, each with both solve rates."""
    own = [f"{r['engine']} {r['integrator']}: {rates(r, position_tolerance)}" for _, r in solvers.iterrows()
           if summary.own_rule_differs(r, position_tolerance) and pd.notna(r[SOLVE_RATE])]
    if not own:
        return []
    return [Paragraph("Solvers that stop by a rule of their own (a library's default threshold; the rule is in the "
                      f"`{SOLVE_RATE_OWN_STOP}` row's detail), at the scene's tolerance and at their own:"),
            Bullets(tuple(own))]
