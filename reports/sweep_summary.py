"""What a report says of a sweep as a whole, computed once from its variants' rows (never by running anything):
each variant's cases, every engine x integrator (x dt) over all the variants (the worst variant decides, as it
would for a user who must pick one scheme for the whole swept range), the variants shown with a section of their
own, and each sweep's variants merged into one line wherever the report lists scenes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from simparity.core.model.run_info import RunInfo
from simparity.core.model.results import OK, SWEEP_COLUMN, SWEEP_PREFIX, case_status
from simparity.reports import summary
from simparity.core.model.metric_catalogue import (
    JOINT_ANGLE_ERROR_MAX, MASS_MATRIX_ERROR_MAX, ORIENTATION_ERROR_MAX, POSITION_ERROR_MAX, SOLVE_RATE, TIME_PER_FK,
    TIME_PER_FORWARD_DYNAMICS, TIME_PER_SOLVE,
)

METRICS = {
    POSITION_ERROR_MAX: ("position error max", "m"),
    ORIENTATION_ERROR_MAX: ("orientation error max", "rad"),
    SOLVE_RATE: ("solve rate", ""),
    MASS_MATRIX_ERROR_MAX: ("mass matrix error max", ""),
    JOINT_ANGLE_ERROR_MAX: ("joint angle error max", "rad"),
}
"""The metric a sweep is judged by, with its name and unit: a dynamics scene's headline error (``run.json``; the
position error where the variants' headlines differ), an IK scene's solve rate, a kinematics scene's frame position
error."""

_KIND_METRIC = {"ik": SOLVE_RATE, "kinematics": POSITION_ERROR_MAX, "joint_dynamics": MASS_MATRIX_ERROR_MAX}
_KIND_COST = {"dynamics": "cost", "ik": TIME_PER_SOLVE, "kinematics": TIME_PER_FK,
              "joint_dynamics": TIME_PER_FORWARD_DYNAMICS}
"""The price of a scheme per kind: compute per simulated second [s/s], time per solve [s], time per FK [s]. Over a
sweep it is the median over the variants: the physics barely changes what a step costs, and one slow timing (a
busy CPU) would decide the largest."""

FIRST, LAST, HARDEST = "first", "last", "hardest"
"""Why a variant gets a section of its own: the two ends of the swept range, and the variant whose errors (IK:
solve rates) rank worst on average over the engine x integrator x dt cases measured in it."""


@dataclass(frozen=True, eq=False)
class Sweep:
    """One swept scene of a run. ``cases``: one row per variant (``scene``) x engine x integrator (x dt), ground
    truths and the reference's own scheme left out, with the case's ``status``, ``value`` (the sweep's metric
    where measured) and ``cost``; ``across``: :func:`across` of them; ``shown``: the variants with a section of
    their own, each with why (:data:`FIRST`, :data:`LAST`, :data:`HARDEST`), in the sweep's order."""

    base: str
    keys: list[str]
    variants: list[str]
    kind: str
    metric: str
    reference: str
    source: str | None
    rows: pd.DataFrame
    cases: pd.DataFrame
    across: pd.DataFrame
    shown: dict[str, tuple[str, ...]]

    @property
    def lower_is_better(self) -> bool:
        return _lower_is_better(self.metric)


def _lower_is_better(metric: str) -> bool:
    """Whether a smaller value of the metric is the better one: errors yes, a solve rate no."""
    return metric != SOLVE_RATE


def metric_label(metric: str) -> str:
    """A metric of :data:`METRICS` as an axis or a table labels it: "position error max [m]", "solve rate"."""
    name, unit = METRICS[metric]
    return f"{name} [{unit}]" if unit else name


