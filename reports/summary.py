"""What a report leads with, computed from a stored run's rows and series (never by running anything):
the cheapest scheme per error budget, the most accurate per cost budget (wall time or force evaluations), each scheme's best time
step, the best IK solvers, the cases without a result grouped by reason, and flagged findings.
"""

from __future__ import annotations

import math

import pandas as pd

from simparity.core.model.results import (
    BELOW_THEORY,
    GROUND_TRUTH_ENGINES,
    NOT_AVAILABLE,
    NOT_CONVERGING,
    OK,
    PRE_ASYMPTOTIC,
    SATURATED,
    SUPERCONVERGENT,
    UNSOLVED,
    case_status,
)
from simparity.core.model.engine import TRUTH_SCHEMES
from simparity.core.model.metric_catalogue import (
    APEX_HEIGHT_ERROR, ENERGY_GAIN_MAX, IMPACT_TIME_ERROR, JOINT_ANGLE_ERROR_MAX, ORDER_JOINT_ANGLE, ORDER_ORIENTATION, ORDER_POSITION, ORIENTATION_ERROR_MAX,
    OWN_STOP_POSITION_TOLERANCE, PENETRATION_MAX, POSITION_ERROR_MAX, RESTITUTION_MEASURED, REST_TIME_ERROR, SOLVE_RATE,
    SOLVE_RATE_OWN_STOP, STABLE_DT_MAX, STOPPING_DISTANCE, TIME_PER_SOLVE, TIME_PER_STEP, TUNNELLED,
    EVALUATIONS_PER_SECOND, TIME_PER_STEP_BATCHED,
)

ERROR_BUDGETS = (1e-3, 1e-6, 1e-9)
"""Error budgets [the headline metric's unit] the summary finds the cheapest scheme for: a coarse
animation budget, a typical engineering one, and one near double precision's reach."""

TIME_BUDGETS = (1e-3, 1e-2)
"""Compute budgets [s per simulated second] the summary finds the most accurate scheme for: 1000x
and 100x faster than real time (wall time: ranked where a run has no force evaluation counts)."""

EVALUATION_BUDGETS = (100.0, 1000.0)
"""Work budgets [force evaluations per simulated second] the summary finds the most accurate scheme for: one
evaluation per step at 100 Hz (an animation's frame rate), and at 1 kHz (a robot controller's rate; an RK4 step
at 250 Hz)."""

EVALUATIONS, WALL = "evaluations", "cost"
"""The costs a summary can rank by (columns of :func:`dynamics_cases`): force evaluations per simulated second
(stages / dt, hardware-neutral, as Hairer's work-precision diagrams count it) or wall time per simulated second."""

SOLVED_ENOUGH = 0.99
"""Solve rate at which an IK solver counts as reliable for "the fastest at >= 99 %"."""

ENERGY_GAIN_FLAGGED = 1e-6
"""A conservative scene's energy rising above E(0) by more than this fraction is flagged: a million
times the unit roundoff, so rounding alone cannot reach it, and a gain (unlike a loss) means a
scheme that can blow up."""

OVERHEAD_DOMINATED_BODIES = 100
"""Below this many bodies, core's time per step is mostly NumPy's per-call overhead, not arithmetic:
``simparity bench`` measured core's rk4 step at 173, 2.1 and 0.3 us per body-step for 1, 100 and
10,000 bodies (2026-11-23, 2 cores; BENCHMARKS.md), so the cost per body falls a hundredfold up to 100."""


