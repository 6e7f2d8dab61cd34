"""The report's full tables: a row per key (scene, engine, integrator, dt, a sweep's values), a column per metric,
and the status of the row's cases, as :class:`reports.blocks.Table`. The per-metric columns of each kind of scene
are here, the compact tables with what they show next to them (:mod:`reports.sections`, :mod:`reports.sweep_sections`).
"""

from __future__ import annotations

import math

import pandas as pd

from simparity.core.model.results import OK
from simparity.reports.blocks import Table, number
from simparity.core.model.metric_catalogue import (
    ANGULAR_MOMENTUM_DRIFT_MAX, ANGULAR_VELOCITY_ERROR_MAX, CHAIN_ANGULAR_MOMENTUM_DRIFT_MAX, LINEAR_MOMENTUM_DRIFT_MAX, APEX_HEIGHT_ERROR, CROSS_EVAL_DISAGREEMENT_MAX,
    CROSS_EVAL_SOLVE_RATE_MIN, ENERGY_DRIFT_MAX, ENERGY_GAIN_MAX, IMPACTS_MISSED, IMPACT_TIME_ERROR,
    ITERATIONS_MEDIAN, JACOBIAN_ERROR_MAX, LIMIT_VIOLATIONS, ORDER_ANGULAR_VELOCITY, ORDER_ORIENTATION,
    ORDER_POSITION, ORDER_VELOCITY, ORIENTATION_ERROR_MAX, ORIENTATION_RESIDUAL_MAX, PENETRATION_MAX,
    POSITION_ERROR_MAX, POSITION_RESIDUAL_MAX, POSITION_RESIDUAL_MEDIAN, REBOUND_VELOCITY_ERROR, RESTITUTION_ERROR,
    RESTITUTION_MEASURED, REST_DISTANCE_MEDIAN, REST_TIME_ERROR, SOLVE_RATE, START_RANK_DEFICIENCY,
    STOPPING_DISTANCE, STOPPING_DISTANCE_ERROR, TIME_PER_FK, TIME_PER_JACOBIAN, TIME_PER_SOLVE, TIME_PER_STEP,
    TUNNELLED, VELOCITY_ERROR_MAX, MASS_MATRIX_ERROR_MAX, BIAS_FORCE_ERROR_MAX, INVERSE_DYNAMICS_ERROR_MAX,
    FORWARD_DYNAMICS_ERROR_MAX, GRAVITY_IDENTITY_RESIDUAL, MASS_COLUMN_RESIDUAL, ROUND_TRIP_RESIDUAL,
    MASS_MATRIX_ASYMMETRY, MASS_MATRIX_DEFINITENESS_MIN, KINETIC_ENERGY_RESIDUAL, CORIOLIS_SKEW_RESIDUAL,
    GRAVITY_EQUIVALENCE_RESIDUAL, BASE_MOMENTUM_RESIDUAL,
    TIME_PER_MASS_MATRIX, TIME_PER_INVERSE_DYNAMICS, TIME_PER_FORWARD_DYNAMICS, JOINT_ANGLE_ERROR_MAX,
    JOINT_VELOCITY_ERROR_MAX, END_EFFECTOR_ERROR_MAX, POWER_BALANCE_RESIDUAL_MAX, ORDER_JOINT_ANGLE, ORDER_JOINT_VELOCITY,
    SELF_PARTING_TIME, REFERENCE_PARTING_TIME, SEGMENT_REFERENCE_ERROR_MAX,
)

