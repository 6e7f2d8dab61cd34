"""A dynamics scene's section (free bodies, contact, a chain in motion): its figures, a row per engine in report.md
(its most accurate scheme, its cheapest within each error budget, its orders or contact measures, its cases), in
report.html the row per engine × integrator and every engine × integrator × dt; a chaotic scene's predictability."""

from __future__ import annotations

import math

import pandas as pd

from simparity.core.model.metric_catalogue import (
    CHAIN_ANGULAR_MOMENTUM_DRIFT_MAX, CONTACT_ENERGY_GAIN_MAX, CONTACT_PENETRATION_MAX, JOINT_ANGLE_ERROR_MAX,
    LINEAR_MOMENTUM_DRIFT_MAX, REFERENCE_PARTING_TIME, REST_ACCELERATION_MAX, REST_EQUILIBRIUM_ERROR, REST_WEIGHT_ERROR,
    SELF_PARTING_TIME,
    SIGNORINI_VIOLATION_MAX, TIME_PER_STEP, TOUCHDOWN_TIME_ERROR,
)
from simparity.core.model.results import NOT_AVAILABLE, OK
from simparity.reports import engine_summary, figures, summary, tables
from simparity.reports.blocks import SCENE_TABLE_TRIM_ORDER, Block, Bullets, Details, Paragraph, Table, number
from simparity.reports.sections import contact
from simparity.reports.sections.context import HEADLINE_NAMES, ReportContext, headline

OVERHEAD_MARK = "†"
"""The mark on core's time per step where the scene's batch is small enough for per-call overhead to dominate."""


def scheme(case: pd.Series | None, unit: str) -> str:
    """A case the summary picked for its accuracy: ``mujoco rk4 @ 0.01: 1.09e-08 rad``."""
    if case is None:
        return "none"
    return f"{case['engine']} {case['integrator']} @ {number(case['dt'])}: {number(case['error'])} {unit}"


def _overhead_mark(engine: str, about: dict) -> str:
    """A mark on core's time when the scene's batch is small enough for per-call overhead to dominate."""
    bodies = about.get("bodies")
    return f" {OVERHEAD_MARK}" if engine == "core" and bodies is not None and bodies < summary.OVERHEAD_DOMINATED_BODIES else ""


def _fits(orders: pd.DataFrame) -> list[Block]:
    fitted = orders[orders["status"] == OK]
    return [Bullets(tuple(f"{r['engine']} {r['integrator']} `{r['metric']}` = {number(r['value'])}: {r['detail']}"
                          for _, r in fitted.iterrows()))] if not fitted.empty else []


def _predictability(rows: pd.DataFrame) -> list[Block]:
    """A chaotic scene's predictability at its finest time step (Chung and Pollard): when each scheme's run parts
    from its own run from a perturbed start, beside when it parts from the reference; nothing where not measured."""
    parting = rows[rows["metric"].isin([SELF_PARTING_TIME, REFERENCE_PARTING_TIME]) & rows["dt"].notna()]
    if parting.empty:
        return []
    finest = parting[parting["dt"] == parting["dt"].min()]
    cells = {(r["engine"], r["integrator"], r["metric"]): (f"{r['value']:.3g}" if r["status"] == OK else "not within "
                                                             "the run" if "whole run" in str(r["detail"]) else r["status"])
             for _, r in finest.iterrows()}
    cases = list(dict.fromkeys(zip(finest["engine"], finest["integrator"])))
    return [Paragraph(f"Predictability at dt = {finest['dt'].iloc[0]:g} s: when each scheme's run parts (a joint 1e-3 "
                      "rad off) from its own run from a start perturbed by the scene's perturbation, and from the "
                      "reference's; parting from the reference no later than from itself is the chain's chaos, not a "
                      "defect."),
            Table(("engine", "integrator", "parts from itself [s]", "parts from the reference [s]"),
                  tuple((e, i, cells.get((e, i, SELF_PARTING_TIME), "—"), cells.get((e, i, REFERENCE_PARTING_TIME), "—"))
                        for e, i in cases))]