def dynamics_cases(rows: pd.DataFrame, headline: str) -> pd.DataFrame:
    """One row per scene x engine x integrator x dt of dynamics scenes (one scene, or a sweep's variants), ground
    truths (their engines, and any engine's scheme of a truth's kind: Pinocchio's DOP853 solve of a chain) and the
    scene's reference scheme (core backup where core is the reference) left out: a scheme measured against itself
    ranks nothing.

    Columns: scene, engine, integrator, dt [s], status (the case's), error (the headline metric where it
    was measured, else NaN), time_per_step [s], cost [s of compute per simulated second], evaluations [force
    evaluations per simulated second] and batched_cost [s per simulated second of one copy stepped in a batch:
    ``time_per_step_batched`` / dt; NaN where the engine cannot batch].
    """
    keys = ["scene", "engine", "integrator", "dt"]
    per_dt = rows[rows["dt"].notna() & ~rows["engine"].isin(GROUND_TRUTH_ENGINES)
                  & ~rows["scheme"].isin(TRUTH_SCHEMES)
                  & (rows["engine"] + ":" + rows["integrator"] != rows["reference"])]
    cases = per_dt.groupby(keys, sort=False)["status"].agg(case_status).rename("status").reset_index()
    columns = [headline, TIME_PER_STEP, EVALUATIONS_PER_SECOND, TIME_PER_STEP_BATCHED]
    measured = per_dt[(per_dt["status"] == OK) & per_dt["metric"].isin(columns)]
    values = measured.pivot_table(index=keys, columns="metric", values="value", sort=False)
    cases = cases.merge(values.reindex(columns=columns).reset_index(), on=keys, how="left")
    cases = cases.rename(columns={headline: "error", EVALUATIONS_PER_SECOND: EVALUATIONS})
    cases[WALL] = cases[TIME_PER_STEP] / cases["dt"]
    cases["batched_cost"] = cases[TIME_PER_STEP_BATCHED] / cases["dt"]
    return cases[["scene", "engine", "integrator", "dt", "status", "error", TIME_PER_STEP, WALL, EVALUATIONS,
                  "batched_cost"]]


def ranking_cost(cases: pd.DataFrame) -> str:
    """The cost a summary ranks ``cases`` by: :data:`EVALUATIONS` where any case counted its force evaluations (a
    plugin's scheme that declares no stage count then goes unranked), else :data:`WALL`."""
    return EVALUATIONS if EVALUATIONS in cases and cases[EVALUATIONS].notna().any() else WALL


def measured(cases: pd.DataFrame, by: str | None = WALL) -> pd.DataFrame:
    """The ok cases with an error, and with a ``by`` cost unless ``by`` is None."""
    kept = (cases["status"] == OK) & cases["error"].notna()
    return cases[kept & cases[by].notna()] if by is not None else cases[kept]


SAME_COST_RELATIVE = 1e-9
"""Costs this close (relative) are the same work: stages / dt computed from two time steps that are one number in
the scene file may differ in their last bits."""

AGREE_RELATIVE = 1e-3
"""Errors this close (relative) are one result: the summary names the cheapest of them as the most accurate rather
than the one a last-digit difference favours, and the convergence figure draws schemes agreeing this closely at
every time step as one line ("core rk4 = mujoco rk4"; on a log axis 1e-3 is 4e-4 of a decade, far below a pixel).
Measured in the quick run: MuJoCo's and Pinocchio's rk4 on dzhanibekov agree to 3e-5 (near the rounding floor),
core's explicit and semi-implicit Euler exactly; different schemes differ by percents."""


def equally_cheap(cases: pd.DataFrame, budget: float, by: str = WALL) -> pd.DataFrame:
    """The cases whose error is within ``budget`` at the least ``by`` cost (within :data:`SAME_COST_RELATIVE`), the
    least wall time first (several where schemes do the same work: RK4 at one dt in every engine); empty when none
    is within it."""
    within = measured(cases, by)
    within = within[within["error"] <= budget]
    if within.empty:
        return within
    least = within[within[by] <= within[by].min() * (1 + SAME_COST_RELATIVE)]
    return least.sort_values([WALL, "error"], na_position="last", kind="stable")


def cheapest_within(cases: pd.DataFrame, budget: float, by: str = WALL) -> pd.Series | None:
    """The case of least ``by`` cost (:data:`WALL` or :data:`EVALUATIONS`; ties: the least wall time) whose error
    is within ``budget``, or None."""
    least = equally_cheap(cases, budget, by)
    return None if least.empty else least.iloc[0]


