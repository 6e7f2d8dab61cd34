"""The report's summary: which integrator (each engine's own choices over the dynamics scenes, then a row per scene
or sweep: the cheapest scheme within each error budget and the most accurate within each cost budget), which IK
solver (a row per scene or sweep), the joint-space dynamics line, the flagged findings and the cases without a
result (:mod:`reports.sections.findings`)."""

from __future__ import annotations

from simparity.core.model.metric_catalogue import SOLVE_RATE, TIME_PER_SOLVE
from simparity.core.model.results import GROUND_TRUTH_ENGINES, OK
from simparity.reports import engine_summary, summary, sweep_sections, sweep_summary
from simparity.reports.blocks import Block, Heading, Paragraph, Table, scene_heading
from simparity.reports.sections import findings, joint_dynamics
from simparity.reports.sections.context import HEADLINE_NAMES, ReportContext, heading_kind, headline, scene_kind
from simparity.reports.sections.dynamics import scheme
from simparity.reports.sections.ik import solver_text
from simparity.reports.sweep_summary import Sweep

SCENE_SUMMARY_TRIM_ORDER = 4
"""Where the summary's row per scene stands among the tables report.md may shorten to stay within its line budget
(:attr:`reports.blocks.Table.trim_order`): last, after a user's engine's table, and down to no row if it must, since
every scene's own section below opens with the same verdict (a suite past ~26 scenes outgrew 400 lines with every
other table at its minimum)."""

_SWEEP_ROWS_DYNAMICS = Paragraph(
    "A sweep has one row, linked to its section: each engine × integrator × dt is ranked by its worst variant (its "
    "error the largest over the variants, its cost the median), and a case that is not ok in every variant is not "
    "ranked.")
_SWEEP_ROWS_IK = Paragraph(
    "A sweep has one row, linked to its section: each solver is ranked by its lowest solve rate over the variants and "
    "its median time per solve, and a solver not measured in every variant is not ranked.")


def _ranking_text(by: str) -> str:
    """What the summary ranks by, and why that is fair."""
    truths = f"Ground truths ({', '.join(GROUND_TRUTH_ENGINES)}) are not ranked."
    if by == summary.WALL:
        return ("Ranked by wall time per simulated second [s/s]: this run has no force evaluation counts (its "
                "engines declare no stages). Within one engine that is fair (its per-call overhead is shared); across "
                f"engines it also measures each one's overhead per call. {truths}")
    return ("Ranked by force evaluations per simulated second (stages / dt: Hairer's hardware-neutral work, blind to "
            "per-call overhead), ties by wall time: \"cheapest\" counts force evaluations, never the clock, and each "
            "pick shows them (\"400/s\") beside its measured wall time per simulated second (\"2.1 ms\"; "
            "report.html has it per scheme, and the batched time). "
            f"{truths[:-1]}; schemes without a stage count only within their engine.")


def _ran_on(engine: str, per_scene: list[dict]) -> str:
    """An engine in the per-engine table: its name, and on how many of the scenes it ran where not on all."""
    ran = sum(engine in scene for scene in per_scene)
    return engine if ran == len(per_scene) else f"{engine} ({ran} of {len(per_scene)} scenes)"


def _sweep_row(sweep: Sweep, by: str) -> tuple[str, ...]:
    """A sweep's row of the summary's table for its kind: its schemes judged by their worst variant."""
    link = (f"[{sweep_summary.label(sweep.base)}](#{sweep_sections.heading(sweep.base).anchor}) "
            f"({len(sweep.variants)} variants)")
    ranked = sweep.across[sweep.across["status"] == OK]
    if sweep.kind == "ik":
        best, fastest = summary.best_ik(ranked.rename(columns={"value": SOLVE_RATE, "cost": TIME_PER_SOLVE}))
        return link, solver_text(best, None), solver_text(fastest, None)
    name, unit = HEADLINE_NAMES[sweep.metric]
    cases = ranked.rename(columns={"value": "error"})
    return ((link, f"{name.removesuffix(' error max')} [{unit}] vs `{sweep.reference}`")
            + tuple(engine_summary.overall(cases, b, by) for b in summary.ERROR_BUDGETS)
            + tuple(scheme(summary.most_accurate_within(cases, b, by), unit) for b in summary.cost_budgets(by)))


