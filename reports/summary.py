"""What a report leads with, computed from a stored run's rows and series (never by running anything):
the cheapest scheme per error budget, the most accurate per time budget, each scheme's best time
step, the best IK solvers, the cases without a result grouped by reason, and flagged findings.
"""

from __future__ import annotations

import math

import pandas as pd

from simparity.core.results import GROUND_TRUTH_ENGINES, NOT_AVAILABLE, OK, case_status

ERROR_BUDGETS = (1e-3, 1e-6, 1e-9)
"""Error budgets [the headline metric's unit] the summary finds the cheapest scheme for: a coarse
animation budget, a typical engineering one, and one near double precision's reach."""

TIME_BUDGETS = (1e-3, 1e-2)
"""Compute budgets [s per simulated second] the summary finds the most accurate scheme for: 1000x
and 100x faster than real time."""

SOLVED_ENOUGH = 0.99
"""Solve rate at which an IK solver counts as reliable for "the fastest at >= 99 %"."""

ENERGY_GAIN_FLAGGED = 1e-6
"""A conservative scene's energy rising above E(0) by more than this fraction is flagged: a million
times the unit roundoff, so rounding alone cannot reach it, and a gain (unlike a loss) means a
scheme that can blow up."""

OVERHEAD_DOMINATED_BODIES = 100
"""Below this many bodies, core's time per step is mostly NumPy's per-call overhead, not arithmetic:
``benchmarks/batch_speed.py`` measured core's first-order step at 305, 39 and 3 us per body-step for
1, 10 and 100 bodies (2026-11-23, 2 cores), so the cost per body keeps falling tenfold up to 100."""


def dynamics_cases(rows: pd.DataFrame, headline: str) -> pd.DataFrame:
    """One row per engine x integrator x dt of a dynamics scene, ground truths left out.

    Columns: engine, integrator, dt [s], status (the case's), error (the headline metric where it
    was measured, else NaN), time_per_step [s], cost [s of compute per simulated second], and
    energy_drift (NaN where not measured).
    """
    per_dt = rows[rows["dt"].notna() & ~rows["engine"].isin(GROUND_TRUTH_ENGINES)]
    out = []
    for (engine, integrator, dt), group in per_dt.groupby(["engine", "integrator", "dt"], sort=False):
        ok = group[group["status"] == OK].set_index("metric")["value"]
        step = float(ok.get("time_per_step", math.nan))
        out.append({"engine": engine, "integrator": integrator, "dt": float(dt),
                    "status": case_status(group["status"]), "error": float(ok.get(headline, math.nan)),
                    "time_per_step": step, "cost": step / float(dt),
                    "energy_drift": float(ok.get("energy_drift_max", math.nan))})
    return pd.DataFrame(out, columns=["engine", "integrator", "dt", "status", "error", "time_per_step", "cost",
                                      "energy_drift"])


def _measured(cases: pd.DataFrame) -> pd.DataFrame:
    return cases[(cases["status"] == OK) & cases["error"].notna() & cases["cost"].notna()]


def cheapest_within(cases: pd.DataFrame, budget: float) -> pd.Series | None:
    """The case of least cost whose error is within ``budget``, or None."""
    within = _measured(cases)
    within = within[within["error"] <= budget]
    return None if within.empty else within.loc[within["cost"].idxmin()]


def most_accurate_within(cases: pd.DataFrame, time_budget: float) -> pd.Series | None:
    """The case of least error whose cost is within ``time_budget`` [s per simulated s], or None."""
    within = _measured(cases)
    within = within[within["cost"] <= time_budget]
    return None if within.empty else within.loc[within["error"].idxmin()]


def best_per_scheme(cases: pd.DataFrame) -> pd.DataFrame:
    """Per engine x integrator: the time step of least error (the cheaper on a tie), with its error and
    cost, and how many of its time steps ended ok / diverged / failed / n/a."""
    out = []
    for (engine, integrator), group in cases.groupby(["engine", "integrator"], sort=False):
        measured = _measured(group).sort_values(["error", "cost"])
        counts = group["status"].value_counts()
        best = measured.iloc[0] if not measured.empty else None
        out.append({"engine": engine, "integrator": integrator,
                    "dt": best["dt"] if best is not None else math.nan,
                    "error": best["error"] if best is not None else math.nan,
                    "cost": best["cost"] if best is not None else math.nan,
                    "time_per_step": best["time_per_step"] if best is not None else math.nan,
                    "statuses": ", ".join(f"{s} {counts[s]}" for s in counts.index)})
    return pd.DataFrame(out)


def n_dts(cases: pd.DataFrame) -> int:
    """How many time steps the scene ran."""
    return cases["dt"].nunique()


