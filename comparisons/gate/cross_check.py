"""Cross-checks: a user's scheme held to the built-in schemes of the same kind, measured in the same run.

The CI gate's bounds say what a kind of scheme must achieve on a scene; a cross-check says what a user's
engine achieves beside the built-in engines' schemes of the same kind (the ``scheme`` column), on the same
scene at the same time step, with the same targets: a scheme silently degraded into another of the same
order keeps its order but not its error, and an IK solver that solves a quarter of what the built-in
solver of its kind solves is broken whatever its order. Built-in engines are not cross-checked against
each other: their differences are the report's findings, held by the bounds.

Each check names both sides: the user's engine and the built-in one it is measured against.
"""

from __future__ import annotations

import math

import pandas as pd

from simparity.comparisons.gate.violation import Violation
from simparity.core.model.engine import SCHEME_FAMILIES
from simparity.core.model.results import NOT_AVAILABLE, OK, ROUNDING_FLOOR, SATURATED, UNSOLVED
from simparity.core.model.metric_catalogue import (
    ANGULAR_MOMENTUM_DRIFT_MAX, ANGULAR_VELOCITY_ERROR_MAX, APEX_HEIGHT_ERROR, CROSS_EVAL_SOLVE_RATE_MIN,
    ENERGY_DRIFT_MAX, ENERGY_LOSS_ERROR, EVALUATIONS_PER_SECOND, IMPACT_TIME_ERROR, ORIENTATION_ERROR_MAX, POSITION_ERROR_FINAL,
    POSITION_ERROR_MAX, REBOUND_VELOCITY_ERROR, RESTITUTION_ERROR, REST_DISTANCE_MEDIAN, REST_TIME_ERROR,
    STOPPING_DISTANCE_ERROR, VELOCITY_ERROR_MAX, JOINT_ANGLE_ERROR_MAX, JOINT_VELOCITY_ERROR_MAX, END_EFFECTOR_ERROR_MAX,
    POWER_BALANCE_RESIDUAL_MAX, SEGMENT_REFERENCE_ERROR_MAX,
)

CROSS_CHECK_FACTOR = 2.0
"""An error (or drift) more than twice the largest of the built-in schemes of the same kind at the same step
is a violation. The largest, because faithful implementations of one scheme differ in their error constant
(core's RK4 on the lecture's (x, q, P, L) state carries 5-9 x MuJoCo's at the same step); twice it, because
a scheme degraded into another of the same order (a stage weight off, a force evaluated at the wrong stage)
multiplies its error constant by more (2.7 x core's in the held-out trial), and the same scheme repeated is
equal to rounding."""

FLOOR_FACTOR = 1e3
"""Where the built-in schemes of a kind are at their rounding floor (exact up to rounding), a user's error more than
1000 x their largest is a violation: two implementations of one exact computation round differently by 10-100 x at
most (core, MuJoCo and Pinocchio within 10 x on every built-in scene), while a planted bug leaves errors of 1e-6 and
more against floors of 1e-12 (a review found a gravity off by 0.1 % at 3.7e-2 against 1.1e-12, unchecked)."""

SOLVE_RATE_FRACTION = 0.8
"""An IK solver that, on the same targets with the same tolerances, solves less than 80 % as often as the best
built-in solver of its kind is a violation: the quick profile's 50 targets resolve the rate to 2 %, and the
planted bugs of IK steps, damping and null-space terms cut it by a half or more."""

ERROR_METRICS = (POSITION_ERROR_MAX, POSITION_ERROR_FINAL, ORIENTATION_ERROR_MAX, VELOCITY_ERROR_MAX,
                 ANGULAR_VELOCITY_ERROR_MAX, ENERGY_DRIFT_MAX, ANGULAR_MOMENTUM_DRIFT_MAX,
                 IMPACT_TIME_ERROR, REBOUND_VELOCITY_ERROR, APEX_HEIGHT_ERROR, RESTITUTION_ERROR,
                 ENERGY_LOSS_ERROR, STOPPING_DISTANCE_ERROR, REST_TIME_ERROR, JOINT_ANGLE_ERROR_MAX,
                 JOINT_VELOCITY_ERROR_MAX, END_EFFECTOR_ERROR_MAX, POWER_BALANCE_RESIDUAL_MAX,
                 SEGMENT_REFERENCE_ERROR_MAX)
