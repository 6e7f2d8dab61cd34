"""The report's full tables: a row per key (scene, engine, integrator, dt, a sweep's values), a column per metric,
and the status of the row's cases, as :class:`reports.blocks.Table`. The per-metric columns of each kind of scene
are here, the compact tables with what they show next to them (:mod:`reports.content`, :mod:`reports.sweep_sections`).
"""

from __future__ import annotations

import math

import pandas as pd

from simparity.core.results import OK
from simparity.reports.blocks import Table, number

DYNAMICS_COLUMNS = [
    ("position_error_max", "position error max [m]"),
    ("orientation_error_max", "orientation error max [rad]"),
    ("velocity_error_max", "velocity error max [m/s]"),
    ("angular_velocity_error_max", "angular velocity error max [rad/s]"),
    ("energy_drift_max", "energy drift max (rel.)"),
    ("angular_momentum_drift_max", "angular momentum drift max (rel.)"),
    ("time_per_step", "time per step [s]"),
    ("impact_time_error", "impact time error [s]"),
    ("rebound_velocity_error", "rebound velocity error [m/s]"),
    ("apex_height_error", "apex height error [m]"),
    ("impacts_missed", "impacts missed"),
    ("restitution_measured", "restitution measured"),
    ("restitution_error", "restitution error"),
    ("penetration_max", "penetration max [m]"),
    ("tunnelled", "bodies tunnelled"),
    ("energy_gain_max", "energy gained max (rel.)"),
    ("rest_time_error", "rest time error [s]"),
    ("stopping_distance", "stopping distance [m]"),
    ("stopping_distance_error", "stopping distance error [m]"),
]
IK_COLUMNS = [
    ("solve_rate", "solve rate"),
    ("position_residual_median", "position residual median [m]"),
    ("position_residual_max", "position residual max [m]"),
    ("orientation_residual_max", "orientation residual max [rad]"),
    ("iterations_median", "iterations median"),
    ("time_per_solve", "time per solve [s]"),
    ("limit_violations", "solutions outside limits"),
    ("start_rank_deficiency", "start pose rank deficiency"),
    ("rest_distance_median", "distance to start median"),
    ("cross_eval_solve_rate_min", "solve rate, worst engine's FK"),
    ("cross_eval_disagreement_max", "FK disagreement max [m]"),
]
ORDER_COLUMNS = [
    ("order_position", "order (position)"),
    ("order_orientation", "order (orientation)"),
    ("order_velocity", "order (velocity)"),
    ("order_angular_velocity", "order (angular velocity)"),
]
KINEMATICS_COLUMNS = [
    ("position_error_max", "frame position error max [m]"),
    ("orientation_error_max", "frame orientation error max [rad]"),
    ("jacobian_error_max", "Jacobian error max"),
    ("time_per_fk", "time per FK [s]"),
    ("time_per_jacobian", "time per Jacobian [s]"),
]


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
