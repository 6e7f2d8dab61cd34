"""Which integrator, engine by engine (issue #26): for each engine (the user's own first: core, then plugins), its
own cheapest scheme at each error budget and its most accurate within each cost budget, per scene and counted over
the run's dynamics scenes; and each scene's verdict in one line. Computed from a stored run's cases (:func:`reports.
summary.dynamics_cases`), never by running anything.
"""

from __future__ import annotations

from collections import Counter
from typing import TypeAlias

import pandas as pd

from simparity.core.model.results import (
    BELOW_THEORY, GROUND_TRUTH_ENGINES, NOT_AVAILABLE, NOT_CONVERGING, OK, SUPERCONVERGENT,
)
from simparity.reports import summary
from simparity.reports.blocks import number

THIRD_PARTY_ENGINES = ("mujoco", "pybullet", "pinocchio")
"""The engines simparity compares against. Every other engine of a run that is not a ground truth is the user's own
(core, a plugin) and is listed first: their schemes are the ones a user picks between."""

SCHEMES_NAMED = 3
"""Schemes a cell of the per-engine table names before it counts the rest: a row stays one line."""


def engine_order(engines, truths: bool = False) -> list[str]:
    """``engines`` with core first, then plugins in run order, then the third-party engines in
    :data:`THIRD_PARTY_ENGINES` order; ground truths left out, or last with ``truths`` (an IK scene's analytic
    solver is a solver a user may pick)."""
    present = [e for e in dict.fromkeys(engines) if e not in GROUND_TRUTH_ENGINES]
    own = [e for e in present if e == "core"] + [e for e in present if e != "core" and e not in THIRD_PARTY_ENGINES]
    last = [e for e in dict.fromkeys(engines) if e in GROUND_TRUTH_ENGINES] if truths else []
    return own + [e for e in THIRD_PARTY_ENGINES if e in present] + last


NO_STAGE_COUNT = "n/a (no stage count)"
"""A work-budget cell of an engine that declares no stage count: its schemes are ranked among themselves by wall
time, which no work budget bounds."""

Choice: TypeAlias = "pd.Series | str | None"
"""An engine's case for a budget; a reason it has none to rank (:data:`NO_STAGE_COUNT`, :func:`unmeasured`); None
where none of its cases qualifies."""

ERROR_NOT_MEASURED = "error n/a"
"""An engine whose cases ran but measured no headline error (saturated, or nothing to measure it against)."""


def unmeasured(own: pd.DataFrame) -> str | None:
    """Why an engine's cases of a scene measured no headline error: "failed" or "diverged" (none ok, some of that
    status, the graver first), "n/a" (every case n/a: it cannot run the scene), :data:`ERROR_NOT_MEASURED`; None
    when some case measured one."""
    if not summary.measured(own, None).empty:
        return None
    statuses = set(own["status"])
    return next((s for s in ("failed", "diverged") if s in statuses),
                "n/a" if statuses <= {NOT_AVAILABLE} else ERROR_NOT_MEASURED)


def own_cost(own: pd.DataFrame, by: str) -> str:
    """The cost one engine's cases ``own`` are ranked by among themselves: the run's ``by``, or wall time where any
    of its measured cases counted no force evaluations (a plugin that declares no stages for some scheme: ranking by
    work would drop that scheme); within one engine wall time is fair, its overhead is shared."""
    return summary.WALL if by not in own or summary.measured(own, None)[by].isna().any() else by


def choices(cases: pd.DataFrame, by: str) -> dict[str, dict[str, Choice]]:
    """{engine: {column: its choice}} for one scene's cases: per engine the cheapest (by :func:`own_cost`) within
    each of :data:`reports.summary.ERROR_BUDGETS` (column ``error ≤ B``) and the most accurate within each cost
    budget of ``by`` (column :func:`reports.summary.cost_label`; :data:`NO_STAGE_COUNT` for an engine ranked by wall
    time in a run ranked by evaluations); None where none of its cases qualifies."""
    out: dict[str, dict[str, Choice]] = {}
    columns = [f"error ≤ {b:g}" for b in summary.ERROR_BUDGETS] + [summary.cost_label(by, b)
                                                                   for b in summary.cost_budgets(by)]
    for engine in engine_order(cases["engine"]):
        own = cases[cases["engine"] == engine]
        reason = unmeasured(own)
        if reason:
            out[engine] = dict.fromkeys(columns, reason)
            continue
        ranked_by = own_cost(own, by)
        picks: dict[str, Choice] = {f"error ≤ {b:g}": summary.cheapest_within(own, b, ranked_by)
                                    for b in summary.ERROR_BUDGETS}
        picks |= {summary.cost_label(by, b): (summary.most_accurate_within(own, b, by) if ranked_by == by
                                              else NO_STAGE_COUNT) for b in summary.cost_budgets(by)}
        out[engine] = picks
    return out