def sweeps(table: pd.DataFrame, info: RunInfo) -> list[Sweep]:
    """Every swept scene of the run, in the order its rows first appear; empty for a run without a sweep."""
    if SWEEP_COLUMN not in table.columns:
        return []
    columns = [c for c in table.columns if c.startswith(SWEEP_PREFIX)]
    out = []
    for base, rows in table[table[SWEEP_COLUMN] != ""].groupby(SWEEP_COLUMN, sort=False):
        variants = _ordered_variants(rows, info)
        kind, metric = _metric(variants, info)
        cases = variant_cases(rows, kind, metric)
        lower = _lower_is_better(metric)
        keys = ["engine", "integrator"] + (["dt"] if kind == "dynamics" else [])
        tabulated = kind in ("kinematics", "joint_dynamics")  # their scenes share one section
        shown = _shown(cases, variants, keys, lower) if not tabulated else {}
        out.append(Sweep(base, [c for c in columns if rows[c].notna().any()], variants, kind, metric,
                         rows["reference"].iloc[0], info.scenes.get(variants[0], {}).get("source"),
                         rows, cases, across(cases, keys, lower), shown))
    return out


def _ordered_variants(rows: pd.DataFrame, info: RunInfo) -> list[str]:
    """The variants of one sweep in the sweep's order (``run.json``), whatever order their rows were stored in."""
    scenes = info.scenes
    names = list(dict.fromkeys(rows["scene"]))
    return sorted(names, key=lambda name: scenes.get(name, {}).get("sweep", {}).get("index", math.inf))


def _metric(variants: list[str], info: RunInfo) -> tuple[str, str]:
    """(the kind of the variants, the metric their sweep is judged by)."""
    about = [info.scenes.get(name, {}) for name in variants]
    kind = about[0].get("kind", "dynamics")
    kind = "dynamics" if kind == "joint_motion" else kind  # a chain's motion is summarised as dynamics
    if kind in _KIND_METRIC:
        return kind, _KIND_METRIC[kind]
    headlines = {a.get("headline_metric", POSITION_ERROR_MAX) for a in about}
    return kind, headlines.pop() if len(headlines) == 1 else POSITION_ERROR_MAX


def variant_cases(rows: pd.DataFrame, kind: str, metric: str) -> pd.DataFrame:
    """One row per variant x engine x integrator (x dt for dynamics): scene, engine, integrator, dt, status (the
    case's), value (``metric`` where measured, else NaN), cost (:data:`_KIND_COST`) and evaluations (force evaluations
    per simulated second; NaN but for dynamics). Dynamics leaves out the
    ground truths and the reference's own scheme (:func:`reports.summary.dynamics_cases`); IK and kinematics keep
    every engine, as their scenes' tables do."""
    if kind == "dynamics":
        cases = summary.dynamics_cases(rows, metric)
        return cases.rename(columns={"error": "value"})[["scene", "engine", "integrator", "dt", "status", "value",
                                                          "cost", summary.EVALUATIONS]]
    keys = ["scene", "engine", "integrator"]
    plain = rows[~rows["metric"].str.startswith("hard_")]
    cases = plain.groupby(keys, sort=False)["status"].agg(case_status).rename("status").reset_index()
    measured = plain[(plain["status"] == OK) & plain["metric"].isin([metric, _KIND_COST[kind]])]
    values = measured.pivot_table(index=keys, columns="metric", values="value", sort=False)
    values = values.reindex(columns=[metric, _KIND_COST[kind]]).set_axis(["value", "cost"], axis=1)
    return cases.merge(values.reset_index(), on=keys, how="left").assign(dt=math.nan, **{summary.EVALUATIONS: math.nan})[
        ["scene", "engine", "integrator", "dt", "status", "value", "cost", summary.EVALUATIONS]]


def _status_across(statuses: pd.Series) -> str:
    """ok when the case is ok in every variant, else the gravest status among them (failed, diverged, n/a)."""
    bad = [s for s in statuses if s != OK]
    return OK if not bad else case_status(bad)