"""Metrics where less is better, cross-checked against the largest built-in value."""

RATE_METRICS = (CROSS_EVAL_SOLVE_RATE_MIN,)
"""Metrics where more is better (the harness's own solve rate), cross-checked against the best built-in."""


WORK_METRICS = (EVALUATIONS_PER_SECOND,)
"""Metrics a scheme declares rather than measures (force evaluations per simulated second, stages / dt): fewer than
every built-in scheme of its kind at the same step is a violation. An RK4 that declares one stage instead of four
would be ranked the cheapest scheme of every budget in the report; declaring more is no violation (a user's scheme
may do extra work)."""

SAME_WORK_RELATIVE = 1e-9
"""Relative rounding allowed between two declared counts per simulated second: stages / dt of one time step differ
in their last bits at most."""


NULLSPACE = "+nullspace"
"""The scheme modifier of an IK solver with a secondary objective in the Jacobian's null space."""

NULLSPACE_ROUNDING = 1e-9
"""Relative rounding allowed when the null-space solver's rest distance equals the plain one's (a chain with no
redundancy has no null space: the two solutions are the same)."""


def nullspace_checks(table: pd.DataFrame, builtin: tuple[str, ...]) -> list[Violation]:
    """A user's null-space solver (``<kind>+nullspace...``) whose median distance from the rest pose
    (``rest_distance_median``) is larger than that of its engine's solver of the same kind without the term,
    on the same targets: the secondary objective made worse, not better (on a chain without redundancy the
    two are equal)."""
    rows = table[(table["metric"] == REST_DISTANCE_MEDIAN) & (table["status"] == OK)
                 & ~table["engine"].isin(builtin) & table["scheme"].fillna("").str.contains(NULLSPACE, regex=False)]
    out = []
    for row in rows.to_dict("records"):
        base = row["scheme"].replace(NULLSPACE, "")
        plain = table[(table["scene"] == row["scene"]) & (table["engine"] == row["engine"])
                      & (table["metric"] == REST_DISTANCE_MEDIAN) & (table["status"] == OK)
                      & (table["scheme"] == base)]
        if plain.empty:
            continue
        without = float(plain["value"].min())
        if float(row["value"]) > without * (1 + NULLSPACE_ROUNDING):
            out.append(Violation(
                row["scene"], row["engine"], row["integrator"], float(row["dt"]), row["metric"],
                f"{float(row['value']):.4g} {row['unit']}", f"<= {without:.4g} {row['unit']}",
                f"cross-check: the null-space term must keep the solutions nearer the rest pose than "
                f"{row['engine']} {plain.iloc[0]['integrator']} without it"))
    return out


AGREEMENT_METRICS = (JOINT_ANGLE_ERROR_MAX, JOINT_VELOCITY_ERROR_MAX, END_EFFECTOR_ERROR_MAX,
                     POWER_BALANCE_RESIDUAL_MAX)
"""A chain's errors of motion (and its ``energy_drift_max``, a metric free bodies share: on a scene with joint
errors), on which the built-in engines of one kind of scheme are held to each other: each kind
is one discretisation of one ODE (the joint equations of motion in (q, qdot)), which core, MuJoCo, Pinocchio and
PyBullet compute with no shared code, so at the same step their errors are the same up to rounding. On a chain no
bound names (a user's own robot) this is what holds a scheme whose order cannot be measured (its coarse steps on
another orbit): a built-in whose error no other built-in of its kind shares within :data:`JOINT_AGREEMENT_FACTOR` is
a violation (two that disagree are both named); a user's engine is held to them as closely."""