def _finest_table(rows: pd.DataFrame, columns: tuple[tuple[str, str], ...], about: str) -> list[Block]:
    """A row per engine and integrator of ``columns`` ((metric, heading) pairs) at the scene's finest time step, after
    the paragraph ``about`` (formatted with ``dt``); the cases the engine cannot do left out (the scene's n/a table has
    them); nothing where none is left."""
    names = [m for m, _ in columns]
    measured = rows[rows["metric"].isin(names) & rows["dt"].notna()]
    if measured.empty:
        return []
    finest = measured[measured["dt"] == measured["dt"].min()]
    cells = {(r["engine"], r["integrator"], r["metric"]): number(r["value"]) if r["status"] == OK else r["status"]
             for _, r in finest.iterrows()}
    shown = finest[finest["status"] != NOT_AVAILABLE]  # an engine that cannot do the scene is in the n/a table
    cases = list(dict.fromkeys(zip(shown["engine"], shown["integrator"])))
    if not cases:
        return []
    return [Paragraph(about.format(dt=f"{finest['dt'].iloc[0]:g}")),
            Table(("engine", "integrator") + tuple(head for _, head in columns),
                  tuple((e, i) + tuple(cells.get((e, i, m), "—") for m in names) for e, i in cases),
                  trim_order=SCENE_TABLE_TRIM_ORDER, keep_at_least=0)]  # report.html has every row


def _momentum(rows: pd.DataFrame) -> list[Block]:
    """A floating base's momentum laws at the scene's finest time step (issue #46): each scheme's drift of its linear
    and angular momentum from its own model; nothing where not measured."""
    return _finest_table(rows, ((LINEAR_MOMENTUM_DRIFT_MAX, "linear momentum drift"),
                                (CHAIN_ANGULAR_MOMENTUM_DRIFT_MAX, "angular momentum drift")),
                         "Momentum at dt = {dt} s: joint forces are internal, so each engine's own momentum keeps its "
                         "law (linear: grows by m g t; angular about the centre of mass: conserved); its drift relative "
                         "to the momentum the motion about the centre of mass carries.")


CHAIN_CONTACT_COLUMNS = ((TOUCHDOWN_TIME_ERROR, "touchdown error"), (CONTACT_PENETRATION_MAX, "penetration / radius"),
                         (SIGNORINI_VIOLATION_MAX, "Signorini violation"), (CONTACT_ENERGY_GAIN_MAX, "energy gain"),
                         (REST_WEIGHT_ERROR, "rest weight error"), (REST_EQUILIBRIUM_ERROR, "rest equilibrium error"),
                         (REST_ACCELERATION_MAX, "rest acceleration"))
"""The contact metrics report.md shows for a chain on a plane, each with its column's name."""


def _chain_contact(rows: pd.DataFrame) -> list[Block]:
    """A chain's contact truths at the scene's finest time step (issue #46): each engine and integrator's own run;
    nothing where the scene has no contact."""
    return _finest_table(rows, CHAIN_CONTACT_COLUMNS,
                         "Contact at dt = {dt} s, truths that need no engine: touchdown against the closed-form fall, "
                         "the deepest penetration, pulls or forces off the plane, energy gained, and at rest the plane "
                         "carrying the weight and every joint balanced (by Pinocchio's model), nothing accelerating from "
                         "when the scene says its robot rests (each engine's contact is its own: no reference).")


def _contact_verdict(rows: pd.DataFrame) -> str:
    """A scene with contact in one line: no reference (each engine against truths that need none), the engines that
    measured them and the cases without a result."""
    names = [m for m, _ in CHAIN_CONTACT_COLUMNS]
    measured = rows[rows["metric"].isin(names) & (rows["status"] == OK)]
    engines = ", ".join(engine_summary.engine_order(measured["engine"])) or "no engine"
    statuses = rows[rows["metric"] == names[0]]["status"].value_counts()
    cases = ", ".join(f"{s} {n}" for s, n in statuses.items())
    return f"contact, no reference: {engines} measured against truths that need no engine; cases {cases}"