def equally_accurate(cases: pd.DataFrame) -> pd.DataFrame:
    """The measured ``cases`` whose error is the least up to :data:`AGREE_RELATIVE`, the cheapest first (by
    evaluations where counted, then wall time)."""
    least = cases[cases["error"] <= cases["error"].min() * (1 + AGREE_RELATIVE)]
    order = [c for c in (EVALUATIONS, WALL) if c in least]
    return least.sort_values(order, na_position="last", kind="stable")


def most_accurate_within(cases: pd.DataFrame, budget: float, by: str = WALL) -> pd.Series | None:
    """The case of least error (errors within :data:`AGREE_RELATIVE` of it count as equal: the cheapest of them)
    whose ``by`` cost is within ``budget`` [s per simulated s for :data:`WALL`, evaluations per simulated s for
    :data:`EVALUATIONS`], or None."""
    within = measured(cases, by)
    within = within[within[by] <= budget]
    return None if within.empty else equally_accurate(within).iloc[0]


def cost_budgets(by: str) -> tuple[float, ...]:
    """The budgets of the "most accurate within" columns for a ranking by ``by``."""
    return EVALUATION_BUDGETS if by == EVALUATIONS else TIME_BUDGETS


def cost_label(by: str, budget: float) -> str:
    """A cost budget as a column says it: "≤ 100 evaluations/s" or "≤ 0.001 s/s"."""
    return f"≤ {budget:g} evaluations/s" if by == EVALUATIONS else f"≤ {budget:g} s/s"


def best_per_scheme(cases: pd.DataFrame) -> pd.DataFrame:
    """Per engine x integrator: the time step of least error (the cheaper on a tie) with its error, cost,
    evaluations, batched cost and time per step (NaN where none was measured), ``statuses`` (how many of its time steps ended ok /
    diverged / failed / n/a) and ``any_result`` (False when every time step is n/a)."""
    keys = ["engine", "integrator"]
    best = measured(cases).sort_values(["error", "cost"]).drop_duplicates(keys)
    summary = cases.groupby(keys, sort=False)["status"].agg(
        statuses=lambda s: ", ".join(f"{status} {n}" for status, n in s.value_counts().items()),
        any_result=lambda s: bool((s != NOT_AVAILABLE).any())).reset_index()
    return summary.merge(best[keys + ["dt", "error", WALL, EVALUATIONS, "batched_cost", TIME_PER_STEP]], on=keys,
                         how="left")


ORDER_METRICS = {POSITION_ERROR_MAX: ORDER_POSITION, ORIENTATION_ERROR_MAX: ORDER_ORIENTATION,
                 JOINT_ANGLE_ERROR_MAX: ORDER_JOINT_ANGLE}
"""The row holding the observed order of convergence of each headline error."""


def heading_kind(kind: str, headline: str) -> str:
    """What a scene section's heading calls its kind: a chain's motion (ranked by its joint angle error) is
    summarised as dynamics and named as itself."""
    return "joint motion" if headline == JOINT_ANGLE_ERROR_MAX else kind


def orders(rows: pd.DataFrame, headline: str) -> dict[tuple[str, str], float]:
    """Observed order of the headline error per (engine, integrator), where it was fitted."""
    metric = ORDER_METRICS[headline]
    fitted = rows[rows["dt"].isna() & (rows["metric"] == metric) & (rows["status"] == OK)]
    return {(r["engine"], r["integrator"]): float(r["value"]) for _, r in fitted.iterrows()}


IK_RATES = (SOLVE_RATE, SOLVE_RATE_OWN_STOP)
"""The two solve rates of an IK solver: at the scene's tolerances, and at the stopping rule it declares."""


def ik_solvers(rows: pd.DataFrame) -> pd.DataFrame:
    """Per engine x solver of an IK scene: solve rate, time per solve, solve rate at its own stopping rule and
    that rule's position tolerance [m] (NaN where not measured; a rate n/a flagged ``unsolved`` is 0: the solver
    ran and solved none)."""
    columns = [SOLVE_RATE, TIME_PER_SOLVE, SOLVE_RATE_OWN_STOP, OWN_STOP_POSITION_TOLERANCE]
    unsolved = rows["metric"].isin(IK_RATES) & (rows["flag"] == UNSOLVED)
    measured = rows[rows["metric"].isin(columns) & ((rows["status"] == OK) | unsolved)]
    measured = measured.assign(value=measured["value"].where(~unsolved, 0.0))
    wide = measured.pivot_table(index=["engine", "integrator"], columns="metric", values="value", sort=False)
    return wide.reindex(columns=columns).reset_index()


