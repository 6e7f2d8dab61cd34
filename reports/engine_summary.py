"""Which integrator, engine by engine (issue #26): for each engine (the user's own first: core, then plugins), its
own cheapest scheme at each error budget and its most accurate within each cost budget, per scene and counted over
the run's dynamics scenes; and each scene's verdict in one line. Computed from a stored run's cases (:func:`reports.
summary.dynamics_cases`), never by running anything.
"""

from __future__ import annotations

from collections import Counter
from typing import TypeAlias

import pandas as pd

from simparity.core.model.results import BELOW_THEORY, GROUND_TRUTH_ENGINES, NOT_AVAILABLE, OK, SUPERCONVERGENT
from simparity.reports import summary
from simparity.reports.blocks import number

THIRD_PARTY_ENGINES = ("mujoco", "pybullet", "pinocchio")
"""The engines simparity compares against. Every other engine of a run that is not a ground truth is the user's own
(core, a plugin) and is listed first: their schemes are the ones a user picks between."""

SCHEMES_NAMED = 3
"""Schemes a cell of the per-engine table names before it counts the rest: a row stays one line."""


def engine_order(engines) -> list[str]:
    """``engines`` (ground truths left out) with core first, then plugins in run order, then the third-party
    engines in :data:`THIRD_PARTY_ENGINES` order."""
    present = [e for e in dict.fromkeys(engines) if e not in GROUND_TRUTH_ENGINES]
    own = [e for e in present if e == "core"] + [e for e in present if e != "core" and e not in THIRD_PARTY_ENGINES]
    return own + [e for e in THIRD_PARTY_ENGINES if e in present]


NO_STAGE_COUNT = "n/a (no stage count)"
"""A work-budget cell of an engine that declares no stage count: its schemes are ranked among themselves by wall
time, which no work budget bounds."""

Choice: TypeAlias = "pd.Series | str | None"
"""An engine's case for a budget, :data:`NO_STAGE_COUNT`, or None where none of its cases qualifies."""


def own_cost(own: pd.DataFrame, by: str) -> str:
    """The cost one engine's cases ``own`` are ranked by among themselves: the run's ``by``, or wall time where the
    engine's measured cases counted no force evaluations (a plugin that declares no stages; an engine with no
    measured case keeps ``by``: it has nothing to rank); within one engine that is fair, its overhead is shared."""
    measured = own[(own["status"] == OK) & own["error"].notna()] if by in own else own.iloc[0:0]
    return summary.WALL if by not in own or (not measured.empty and measured[by].isna().all()) else by


def choices(cases: pd.DataFrame, by: str) -> dict[str, dict[str, Choice]]:
    """{engine: {column: its choice}} for one scene's cases: per engine the cheapest (by :func:`own_cost`) within
    each of :data:`reports.summary.ERROR_BUDGETS` (column ``error ≤ B``) and the most accurate within each cost
    budget of ``by`` (column :func:`reports.summary.cost_label`; :data:`NO_STAGE_COUNT` for an engine ranked by wall
    time in a run ranked by evaluations); None where none of its cases qualifies."""
    out: dict[str, dict[str, Choice]] = {}
    for engine in engine_order(cases["engine"]):
        own = cases[cases["engine"] == engine]
        ranked_by = own_cost(own, by)
        picks: dict[str, Choice] = {f"error ≤ {b:g}": summary.cheapest_within(own, b, ranked_by)
                                    for b in summary.ERROR_BUDGETS}
        picks |= {summary.cost_label(by, b): (summary.most_accurate_within(own, b, by) if ranked_by == by
                                              else NO_STAGE_COUNT) for b in summary.cost_budgets(by)}
        out[engine] = picks
    return out


def tally(per_scene: list[dict[str, dict[str, Choice]]]) -> dict[str, dict[str, str]]:
    """{engine: {column: "rk4 ×9, midpoint ×2, none ×1"}}: how often each of an engine's schemes was its choice
    over the scenes (:func:`choices` of each), the most frequent first, at most :data:`SCHEMES_NAMED` named."""
    counts: dict[str, dict[str, Counter]] = {}
    for scene in per_scene:
        for engine, picks in scene.items():
            for column, case in picks.items():
                name = "none" if case is None else case if isinstance(case, str) else case["integrator"]
                counts.setdefault(engine, {}).setdefault(column, Counter())[name] += 1
    out: dict[str, dict[str, str]] = {}
    for engine in engine_order(counts):
        out[engine] = {}
        for column, counter in counts[engine].items():
            ranked = counter.most_common()
            named = [name if name == NO_STAGE_COUNT else f"{name} ×{n}" for name, n in ranked[:SCHEMES_NAMED]]
            rest = sum(n for _, n in ranked[SCHEMES_NAMED:])
            out[engine][column] = ", ".join(named) + (f", others ×{rest}" if rest else "")
    return out


def pick(case: Choice, by: str, show_error: bool) -> str:
    """One engine's choice in a cell: ``rk4 @ 0.01 (400/s)`` (its cost by ``by``) or ``rk4 @ 0.04: 3.1e-07`` (its
    error); "none", or the reason it has none."""
    if case is None or isinstance(case, str):
        return case or "none"
    head = f"{case['integrator']} @ {case['dt']:g}"
    return f"{head}: {number(case['error'])}" if show_error else f"{head} ({cost_text(case, by)})"


def cost_text(case: pd.Series, by: str) -> str:
    """A case's cost as the ranking counts it: ``400/s`` (evaluations) or ``0.0021 s/s`` (wall time)."""
    return f"{number(case[by])}/s" if by == summary.EVALUATIONS else f"{number(case[by])} s/s"


def overall(cases: pd.DataFrame, budget: float, by: str) -> str:
    """The cheapest case of every engine within an error ``budget``, by ``by``: ``mujoco rk4 @ 0.01 (400/s; +2 as
    cheap)``, naming how many others do the same work within it; "none"."""
    least = summary.equally_cheap(cases, budget, by)
    if least.empty:
        return "none"
    best = least.iloc[0]
    tied = f"; +{len(least) - 1} as cheap" if len(least) > 1 else ""
    return f"{best['engine']} {best['integrator']} @ {best['dt']:g} ({cost_text(best, by)}{tied})"


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


def dynamics_verdict(cases: pd.DataFrame, fits: pd.DataFrame, findings: int, unit: str) -> str:
    """A dynamics scene in one line: each engine's most accurate scheme and its error, how the fitted orders
    compare with theory, the findings and the cases without a result."""
    best = cases[(cases["status"] == OK) & cases["error"].notna()].sort_values(["error", summary.WALL])
    per_engine = [f"{e} {b.iloc[0]['integrator']} {number(b.iloc[0]['error'])}"
                  for e in engine_order(best["engine"]) if not (b := best[best["engine"] == e]).empty]
    parts = [f"most accurate: {', '.join(per_engine)} {unit}" if per_engine else "nothing measured"]
    if not fits.empty:
        parts.append("orders " + orders_text(fits))
    statuses = cases["status"].value_counts()
    unresolved = [f"{s} {statuses[s]}" for s in ("failed", "diverged", NOT_AVAILABLE) if s in statuses]
    parts.append(f"{findings} finding{'s' if findings != 1 else ''}" + (f"; cases {', '.join(unresolved)}"
                                                                     if unresolved else ""))
    return "; ".join(parts)