DYNAMICS_COLUMNS = [
    (POSITION_ERROR_MAX, "position error max [m]"),
    (ORIENTATION_ERROR_MAX, "orientation error max [rad]"),
    (VELOCITY_ERROR_MAX, "velocity error max [m/s]"),
    (ANGULAR_VELOCITY_ERROR_MAX, "angular velocity error max [rad/s]"),
    (ENERGY_DRIFT_MAX, "energy drift max (rel.)"),
    (ANGULAR_MOMENTUM_DRIFT_MAX, "angular momentum drift max (rel.)"),
    (TIME_PER_STEP, "time per step [s]"),
    (IMPACT_TIME_ERROR, "impact time error [s]"),
    (REBOUND_VELOCITY_ERROR, "rebound velocity error [m/s]"),
    (APEX_HEIGHT_ERROR, "apex height error [m]"),
    (IMPACTS_MISSED, "impacts missed"),
    (RESTITUTION_MEASURED, "restitution measured"),
    (RESTITUTION_ERROR, "restitution error"),
    (PENETRATION_MAX, "penetration max [m]"),
    (TUNNELLED, "bodies tunnelled"),
    (ENERGY_GAIN_MAX, "energy gained max (rel.)"),
    (REST_TIME_ERROR, "rest time error [s]"),
    (STOPPING_DISTANCE, "stopping distance [m]"),
    (STOPPING_DISTANCE_ERROR, "stopping distance error [m]"),
]
IK_COLUMNS = [
    (SOLVE_RATE, "solve rate"),
    (POSITION_RESIDUAL_MEDIAN, "position residual median [m]"),
    (POSITION_RESIDUAL_MAX, "position residual max [m]"),
    (ORIENTATION_RESIDUAL_MAX, "orientation residual max [rad]"),
    (ITERATIONS_MEDIAN, "iterations median"),
    (TIME_PER_SOLVE, "time per solve [s]"),
    (LIMIT_VIOLATIONS, "solutions outside limits"),
    (START_RANK_DEFICIENCY, "start pose rank deficiency"),
    (REST_DISTANCE_MEDIAN, "distance to start median"),
    (CROSS_EVAL_SOLVE_RATE_MIN, "solve rate, worst engine's FK"),
    (CROSS_EVAL_DISAGREEMENT_MAX, "FK disagreement max [m]"),
]
ORDER_COLUMNS = [
    (ORDER_POSITION, "order (position)"),
    (ORDER_ORIENTATION, "order (orientation)"),
    (ORDER_VELOCITY, "order (velocity)"),
    (ORDER_ANGULAR_VELOCITY, "order (angular velocity)"),
]
JOINT_MOTION_COLUMNS = [
    (JOINT_ANGLE_ERROR_MAX, "joint angle error max [rad]"),
    (JOINT_VELOCITY_ERROR_MAX, "joint velocity error max (rel.)"),
    (END_EFFECTOR_ERROR_MAX, "end-effector error max (rel. to reach)"),
    (SEGMENT_REFERENCE_ERROR_MAX, "segment ends at dt/16 vs reference"),
    (ENERGY_DRIFT_MAX, "energy drift max (rel.)"),
    (POWER_BALANCE_RESIDUAL_MAX, "power balance residual max (rel.)"),
    (LINEAR_MOMENTUM_DRIFT_MAX, "linear momentum drift max (rel.)"),
    (CHAIN_ANGULAR_MOMENTUM_DRIFT_MAX, "angular momentum drift max (rel.)"),
    (SELF_PARTING_TIME, "parts from itself [s]"),
    (REFERENCE_PARTING_TIME, "parts from the reference [s]"),
    (TIME_PER_STEP, "time per step [s]"),
]
JOINT_ORDER_COLUMNS = [
    (ORDER_JOINT_ANGLE, "order (joint angle)"),
    (ORDER_JOINT_VELOCITY, "order (joint velocity)"),
]
KINEMATICS_COLUMNS = [
    (POSITION_ERROR_MAX, "frame position error max [m]"),
    (ORIENTATION_ERROR_MAX, "frame orientation error max [rad]"),
    (JACOBIAN_ERROR_MAX, "Jacobian error max"),
    (TIME_PER_FK, "time per FK [s]"),
    (TIME_PER_JACOBIAN, "time per Jacobian [s]"),
]
JOINT_DYNAMICS_COLUMNS = [
    (MASS_MATRIX_ERROR_MAX, "M error"),
    (BIAS_FORCE_ERROR_MAX, "h error"),
    (INVERSE_DYNAMICS_ERROR_MAX, "tau error (RNEA)"),
    (FORWARD_DYNAMICS_ERROR_MAX, "qddot error (ABA)"),
    (GRAVITY_IDENTITY_RESIDUAL, "RNEA(q,0,0) = g"),
    (MASS_COLUMN_RESIDUAL, "RNEA(q,0,e_i) - g = M e_i"),
    (ROUND_TRIP_RESIDUAL, "ABA(RNEA) = id"),
    (MASS_MATRIX_ASYMMETRY, "M - M^T"),
    (MASS_MATRIX_DEFINITENESS_MIN, "min eig of D^-1/2 M D^-1/2"),
    (KINETIC_ENERGY_RESIDUAL, "kinetic energy vs links'"),
    (CORIOLIS_SKEW_RESIDUAL, "qdot^T (Mdot - 2C) qdot"),
    (GRAVITY_EQUIVALENCE_RESIDUAL, "h(q,0) = -M[:, :3] g (floating base)"),
    (BASE_MOMENTUM_RESIDUAL, "M[:6] qdot = links' momentum (floating base)"),
    (TIME_PER_MASS_MATRIX, "time per M [s]"),
    (TIME_PER_INVERSE_DYNAMICS, "time per RNEA [s]"),
    (TIME_PER_FORWARD_DYNAMICS, "time per ABA [s]"),
]
"""Every joint-dynamics metric: errors relative to the reference's scale, identities relative to the engine's own."""


def swept_value(value) -> str:
    """A swept value or time step for a heading or a cell: a whole number as one, else 6 significant digits."""
    return str(int(value)) if float(value).is_integer() and abs(value) < 1e15 else f"{float(value):.6g}"


def status(group: pd.DataFrame) -> str:
    """'ok', or each non-ok status with the metrics it is about (none named when it covers them all) and why."""
    bad = group[group["status"] != OK]
    if bad.empty:
        return OK
    parts = [OK] if len(bad) < len(group) else []
    for (name, detail), rows in bad.groupby(["status", "detail"], sort=False):
        label = name if len(rows) == len(group) else f"{name} ({', '.join(rows['metric'])})"
        parts.append(f"{label}: {detail}" if detail else label)
    return " · ".join(parts)


def metric_table(rows: pd.DataFrame, columns, keys: list[str]) -> Table:
    """A row per combination of ``keys`` in the order they come (dt with three significant digits, a sweep's
    values by :func:`swept_value`), a column per metric of ``columns`` ((metric, label) pairs) the rows hold,
    and the :func:`status` of the row."""
    present = set(rows["metric"])
    columns = [(metric, label) for metric, label in columns if metric in present]
    out = []
    for key, group in rows.groupby(keys, sort=False, dropna=False):
        key = key if isinstance(key, tuple) else (key,)
        values = dict(zip(group["metric"], group["value"]))
        cells = [number(float(v)) if name == "dt" else v if isinstance(v, str) else swept_value(v)
                 for name, v in zip(keys, key)]
        cells += [number(values.get(metric, math.nan)) for metric, _ in columns]
        out.append(tuple(cells + [status(group)]))
    return Table(tuple(keys + [label for _, label in columns] + ["status"]), tuple(out))