def own_rule_differs(solver: pd.Series, position_tolerance: float | None) -> bool:
    """Whether a solver of :func:`ik_solvers` stops by a rule of its own, not the scene's
    ``position_tolerance`` [m] (unknown: any rule it declares counts as its own)."""
    own = solver.get(OWN_STOP_POSITION_TOLERANCE, math.nan)
    return bool(pd.notna(own) and (position_tolerance is None or not math.isclose(own, position_tolerance)))


def best_ik(solvers: pd.DataFrame) -> tuple[pd.Series | None, pd.Series | None]:
    """(the solver of best solve rate, the quicker one on a tie; the fastest at >= :data:`SOLVED_ENOUGH`), None where
    no solver has both a solve rate and a time per solve."""
    rated = solvers.dropna(subset=[SOLVE_RATE, TIME_PER_SOLVE])
    if rated.empty:
        return None, None
    best = rated.sort_values([SOLVE_RATE, TIME_PER_SOLVE], ascending=[False, True]).iloc[0]
    reliable = rated[rated[SOLVE_RATE] >= SOLVED_ENOUGH]
    return best, (None if reliable.empty else reliable.loc[reliable[TIME_PER_SOLVE].idxmin()])


def unresolved_cases(table: pd.DataFrame) -> pd.DataFrame:
    """Every case that is not ok, one row per status x reason x scene x engine x integrator: columns
    status, order_fit (the cases are observed-order fits over a scene's time steps), scene, engine,
    integrator, reason, n_cases and dts (the cases' time steps, empty where there are none); failed
    first, then diverged, then n/a."""
    keys = ["scene", "engine", "integrator", "dt"]
    statuses = table.groupby(keys, sort=False, dropna=False)["status"].agg(case_status).rename("case_status")
    cases = table.merge(statuses.reset_index(), on=keys)
    cases = cases[(cases["case_status"] != OK) & (cases["status"] == cases["case_status"])].drop_duplicates(keys)
    has_dt = table["dt"].notna().groupby(table["scene"]).any()
    cases = cases.assign(order_fit=cases["dt"].isna() & cases["scene"].map(has_dt).astype(bool))
    grouped = cases.groupby(["case_status", "order_fit", "scene", "engine", "integrator", "detail"], sort=False)
    out = grouped["dt"].agg(n_cases="size", dts=lambda d: [float(v) for v in d if not math.isnan(v)]).reset_index()
    out = out.rename(columns={"case_status": "status", "detail": "reason"})
    rank = {s: i for i, s in enumerate(("failed", "diverged", NOT_AVAILABLE))}
    return out.sort_values("status", key=lambda c: c.map(rank), kind="stable").reset_index(drop=True)


def energy_gains(series: pd.DataFrame) -> pd.DataFrame:
    """Cases of a conservative scene whose energy rose above E(0) by more than
    :data:`ENERGY_GAIN_FLAGGED` (relative), ground truths left out: per scene x engine x integrator the
    largest gain and the time steps it happened at."""
    energy = series[(series["quantity"] == "energy_change") & ~series["engine"].isin(GROUND_TRUTH_ENGINES)]
    peak = energy.groupby(["scene", "engine", "integrator", "dt"], sort=False)["value"].max().reset_index()
    gained = peak[peak["value"] > ENERGY_GAIN_FLAGGED]
    per_scheme = gained.groupby(["scene", "engine", "integrator"], sort=False).agg(
        gain_max=("value", "max"), dts=("dt", lambda d: sorted(d)))
    return per_scheme.reset_index().reindex(columns=["scene", "engine", "integrator", "gain_max", "dts"])