def tally(per_scene: list[dict[str, dict[str, Choice]]], variants: dict | None = None) -> dict[str, dict[str, str]]:
    """{engine: {column: "rk4 ×9, midpoint ×2, none ×1, n/a ×2"}}: how often each of an engine's schemes was its
    choice over the scenes (:func:`choices` of each), the most frequent first, at most :data:`SCHEMES_NAMED` named
    and the rest counted; then, always named, how often it had none ("none": no scheme reached the budget) or a
    reason for none (n/a, diverged, :data:`ERROR_NOT_MEASURED`, :data:`NO_STAGE_COUNT`). The variants of a scheme
    (``variants``: run.json's ``integrator_variants``; core's orientation updates) count as their scheme: which of
    them a budget picks is decided by wall-time noise."""
    counts: dict[str, dict[str, Counter]] = {}
    for scene in per_scene:
        for engine, picks in scene.items():
            for column, case in picks.items():
                key = (True, "none") if case is None else (True, case) if isinstance(case, str) else (
                    False, (variants or {}).get(engine, {}).get(case["integrator"], (case["integrator"], ""))[0])
                counts.setdefault(engine, {}).setdefault(column, Counter())[key] += 1
    out: dict[str, dict[str, str]] = {}
    for engine in engine_order(counts):
        out[engine] = {}
        for column, counter in counts[engine].items():
            schemes = [(name, n) for (reason, name), n in counter.most_common() if not reason]
            reasons = [(name, n) for (reason, name), n in counter.most_common() if reason]
            named = [f"{name} ×{n}" for name, n in schemes[:SCHEMES_NAMED]]
            rest = sum(n for _, n in schemes[SCHEMES_NAMED:])
            named += [f"others ×{rest}"] if rest else []
            named += [name if name == NO_STAGE_COUNT else f"{name} ×{n}" for name, n in reasons]
            out[engine][column] = ", ".join(named)
    return out


def pick(case: Choice, by: str, show_error: bool) -> str:
    """One engine's choice in a cell: ``rk4 @ 0.01 (400/s, 2.1 ms)`` (its cost by ``by``, :func:`cost_text`) or ``rk4 @ 0.04: 3.1e-07`` (its
    error); "none", or the reason it has none."""
    if case is None or isinstance(case, str):
        return case or "none"
    head = f"{case['integrator']} @ {number(case['dt'])}"
    return f"{head}: {number(case['error'])}" if show_error else f"{head} ({cost_text(case, by)})"


def cost_text(case: pd.Series, by: str) -> str:
    """A case's cost as the ranking counts it, beside its measured wall time so neither passes for the other (the
    column head says which is which, :func:`cheapest_head`): ``400/s, 2.1 ms`` (force evaluations per simulated
    second, ranked by them; then milliseconds of wall time per simulated second) or ``2.1 ms`` (ranked by wall
    time)."""
    wall = case.get(summary.WALL)
    wall_text = f"{milliseconds(wall)} ms" if wall is not None and pd.notna(wall) else "wall n/a"
    return f"{number(case[by])}/s, {wall_text}" if by == summary.EVALUATIONS else wall_text


def milliseconds(seconds: float) -> str:
    """A wall time in milliseconds, two significant digits (whole milliseconds from 10 on): a cell's aside."""
    value = seconds * 1e3
    return f"{value:.0f}" if value >= 10 else f"{value:.2g}"


def cheapest_head(by: str, budget: float) -> str:
    """A column head of the cheapest scheme within an error ``budget``, saying what it counts and what its cells
    show (:func:`cost_text`): ``cheapest at error ≤ 0.001 (force evals/s; wall ms/s)``."""
    counted = "force evals/s; wall ms/s" if by == summary.EVALUATIONS else "wall ms/s"
    return f"cheapest at error ≤ {budget:g} ({counted})"