def across(cases: pd.DataFrame, keys: list[str], lower_is_better: bool = True) -> pd.DataFrame:
    """One row per ``keys`` (engine, integrator, and dt for dynamics) over every variant: ``status``
    (:func:`_status_across`), ``value`` at the worst variant and that variant (``worst_scene``), ``median`` and
    ``best`` of the value over the variants measured, ``cost`` its median (:data:`_KIND_COST`; ``evaluations`` the
    median force evaluations per simulated second, dynamics only), ``statuses`` (how
    many variants ended ok / diverged / failed / n/a) and ``variants`` (how many were measured)."""
    if summary.EVALUATIONS not in cases:  # cases of a kind, or a caller, that counts no force evaluations
        cases = cases.assign(**{summary.EVALUATIONS: math.nan})
    grouped = cases.groupby(keys, sort=False, dropna=False)
    out = grouped["status"].agg(status=_status_across,
                                statuses=lambda s: ", ".join(f"{k} {n}" for k, n in s.value_counts().items()))
    measured = cases[cases["value"].notna()]
    by = measured.groupby(keys, sort=False, dropna=False)
    worst = by["value"].idxmax() if lower_is_better else by["value"].idxmin()
    out = out.join(pd.DataFrame({"value": measured.loc[worst.values, "value"].values,
                                 "worst_scene": measured.loc[worst.values, "scene"].values}, index=worst.index))
    out = out.join(by["value"].agg(median="median", best="min" if lower_is_better else "max", variants="size"))
    out = out.join(grouped[["cost", summary.EVALUATIONS]].median())
    out["variants"] = out["variants"].fillna(0).astype(int)
    return out.reset_index()


def order_ranges(rows: pd.DataFrame, metric: str) -> dict[tuple[str, str], tuple[float, float]]:
    """(least, largest) observed order of ``metric``'s error over a dynamics sweep's variants, per (engine,
    integrator), where one was fitted."""
    fitted = rows[rows["dt"].isna() & (rows["metric"] == summary.ORDER_METRICS[metric]) & (rows["status"] == OK)]
    ranges = fitted.groupby(["engine", "integrator"], sort=False)["value"].agg(["min", "max"])
    return {key: (float(r["min"]), float(r["max"])) for key, r in ranges.iterrows()}


def _shown(cases: pd.DataFrame, variants: list[str], keys: list[str], lower_is_better: bool) -> dict[str, tuple]:
    """The variants with a section of their own and why: the first, the last and the hardest (:data:`HARDEST`;
    the first in the sweep's order on a tie), in the sweep's order."""
    roles: dict[str, list[str]] = {variants[0]: [FIRST]}
    roles.setdefault(variants[-1], []).append(LAST)
    measured = cases[cases["value"].notna()]
    if not measured.empty:
        rank = measured.groupby(keys, sort=False, dropna=False)["value"].rank(pct=True, ascending=lower_is_better)
        mean = rank.groupby(measured["scene"]).mean().reindex(variants)
        roles.setdefault(variants[int(np.nanargmax(mean.to_numpy()))], []).append(HARDEST)
    return {name: tuple(roles[name]) for name in variants if name in roles}


def groups(all_sweeps: list[Sweep]) -> dict[str, str]:
    """{variant: its sweep's label ("sweep of BASE")} over every sweep of the run."""
    return {name: label(s.base) for s in all_sweeps for name in s.variants}


def counts(all_sweeps: list[Sweep]) -> dict[str, int]:
    """{a sweep's label: how many variants it has} over every sweep of the run."""
    return {label(s.base): len(s.variants) for s in all_sweeps}


def label(base: str) -> str:
    """How the report names a sweep where it lists scenes."""
    return f"sweep of {base}"


def merge_variants(frame: pd.DataFrame, scene_groups: dict[str, str], keys: list[str], **aggregations) -> pd.DataFrame:
    """``frame`` (a ``scene`` column) with each sweep's variants merged: ``scene`` becomes the sweep's
    :func:`label`, and rows agreeing on it and ``keys`` become one, aggregated by ``aggregations`` (pandas named
    aggregations), with ``variants``: how many variants the row stands for (1 for a scene of its own)."""
    labelled = frame.assign(variants=frame["scene"], scene=frame["scene"].map(lambda s: scene_groups.get(s, s)))
    return (labelled.groupby(["scene", *keys], sort=False, dropna=False)
            .agg(variants=("variants", "nunique"), **aggregations).reset_index())


def union(values) -> list[float]:
    """The time steps of merged rows (each a list), sorted and once each: an aggregation for
    :func:`merge_variants`."""
    return sorted({v for vs in values for v in vs})