def saturated(table: pd.DataFrame) -> pd.DataFrame:
    """Per scene x metric, how many cases had the metric saturated (n/a, flagged ``saturated``: it lost all
    meaning), order fits left out (:func:`order_findings` has them)."""
    rows = table[(table["flag"] == SATURATED) & table["dt"].notna()]
    return rows.groupby(["scene", "metric"], sort=False).size().rename("n_cases").reset_index()


ORDER_FINDINGS = (NOT_CONVERGING, BELOW_THEORY, SUPERCONVERGENT, PRE_ASYMPTOTIC)
"""Order fits a report lists as findings, by flag, in this order: errors that do not converge (an alarm),
clean fits away from theory either way, fits whose time steps are not in the asymptotic range."""


def order_findings(table: pd.DataFrame) -> pd.DataFrame:
    """Order fits flagged with one of :data:`ORDER_FINDINGS`, ground truths left out: per scene x flag x engine x
    integrator, the metrics (``order_position`` ...) and their values (NaN where n/a), with one detail."""
    rows = table[table["dt"].isna() & table["flag"].isin(ORDER_FINDINGS) & ~table["engine"].isin(GROUND_TRUTH_ENGINES)]
    grouped = rows.groupby(["scene", "flag", "engine", "integrator"], sort=False).agg(
        metrics=("metric", list), values=("value", list), detail=("detail", "first"))
    rank = {flag: i for i, flag in enumerate(ORDER_FINDINGS)}
    out = grouped.reset_index()
    return out.sort_values("flag", key=lambda c: c.map(rank), kind="stable").reset_index(drop=True)



CONTACT_COLUMNS = (RESTITUTION_MEASURED, PENETRATION_MAX, ENERGY_GAIN_MAX, IMPACT_TIME_ERROR,
                   APEX_HEIGHT_ERROR, REST_TIME_ERROR, STOPPING_DISTANCE)
"""The contact metrics a contact scene's compact table shows, per engine x integrator."""


def contact_cases(rows: pd.DataFrame) -> pd.DataFrame:
    """One row per engine x integrator x dt of a contact scene with its contact metrics (ok values, NaN
    otherwise) and the case's status; ground truths left out."""
    keys = ["engine", "integrator", "dt"]
    per_dt = rows[rows["dt"].notna() & ~rows["engine"].isin(GROUND_TRUTH_ENGINES)]
    cases = per_dt.groupby(keys, sort=False)["status"].agg(case_status).rename("status").reset_index()
    measured = per_dt[(per_dt["status"] == OK) & per_dt["metric"].isin(CONTACT_COLUMNS)]
    values = measured.pivot_table(index=keys, columns="metric", values="value", sort=False)
    return cases.merge(values.reindex(columns=list(CONTACT_COLUMNS)).reset_index(), on=keys, how="left")


def stability_limits(rows: pd.DataFrame) -> pd.DataFrame:
    """The measured stable_dt_max rows of a scene: engine, integrator, status, value [s], detail."""
    limits = rows[rows["metric"] == STABLE_DT_MAX]
    return limits[["engine", "integrator", "status", "value", "detail"]]


def contact_flags(table: pd.DataFrame) -> pd.DataFrame:
    """Contact cases that gained energy (energy_gain_max above :data:`ENERGY_GAIN_FLAGGED`) or let a body
    through a plane (tunnelled > 0), ground truths left out: per scene x metric x engine x integrator the
    largest value and the time steps it happened at."""
    ok = table[(table["status"] == OK) & ~table["engine"].isin(GROUND_TRUTH_ENGINES)]
    flagged = ok[((ok["metric"] == ENERGY_GAIN_MAX) & (ok["value"] > ENERGY_GAIN_FLAGGED))
                 | ((ok["metric"] == TUNNELLED) & (ok["value"] > 0))]
    per_scheme = flagged.groupby(["scene", "metric", "engine", "integrator"], sort=False).agg(
        value_max=("value", "max"), dts=("dt", lambda d: sorted(d)))
    return per_scheme.reset_index().reindex(columns=["scene", "metric", "engine", "integrator", "value_max", "dts"])