def overall(cases: pd.DataFrame, budget: float, by: str) -> str:
    """The cheapest case of every engine within an error ``budget``, by ``by``: ``mujoco rk4 @ 0.01 (400/s, 2.1 ms;
    +2 as cheap)``, naming how many others do the same work within it; "none"."""
    least = summary.equally_cheap(cases, budget, by)
    if least.empty:
        uncounted = summary.measured(cases, None)
        uncounted = uncounted[(uncounted["error"] <= budget) & uncounted[by].isna()] if by in cases else uncounted[0:0]
        return f"none counted ({_schemes(len(uncounted))} without a stage count within)" if len(uncounted) else "none"
    best = least.iloc[0]
    tied = f"; +{len(least) - 1} as cheap" if len(least) > 1 else ""
    return f"{best['engine']} {best['integrator']} @ {number(best['dt'])} ({cost_text(best, by)}{tied})"


def _schemes(n: int) -> str:
    return f"{n} case" + ("s" if n != 1 else "")


def orders_text(observed: pd.DataFrame) -> str:
    """How the fitted orders compare with theory: ``11 of 13 as theory; below: core x; above: …``; ``no fit``."""
    if observed.empty:
        return "no fit"
    away = observed[observed["flag"].isin((BELOW_THEORY, SUPERCONVERGENT))]
    text = f"{len(observed) - len(away)} of {len(observed)} as theory"
    for flag, word in ((BELOW_THEORY, "below"), (SUPERCONVERGENT, "above")):
        names = [f"{r['engine']} {r['integrator']} {number(r['value'])}" for _, r in away[away["flag"] == flag].iterrows()]
        if names:
            text += f"; {word}: " + ", ".join(names[:2]) + (f" (+{len(names) - 2})" if len(names) > 2 else "")
    return text


def fitted_orders(rows: pd.DataFrame, headline: str, theory: dict) -> pd.DataFrame:
    """The ok fits of the headline error's order of the schemes with a theoretical order (ground truths and the
    reference's own scheme left out): engine, integrator, value, flag."""
    fits = rows[rows["dt"].isna() & (rows["metric"] == summary.ORDER_METRICS[headline]) & (rows["status"] == OK)
                & ~rows["engine"].isin(GROUND_TRUTH_ENGINES)
                & (rows["engine"] + ":" + rows["integrator"] != rows["reference"])]
    known = fits.apply(lambda r: theory.get(r["engine"], {}).get(r["integrator"]) is not None, axis=1)
    return fits[known.astype(bool)] if not fits.empty else fits


def most_accurate(own: pd.DataFrame) -> pd.Series | None:
    """An engine's most accurate case (errors within :data:`reports.summary.AGREE_RELATIVE` of the least are one
    result: the cheapest of them); None when none measured its error."""
    measured = summary.measured(own, None)
    return None if measured.empty else summary.equally_accurate(measured).iloc[0]


def order_alarms(rows: pd.DataFrame, headline: str) -> list[str]:
    """The schemes whose headline error's order fit is flagged not-converging (an alarm): "core rk4", …"""
    alarms = rows[rows["dt"].isna() & (rows["metric"] == summary.ORDER_METRICS[headline])
                  & (rows["flag"] == NOT_CONVERGING)]
    return [f"{r['engine']} {r['integrator']}" for _, r in alarms.iterrows()]


def dynamics_verdict(cases: pd.DataFrame, fits: pd.DataFrame, findings: int, unit: str,
                     alarms: list[str] | None = None) -> str:
    """A dynamics scene in one line: orders that do not converge (an alarm) first, each engine's most accurate
    scheme and its error (the engines that measured none, with why), how the fitted orders compare with theory,
    the findings and the cases without a result."""
    per_engine: list[str] = []
    without: dict[str | None, list[str]] = {}
    for engine in engine_order(cases["engine"]):
        own = cases[cases["engine"] == engine]
        best = most_accurate(own)
        if best is None:
            without.setdefault(unmeasured(own), []).append(engine)
        else:
            per_engine.append(f"{engine} {best['integrator']} {number(best['error'])}")
    parts = [f"ALARM, orders not converging: {', '.join(alarms)}"] if alarms else []
    parts.append(f"most accurate: {', '.join(per_engine)} {unit}" if per_engine else "nothing measured")
    parts += [f"{', '.join(engines)}: {reason}" for reason, engines in without.items()]
    if not fits.empty:
        parts.append("orders " + orders_text(fits))
    statuses = cases["status"].value_counts()
    unresolved = [f"{s} {statuses[s]}" for s in ("failed", "diverged", NOT_AVAILABLE) if s in statuses]
    parts.append(f"{findings} finding{'s' if findings != 1 else ''}" + (f"; cases {', '.join(unresolved)}"
                                                                     if unresolved else ""))
    return "; ".join(parts)