def _per_engine_table(ctx: ReportContext) -> list[Block]:
    """The per-engine answer over the run's dynamics scenes (sweeps have theirs in their section): how often each
    scheme of an engine was its own cheapest within each error budget and most accurate within each cost
    budget."""
    per_scene = [ctx.choices(scene, cases) for scene, cases in ctx.cases.items()]
    if not per_scene:
        return []
    tallies = engine_summary.tally(per_scene, ctx.info.integrator_variants)
    columns = [f"error ≤ {b:g}" for b in summary.ERROR_BUDGETS] + [summary.cost_label(ctx.by, b)
                                                                   for b in summary.cost_budgets(ctx.by)]
    head = ("engine",) + tuple(engine_summary.cheapest_head(ctx.by, b) for b in summary.ERROR_BUDGETS) + tuple(
        f"most accurate at {c}" for c in columns[len(summary.ERROR_BUDGETS):])
    return [Paragraph(f"Each engine's own scheme (its variants together) over {len(per_scene)} scenes (\"rk4 ×9\": "
                      "on 9; \"none\": no "
                      "scheme of it reached the budget; n/a, diverged: why it had none), then the overall best per "
                      "scene (\"+k as cheap\": k others do the same work)."),
            Table(head, tuple((_ran_on(engine, per_scene),) + tuple(cells.get(c, "none") for c in columns)
                              for engine, cells in tallies.items()))]


def section(ctx: ReportContext) -> list[Block]:
    """The "Summary" section, in order: which integrator, which IK solver, the joint-space dynamics line, the flagged
    findings, the cases without a result."""
    blocks: list[Block] = [Heading(2, "Summary")]
    dyn_rows: list[tuple[str, ...]] = []
    ik_rows: list[tuple[str, ...]] = []
    swept: set[str] = set()
    by = ctx.by
    for scene, rows in ctx.table.groupby("scene", sort=False):
        kind, about = scene_kind(rows), ctx.about(scene)
        if scene in ctx.sweep_of:
            sweep = ctx.sweep_of[scene]
            if sweep.base not in swept and kind in ("dynamics", "ik"):
                (dyn_rows if kind == "dynamics" else ik_rows).append(_sweep_row(sweep, by))
            swept.add(sweep.base)
        elif kind == "dynamics":
            name, unit = HEADLINE_NAMES[headline(about)]
            cases = ctx.cases[scene]
            cells = [f"[{scene}](#{scene_heading(scene, heading_kind(about, kind)).anchor})",
                     f"{name.removesuffix(' error max')} [{unit}] vs `{rows['reference'].iloc[0]}`"]
            cells += [engine_summary.overall(cases, b, by) for b in summary.ERROR_BUDGETS]
            cells += [scheme(summary.most_accurate_within(cases, b, by), unit) for b in summary.cost_budgets(by)]
            dyn_rows.append(tuple(cells))
        elif kind == "ik":
            best, fastest = summary.best_ik(summary.ik_solvers(rows[~rows["metric"].str.startswith("hard_")]))
            tolerance = about.get("position_tolerance")
            ik_rows.append((f"[{scene}](#{scene_heading(scene, kind).anchor})", solver_text(best, tolerance),
                            solver_text(fastest, tolerance)))
    if dyn_rows:
        blocks += [Heading(3, "Which integrator?"), Paragraph(_ranking_text(by)), *_per_engine_table(ctx),
                   Table(("scene", "error (reference)") + tuple(engine_summary.cheapest_head(by, b)
                                                                for b in summary.ERROR_BUDGETS)
                         + tuple(f"most accurate at {summary.cost_label(by, b)}" for b in summary.cost_budgets(by)),
                         tuple(dyn_rows), trim_order=SCENE_SUMMARY_TRIM_ORDER, keep_at_least=0),
                   *([_SWEEP_ROWS_DYNAMICS] if any(s.kind == "dynamics" for s in ctx.sweeps) else [])]
    if ik_rows:
        blocks += [Heading(3, "Which IK solver?"),
                   Paragraph(f"Best solve rate (the faster on a tie) and the fastest at ≥ "
                             f"{summary.SOLVED_ENOUGH:.0%}, at the scene's position tolerance (a solver with a "
                             "looser rule of its own: its rate at that rule beside it)."),
                   Table(("scene", "best solve rate", f"fastest at ≥ {summary.SOLVED_ENOUGH:.0%}"),
                         tuple(ik_rows)),
                   *([_SWEEP_ROWS_IK] if any(s.kind == "ik" for s in ctx.sweeps) else [])]
    return blocks + joint_dynamics.summary_line(ctx) + findings.section(ctx) + findings.unresolved(ctx)