JOINT_AGREEMENT_FACTOR = 1.25
"""How far apart two errors of one kind of scheme on one chain at one step may be. Measured (quick profile, every
engine pair): within 0.1 % on the default suite's chains (the worst at an error of 6e-13, near rounding), within
3e-6 relative on held-out robots (SO-100, Kinova Gen2) from PyBullet's float32 link states; in a chaotic chain the
engines' rounding grows like the reference's own error, and an error is measured only where it is more than 10 x
that (else it is at the reference's floor), so rounding stays ~1e-4 of it. 25 % is 250 x the worst spread measured,
while a scheme degraded into another (semi-implicit Euler moving the joints with the old velocity: 2 x on a falling
arm; a stage weight off) moves the error by a factor of 1.5 and more: the free bodies' :data:`CROSS_CHECK_FACTOR` of
2, set for representations that differ ((x, q, P, L) against MuJoCo's qpos), let such bugs through at 1.0-1.3 x."""

TRUTH_KINDS = ("adaptive", "closed_form")
"""Kinds of the references themselves: held by their own bounds, never to another engine's error."""


def agreement_checks(table: pd.DataFrame, builtin: tuple[str, ...]) -> list[Violation]:
    """Every measured row of a built-in engine's chain in motion (:data:`AGREEMENT_METRICS`) whose value is not within
    :data:`JOINT_AGREEMENT_FACTOR` of the same metric of some other built-in engine of its kind, on the same scene and
    step (rows at their rounding floor are exact up to rounding: left out)."""
    out = []
    for row, others in _agreement_groups(table, builtin):
        value = float(row["value"])
        if any(value <= JOINT_AGREEMENT_FACTOR * o and o <= JOINT_AGREEMENT_FACTOR * value for o in others["value"]):
            continue
        listed = ", ".join(f"{o['engine']} {o['integrator']} {float(o['value']):.4g}" for o in others.to_dict("records"))
        out.append(Violation(row["scene"], row["engine"], row["integrator"], float(row["dt"]), row["metric"],
                             f"{value:.4g} {row['unit']}", f"within {JOINT_AGREEMENT_FACTOR:g} x another built-in "
                             f"{row['scheme']}",
                             f"agreement: the built-in {row['scheme']} schemes compute one discretisation at this step, "
                             f"but none agrees with this one ({listed})"))
    return out


def _agreement_groups(table: pd.DataFrame, builtin: tuple[str, ...]):
    """(row, the other built-in engines' rows of its kind, scene, step and metric) for every measured built-in row
    in :data:`AGREEMENT_METRICS` that has such others."""
    if "scheme" not in table.columns:
        return
    rows = table[table["engine"].isin(builtin) & _in_motion(table) & (table["status"] == OK)
                 & (_flags(table) != ROUNDING_FLOOR) & (table["scheme"].fillna("") != "") & ~table["scheme"].isin(TRUTH_KINDS)]
    rows = rows.assign(dt_key=rows["dt"].map(_dt_key))
    for _, group in rows.groupby(["scene", "scheme", "dt_key", "metric"]):
        if group["engine"].nunique() < 2:
            continue
        for row in group.to_dict("records"):
            yield row, group[group["engine"] != row["engine"]]


def _in_motion(table: pd.DataFrame) -> pd.Series:
    """(rows,) bool: the rows of a chain in motion held as closely as :data:`JOINT_AGREEMENT_FACTOR` says (its
    :data:`AGREEMENT_METRICS`, and its energy drift: a scene with joint errors is a chain's)."""
    chains = table.loc[table["metric"] == JOINT_ANGLE_ERROR_MAX, "scene"].unique()
    return table["metric"].isin(AGREEMENT_METRICS) | ((table["metric"] == ENERGY_DRIFT_MAX)
                                                      & table["scene"].isin(chains))