def scheme_row(engine: str, scheme: str, members: list[tuple[str, tuple[str, ...]]]) -> tuple[str, ...]:
    """One compact-table row for the variants of a scheme (core's orientation updates): each cell lists
    the variants' values in the order the integrator cell names them, or one value where they agree."""
    if len(members) == 1 and not members[0][0]:
        return (engine, scheme, *members[0][1])
    names = " / ".join(variant for variant, _ in members)
    cells = [cells for _, cells in members]
    return (engine, f"{scheme} ({names})",
            *(column[0] if len(set(column)) == 1 else " / ".join(column) for column in zip(*cells)))


def section(ctx: ReportContext, scene, rows, about, reference, series) -> tuple[str, list[Block]]:
    """(the scene's verdict in one line, its blocks): figures, a row per engine in report.md (its most accurate
    scheme, its cheapest within each error budget, its orders or contact measures, its cases), and in report.html
    the row per engine × integrator and every engine × integrator × dt."""
    metric = headline(about)
    name, unit = HEADLINE_NAMES[metric]
    cases = ctx.cases[scene] if scene in ctx.cases else summary.dynamics_cases(rows, metric)
    observed = summary.orders(rows, metric)
    theory = ctx.info.theoretical_orders
    blocks = ctx.figure(figures.work_precision_figure(scene, cases, metric, reference,
                                                      ctx.info.integrator_variants),
                        f"{scene}-work-precision",
                        f"Work-precision: x = {name} [{unit}] (log), y = wall time per simulated second [s/s] "
                        "(log; below, where counted: force evaluations per simulated second, the hardware-neutral "
                        "cost); one point per dt, lower left is better. A scheme's variants share its colour, one "
                        "marker each; dotted: the summary's error budgets.")
    if not about.get("contact"):  # with contact the error has no order (impacts), so no convergence figure
        order_rows = rows[rows["dt"].isna() & (rows["metric"] == summary.ORDER_METRICS[metric])
                          & (rows["status"] != OK)]
        unfitted = {(r["engine"], r["integrator"]): r["detail"] for _, r in order_rows.iterrows()}
        blocks += ctx.figure(figures.convergence_figure(scene, cases, metric, reference, observed, theory,
                                                        unfitted),
                             f"{scene}-convergence", f"Convergence: x = time step dt [s] (log), y = {name} "
                             f"[{unit}] (log); observed order (theory) in the legend, grey dashed: a line of each "
                             "theoretical order's slope; schemes whose errors agree to 0.1 % share one line.")
    blocks += ctx.figure(figures.drift_figure(scene, series, reference), f"{scene}-drift",
                         "Drift over time at the coarsest dt, from the stored series.")
    fits = engine_summary.fitted_orders(rows, metric, theory)
    touching = contact.section(ctx, scene, rows, about, reference, series) if about.get("contact") else None
    blocks += touching.figure if touching else []
    blocks += [_per_engine(ctx, scene, cases, fits, unit, touching), _per_scheme(ctx, cases, observed, about, unit)]
    blocks += touching.blocks if touching else []
    blocks += _predictability(rows) + _momentum(rows) + _chain_contact(rows)
    columns, order_columns = ((tables.JOINT_MOTION_COLUMNS, tables.JOINT_ORDER_COLUMNS)
                              if metric == JOINT_ANGLE_ERROR_MAX else (tables.DYNAMICS_COLUMNS, tables.ORDER_COLUMNS))
    full: list[Block] = [tables.metric_table(rows[rows["dt"].notna()], columns, ["engine", "integrator", "dt"])]
    orders = rows[rows["dt"].isna()]
    if not orders.empty:
        explained: list[Block] = [
            Paragraph("Observed order of convergence: slope of log(error max) against log(dt) over the finest "
                      "time steps whose local slopes agree; errors at the rounding floor or saturated are left out."),
            tables.metric_table(orders, order_columns, ["engine", "integrator"])]
        full += explained + _fits(orders)
    verdict = engine_summary.dynamics_verdict(cases, fits, ctx.findings_of(scene), unit,
                                              engine_summary.order_alarms(rows, metric))
    if rows["metric"].isin([m for m, _ in CHAIN_CONTACT_COLUMNS]).any():
        verdict = _contact_verdict(rows)
    return verdict, blocks + [Details(f"{scene}: every engine × integrator × dt", tuple(full), markdown=False)]