def orders(rows: pd.DataFrame, headline: str) -> dict[tuple[str, str], float]:
    """Observed order of the headline error per (engine, integrator), where it was fitted."""
    metric = {"position_error_max": "order_position", "orientation_error_max": "order_orientation"}[headline]
    fitted = rows[rows["dt"].isna() & (rows["metric"] == metric) & (rows["status"] == OK)]
    return {(r["engine"], r["integrator"]): float(r["value"]) for _, r in fitted.iterrows()}


def ik_solvers(rows: pd.DataFrame) -> pd.DataFrame:
    """Per engine x solver of an IK scene: solve rate and time per solve (NaN where not measured)."""
    measured = rows[rows["metric"].isin(["solve_rate", "time_per_solve"]) & (rows["status"] == OK)]
    wide = measured.pivot_table(index=["engine", "integrator"], columns="metric", values="value", sort=False)
    return wide.reindex(columns=["solve_rate", "time_per_solve"]).reset_index()


def best_ik(solvers: pd.DataFrame) -> tuple[pd.Series | None, pd.Series | None]:
    """(the solver of best solve rate, the fastest quicker one on a tie; the fastest at >= 99 %)."""
    rated = solvers.dropna(subset=["solve_rate", "time_per_solve"])
    if rated.empty:
        return None, None
    best = rated.sort_values(["solve_rate", "time_per_solve"], ascending=[False, True]).iloc[0]
    reliable = rated[rated["solve_rate"] >= SOLVED_ENOUGH]
    return best, (None if reliable.empty else reliable.loc[reliable["time_per_solve"].idxmin()])


def unresolved_cases(table: pd.DataFrame) -> pd.DataFrame:
    """Every case that is not ok, grouped by (status, reason): columns status, reason, order_fit (the
    cases are observed-order fits over a scene's time steps), n_cases, cases (list of "scene engine
    integrator [dt]" labels, one per engine x integrator with its time steps)."""
    keys = ["scene", "engine", "integrator", "dt"]
    statuses = table.groupby(keys, sort=False, dropna=False)["status"].agg(case_status).rename("case_status")
    cases = table.merge(statuses.reset_index(), on=keys)
    cases = cases[(cases["case_status"] != OK) & (cases["status"] == cases["case_status"])]
    cases = cases.drop_duplicates(keys)
    has_dt = table.groupby("scene")["dt"].agg(lambda d: d.notna().any())
    cases["order_fit"] = cases["dt"].isna() & cases["scene"].map(has_dt)
    out = []
    for (status, reason, order_fit), group in cases.groupby(["case_status", "detail", "order_fit"], sort=False):
        labels = []
        for (scene, engine, integrator), g in group.groupby(["scene", "engine", "integrator"], sort=False):
            dts = ", ".join(f"{dt:g}" for dt in g["dt"] if not math.isnan(dt))
            labels.append(f"{scene} {engine} {integrator}".strip() + (f" (dt {dts})" if dts else ""))
        out.append({"status": status, "reason": reason, "order_fit": order_fit, "n_cases": len(group), "cases": labels})
    frame = pd.DataFrame(out, columns=["status", "reason", "order_fit", "n_cases", "cases"])
    order = {s: i for i, s in enumerate(("failed", "diverged", NOT_AVAILABLE))}
    return frame.sort_values(["status", "n_cases"], key=lambda c: c.map(order) if c.name == "status" else -c,
                             kind="stable")


def energy_gains(series: pd.DataFrame) -> pd.DataFrame:
    """Cases of a conservative scene whose energy rose above E(0) by more than
    :data:`ENERGY_GAIN_FLAGGED` (relative), ground truths left out: per scene x engine x integrator the
    largest gain and the time steps it happened at."""
    energy = series[(series["quantity"] == "energy_change") & ~series["engine"].isin(GROUND_TRUTH_ENGINES)]
    peak = energy.groupby(["scene", "engine", "integrator", "dt"], sort=False)["value"].max().reset_index()
    gained = peak[peak["value"] > ENERGY_GAIN_FLAGGED]
    return (gained.groupby(["scene", "engine", "integrator"], sort=False)
            .agg(gain_max=("value", "max"), dts=("dt", lambda d: sorted(d))).reset_index())


def saturated(table: pd.DataFrame) -> pd.DataFrame:
    """Per scene x metric, how many cases had the metric saturated (n/a: it lost all meaning)."""
    rows = table[(table["status"] == NOT_AVAILABLE) & table["detail"].str.startswith("saturated")]
    return rows.groupby(["scene", "metric"], sort=False).size().rename("n_cases").reset_index()