def held_series(table: pd.DataFrame, builtin: tuple[str, ...]) -> set[tuple[str, str, str]]:
    """The series (scene, engine, integrator) a cross-check or the built-ins' agreement holds to a value: a user's
    engine with a row compared with a built-in scheme of its kind that measured one, a built-in with a row compared
    with another built-in of its kind (:func:`agreement_checks`)."""
    held = {(row["scene"], row["engine"], row["integrator"]) for row, _ in _agreement_groups(table, builtin)}
    if "scheme" not in table.columns:
        return held
    watched = table[table["metric"].isin(ERROR_METRICS + RATE_METRICS) & (table["scheme"].fillna("") != "")]
    measured = watched[watched["engine"].isin(builtin) & (watched["status"] == OK)]
    kinds = set(zip(measured["scene"], measured["scheme"], measured["dt"].map(_dt_key), measured["metric"]))
    users = watched[~watched["engine"].isin(builtin) & (watched["status"] == OK) & (_flags(watched) != ROUNDING_FLOOR)]
    for row in users.to_dict("records"):
        scheme = row["scheme"] if (row["scene"], row["scheme"], _dt_key(row["dt"]), row["metric"]) in kinds else (
            SCHEME_FAMILIES.get(row["scheme"], ""))
        if (row["scene"], scheme, _dt_key(row["dt"]), row["metric"]) in kinds:
            held.add((row["scene"], row["engine"], row["integrator"]))
    return held


def _flags(table: pd.DataFrame) -> pd.Series:
    """(rows,) str: each row's flag ("" for none, and for a table without flags)."""
    return table["flag"].fillna("") if "flag" in table.columns else pd.Series("", index=table.index)


def _dt_key(dt) -> str:
    """A time step as a grouping key (NaN, an IK or kinematics row's, as "nan": NaN equals nothing)."""
    return "nan" if pd.isna(dt) else repr(float(dt))


def _builtin_rows(table: pd.DataFrame, builtin: tuple[str, ...]) -> pd.DataFrame:
    return table[table["engine"].isin(builtin) & (table["scheme"] != "")]


def cross_check(table: pd.DataFrame, builtin: tuple[str, ...]) -> list[Violation]:
    """Every row of an engine not in ``builtin`` with a declared scheme that the built-in rows of the same scene,
    scheme, time step and metric show to be beyond :data:`CROSS_CHECK_FACTOR` (errors), below
    :data:`SOLVE_RATE_FRACTION` (solve rates) or below the least (declared work, :data:`WORK_METRICS`), or saturated (unsolved) where the built-ins of its kind measured a
    number; every null-space solver of such an engine that does worse than its solver without the term
    (:func:`nullspace_checks`); and every built-in's chain in motion that no other built-in of its kind agrees with
    (:func:`agreement_checks`)."""
    if "scheme" not in table.columns:
        return []
    keys = ["scene", "scheme", "dt_key", "metric"]
    table = table.assign(dt_key=table["dt"].map(_dt_key), in_motion=_in_motion(table), flag=_flags(table))
    out = nullspace_checks(table, builtin) + agreement_checks(table, builtin)
    watched = table[table["metric"].isin(ERROR_METRICS + RATE_METRICS + WORK_METRICS)]
    users = watched[~watched["engine"].isin(builtin) & (watched["scheme"].fillna("") != "")]
    if users.empty:  # no user's engine: no frame per group of the built-ins' rows (a sweep's thousands: 200 MB)
        return out
    reference = {key: rows for key, rows in _builtin_rows(watched, builtin).groupby(keys)}
    for row in users.to_dict("records"):
        rows, factor = reference.get(tuple(row[k] for k in keys)), None
        if (rows is None or not (rows["status"] == OK).any()) and row["scheme"] in SCHEME_FAMILIES:
            family = reference.get((row["scene"], SCHEME_FAMILIES[row["scheme"]], row["dt_key"], row["metric"]))
            if family is not None:  # no built-in of its kind measured it (none ran, or n/a): its family's did
                rows, factor = family, CROSS_CHECK_FACTOR
        if rows is None:
            continue
        found = _judge(row, rows, factor)
        if found:
            out.append(Violation(row["scene"], row["engine"], row["integrator"], float(row["dt"]), row["metric"],
                                      *found))
    return out