def _per_engine(ctx: ReportContext, scene: str, cases: pd.DataFrame, fits: pd.DataFrame, unit: str,
                touching: contact.Contact | None) -> Table:
    """report.md's table of a dynamics scene: a row per engine (the user's first) with its most accurate scheme,
    its cheapest within each error budget (by the summary's cost), its fitted orders against theory (a contact
    scene: its measured restitution and worst penetration) and how its cases ended."""
    choices = ctx.choices(scene, cases)
    rows = []
    for engine, picks in choices.items():
        own = cases[cases["engine"] == engine]
        best = engine_summary.most_accurate(own)
        accurate = engine_summary.pick(best if best is not None else engine_summary.unmeasured(own), ctx.by,
                                       show_error=True)
        ranked_by = engine_summary.own_cost(own, ctx.by)
        budgets = [engine_summary.pick(picks[f"error ≤ {b:g}"], ranked_by, show_error=False)
                   for b in summary.ERROR_BUDGETS]
        measures = (touching.per_engine.get(engine, ("—", "—")) if touching else
                    (engine_summary.orders_text(fits[fits["engine"] == engine]),))
        statuses = ", ".join(f"{k} {n}" for k, n in own["status"].value_counts().items())
        rows.append((engine, accurate, *budgets, *measures, statuses))
    measured = (("restitution measured", "penetration max [m]") if touching else ("orders vs theory",))
    return Table(("engine", f"most accurate [{unit}]") + tuple(engine_summary.cheapest_head(ctx.by, b)
                                                             for b in summary.ERROR_BUDGETS)
                 + measured + ("cases",), tuple(rows), trim_order=SCENE_TABLE_TRIM_ORDER, keep_at_least=0)


def _per_scheme(ctx: ReportContext, cases: pd.DataFrame, observed: dict, about: dict, unit: str) -> Details:
    """Per engine × integrator (variants of a scheme on one row): the time step of least error with its error,
    wall time, force evaluations and batched time per simulated second, time per step, observed order (theory)
    and how its time steps ended; unfolded in report.html, not in report.md (which has a row per engine)."""
    theory = ctx.info.theoretical_orders
    best = summary.best_per_scheme(cases)
    variants = ctx.info.integrator_variants
    per_scheme: dict[tuple[str, str], list[tuple[str, tuple[str, ...]]]] = {}
    for _, b in best[best["any_result"]].iterrows():
        p = theory.get(b["engine"], {}).get(b["integrator"])
        fitted = observed.get((b["engine"], b["integrator"]), math.nan)
        name, variant = variants.get(b["engine"], {}).get(b["integrator"], (b["integrator"], ""))
        per_scheme.setdefault((b["engine"], name), []).append((variant, (
            number(b["dt"]), number(b["error"]), number(b["cost"]), number(b[summary.EVALUATIONS]),
            number(b["batched_cost"]), number(b[TIME_PER_STEP]) + _overhead_mark(b["engine"], about),
            f"{number(fitted)} ({p})" if p else number(fitted), b["statuses"])))
    table = Table(("engine", "integrator", "best dt [s]", f"error [{unit}]", "cost [s/s]", "evaluations [1/s]",
                   "batched cost [s/s]", "time per step [s]", "order (theory)", "time steps"),
                  tuple(scheme_row(engine, name, members) for (engine, name), members in per_scheme.items()))
    return Details("Per engine × integrator: the time step of least error (batched cost: one copy's share of a "
                   "batch stepped together, where the engine can batch)", (table,), markdown=False, open=True)