def _judge(row: dict, builtin: pd.DataFrame, factor: float | None = None) -> tuple[str, str, str] | None:
    """(what was found, the bound, why) when ``row`` breaks the cross-check against ``builtin`` (the built-in rows
    of its scene, scheme, step and metric, or of its scheme's family: :data:`SCHEME_FAMILIES`, held within
    ``factor``), else None."""
    measured = builtin[(builtin["status"] == OK)]
    kind = str(builtin["scheme"].iloc[0])
    if measured.empty or row["flag"] == ROUNDING_FLOOR:
        return None  # nothing to compare with, or exact up to rounding: rounding has no size to hold
    if (measured["flag"] == ROUNDING_FLOOR).any():  # the built-ins are exact up to rounding: hold the user's to more
        largest = float(measured["value"].max())
        if row["status"] == OK and row["metric"] in ERROR_METRICS and float(row["value"]) > FLOOR_FACTOR * largest:
            return (f"{float(row['value']):.4g} {row['unit']}", f"<= {FLOOR_FACTOR:g} x {largest:.4g} {row['unit']}",
                    f"cross-check: the built-in {kind} is exact up to rounding here ({largest:.4g}); "
                    f"{FLOOR_FACTOR:g} x that is no rounding of the same arithmetic")
        return None
    if row["metric"] in WORK_METRICS:
        least = measured.loc[measured["value"].idxmin()]
        if row["status"] == OK and float(row["value"]) < float(least["value"]) * (1 - SAME_WORK_RELATIVE):
            return (f"{float(row['value']):.4g} {row['unit']}", f">= {float(least['value']):.4g} {row['unit']}",
                    f"cross-check: a {kind} step evaluates the forces at least as often as the built-in {kind}, "
                    f"{least['engine']} {least['integrator']} ({float(least['value']):.4g} {row['unit']}); the "
                    "engine's stages() declares fewer")
        return None
    if row["metric"] in RATE_METRICS:
        best = measured.loc[measured["value"].idxmax()]
        limit = SOLVE_RATE_FRACTION * float(best["value"])
        why = (f"cross-check: {SOLVE_RATE_FRACTION:.0%} of the best built-in {kind} solver, {best['engine']} "
               f"{best['integrator']} ({float(best['value']):.4g}), on the same targets")
        if row["status"] == OK and float(row["value"]) < limit:
            return f"{float(row['value']):.4g}", f">= {limit:.3g}", why
        if row["status"] == NOT_AVAILABLE and row["flag"] == UNSOLVED:
            return "0 (unsolved)", f">= {limit:.3g}", why
        return None
    largest = measured.loc[measured["value"].idxmax()]
    if factor is None:
        factor = JOINT_AGREEMENT_FACTOR if row["in_motion"] else CROSS_CHECK_FACTOR
    limit = factor * float(largest["value"])
    side = f"{largest['engine']} {largest['integrator']} ({float(largest['value']):.4g} {row['unit']})"
    if row["status"] == OK and float(row["value"]) > limit and math.isfinite(limit):
        return (f"{float(row['value']):.4g} {row['unit']}", f"<= {limit:.3g} {row['unit']}",
                f"cross-check: {factor:g} x the largest built-in {kind} at this step, {side}")
    if row["status"] == NOT_AVAILABLE and row["flag"] == SATURATED and (builtin["status"] == OK).all():
        return ("saturated", f"a number like the built-in {kind}",
                f"cross-check: saturated where every built-in {kind} at this step measured one, e.g. {side}")
    return None
