"""``report.md``: per scene, error against the reference and time per step for every engine."""

from __future__ import annotations

import math

import pandas as pd

from simparity.core.results import HARD_VERDICT_SUFFIXES, NOT_AVAILABLE, OK, STATUSES, case_counts, case_status

_DYNAMICS_COLUMNS = [
    ("position_error_max", "position error max [m]"),
    ("orientation_error_max", "orientation error max [rad]"),
    ("velocity_error_max", "velocity error max [m/s]"),
    ("angular_velocity_error_max", "angular velocity error max [rad/s]"),
    ("energy_drift_max", "energy drift max (rel.)"),
    ("angular_momentum_drift_max", "angular momentum drift max (rel.)"),
    ("time_per_step", "time per step [s]"),
]
_IK_COLUMNS = [
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
_IK_PROTOCOL = (
    "Protocol (TRAC-IK): seeded random reachable targets (end-effector poses of seeded random configurations "
    "within the limits), every solve from the scene's one start pose, success when the residuals are within "
    "the scene's tolerances and the joint values within their limits (an engine's solver that leaves them "
    "fails with `outside_limits`), time per solve = batch time / batch size with failed solves included. Each "
    "solution is also put through every engine's forward kinematics (worst solve rate and largest "
    "disagreement shown), so no solver passes on its own kinematics alone."
)
_ORDER_COLUMNS = [
    ("order_position", "order (position)"),
    ("order_orientation", "order (orientation)"),
    ("order_velocity", "order (velocity)"),
    ("order_angular_velocity", "order (angular velocity)"),
]
_TIMING_METRICS = ("time_per_step", "time_per_fk", "time_per_solve")
_DEFINITIONS = (
    "Statuses: `ok` measured; `n/a` not measured, with the reason: the engine cannot do what the scene asks, "
    "or the metric means nothing here (an orientation error saturated at >= pi/2, a drift above 100 %, errors at "
    "the rounding floor, too few time steps for an order, a point-mass rule that does not move orientation, "
    "nothing to compare against); `diverged` non-finite, or faster than the scene's forces allow, or a conserved "
    "quantity more than doubled; `failed` the engine raised. A status cell names the metrics it is about. "
    "Energy drift is max |E(t) - E(0)| / |E(0)| (potential zero at the world origin; relative to the largest "
    "kinetic energy when |E(0)| is near zero, and the row says so); angular momentum drift is "
    "max |L(t) - L(0)| / |L(0)|. Definitions: docs/metrics.md."
)
_KINEMATICS_COLUMNS = [
    ("position_error_max", "frame position error max [m]"),
    ("orientation_error_max", "frame orientation error max [rad]"),
    ("jacobian_error_max", "Jacobian error max"),
    ("time_per_fk", "time per FK [s]"),
    ("time_per_jacobian", "time per Jacobian [s]"),
]


def _number(value: float) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "—"
    return "0" if value == 0 else f"{value:.3g}"


def _status(group: pd.DataFrame) -> str:
    """'ok', or each non-ok status with the metrics it is about (none named when it covers them all) and why."""
    bad = group[group["status"] != OK]
    if bad.empty:
        return OK
    parts = [OK] if len(bad) < len(group) else []
    for (status, detail), rows in bad.groupby(["status", "detail"], sort=False):
        label = status if len(rows) == len(group) else f"{status} ({', '.join(rows['metric'])})"
        parts.append(f"{label}: {detail}" if detail else label)
    return " · ".join(parts)


def _table(scene_rows: pd.DataFrame, columns, keys: list[str]) -> list[str]:
    present = set(scene_rows["metric"])
    columns = [(metric, label) for metric, label in columns if metric in present]
    head = keys + [label for _, label in columns] + ["status"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for key, group in scene_rows.groupby(keys, sort=False, dropna=False):
        key = key if isinstance(key, tuple) else (key,)
        values = dict(zip(group["metric"], group["value"]))
        cells = [_key_cell(name, v) for name, v in zip(keys, key)]
        cells += [_number(values.get(metric, math.nan)) for metric, _ in columns]
        lines.append("| " + " | ".join(cells + [_status(group).replace("|", "/")]) + " |")
    return lines


def _key_cell(name: str, value) -> str:
    if name == "dt":
        return _number(float(value))
    return str(value)


def _notes(scene_rows: pd.DataFrame) -> list[str]:
    timed = scene_rows["metric"].isin(_TIMING_METRICS)
    ok = scene_rows[timed & (scene_rows["status"] == OK)].drop_duplicates(["engine", "integrator"])
    lines = ["", "What each engine was given:", ""]
    for _, row in ok.iterrows():
        label = f"{row['engine']} {row['integrator']}".strip()
        lines.append(f"- **{label}**: {row['detail']}")
    return lines if len(lines) > 3 else []


def _fits(orders: pd.DataFrame) -> list[str]:
    """Each fitted order's range, local slopes and residual, folded away."""
    fitted = orders[orders["status"] == OK]
    if fitted.empty:
        return []
    lines = ["", "<details><summary>Fits (range, local slopes, residual)</summary>", ""]
    lines += [f"- {r['engine']} {r['integrator']} `{r['metric']}` = {_number(r['value'])}: {r['detail']}"
              for _, r in fitted.iterrows()]
    return lines + ["", "</details>"]


def _hard_cell(row) -> str:
    if row["status"] != OK:
        return row["status"]
    verdict = row["detail"].split(";")[0]
    return f"{'✓' if verdict == 'solved' else '✗ ' + verdict.removeprefix('failed: ')} {_number(row['value'])} m"


def _hard_table(rows: pd.DataFrame) -> list[str]:
    """Engine x solver against each hard target: solved or the reason, with the position residual."""
    hard = rows[rows["metric"].str.startswith("hard_") & ~rows["metric"].str.endswith(HARD_VERDICT_SUFFIXES)]
    if hard.empty:
        return []
    names = list(dict.fromkeys(hard["metric"]))
    head = ["engine", "solver"] + [n.removeprefix("hard_") for n in names]
    lines = ["", "Hard targets (✓ solved, ✗ the reason; position residual):", "",
             "| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for (engine, solver), group in hard.groupby(["engine", "integrator"], sort=False):
        cells = {r["metric"]: _hard_cell(r) for _, r in group.iterrows()}
        lines.append("| " + " | ".join([engine, solver] + [cells.get(n, "—") for n in names]) + " |")
    notes = hard[hard["status"] == OK].drop_duplicates("metric")
    lines += [""] + [f"- `{r['metric'].removeprefix('hard_')}`: {r['detail'].split('; ')[-1]}"
                     for _, r in notes.iterrows()]
    return lines


def _dynamics_verdicts(rows: pd.DataFrame) -> list[str]:
    """Engine x integrator against each time step: the status each case earned."""
    per_dt = rows[rows["dt"].notna()]
    dts = sorted(per_dt["dt"].unique())
    lines = ["| engine | integrator | " + " | ".join(f"dt {dt:g} s" for dt in dts) + " |",
             "|---|---|" + "---|" * len(dts)]
    for (engine, integrator), group in per_dt.groupby(["engine", "integrator"], sort=False):
        status = {dt: case_status(g["status"]) for dt, g in group.groupby("dt")}
        lines.append(f"| {engine} | {integrator} | " + " | ".join(status.get(dt, "—") for dt in dts) + " |")
    return lines


def _hard_cases(table: pd.DataFrame, info: dict) -> list[str]:
    """The verdict every engine earned on each scene of the hard suite in the run."""
    scenes = [name for name, about in info.get("scenes", {}).items() if "hard" in about.get("suites", ())]
    scenes = [name for name in scenes if (table["scene"] == name).any()]
    if not scenes:
        return []
    lines = ["", "## Hard cases", "",
             "The numerical-stability cases of the `hard` suite and the verdict each engine earned: a case is "
             "`diverged` when a conserved quantity or a speed left its bound, `ok` when it stayed bounded (its "
             "errors are in the scene's section). The verdict each must earn is in the shipped tolerances "
             "(`simparity check`)."]
    for name in scenes:
        rows = table[table["scene"] == name]
        lines += ["", f"### {name}", ""]
        description = info["scenes"][name].get("description")
        lines += [description, ""] if description else []
        lines += _hard_table(rows)[1:] if _kind(rows) == "ik" else _dynamics_verdicts(rows)
    return lines


def _kind(rows: pd.DataFrame) -> str:
    if (rows["metric"] == "solve_rate").any():
        return "ik"
    return "dynamics" if rows["dt"].notna().any() else "kinematics"


def render(table: pd.DataFrame, info: dict) -> str:
    """Markdown text of a stored run."""
    versions = ", ".join(f"{k} {v}" for k, v in info.get("engine_versions", {}).items())
    m = info.get("machine", {})
    counts = case_counts(table.to_dict("records"))
    lines = [
        "# simparity report",
        "",
        f"Run {info.get('created_utc', '?')} · commit {info.get('git_commit', '?')} · "
        f"{m.get('platform', '?')} · {m.get('cpu_count', '?')} CPUs · Python {m.get('python', '?')}",
        "",
        f"Engines: {versions}",
        "",
        "Cases (failed or diverged if any row is, ok if anything was measured): " + ", ".join(f"{s} {counts[s]}" for s in STATUSES)
        + f". `{NOT_AVAILABLE}`: nothing was measured, and the rows say why (statuses below).",
        "Errors are maxima over every body and sample against the reference named per scene; "
        "times are the best of several repeats of the stepping alone (model building excluded).",
        "",
        _DEFINITIONS,
    ]
    lines += _hard_cases(table, info)
    for scene, rows in table.groupby("scene", sort=False):
        kind = _kind(rows)
        reference = rows["reference"].iloc[0]
        about = info.get("scenes", {}).get(scene, {})
        lines += ["", f"## {scene} ({kind})", ""]
        if about.get("description"):
            lines += [about["description"], ""]
        lines += [f"Reference: `{reference}`." + (f" Scene file: `{about['source']}`." if about.get("source") else ""), ""]
        if kind == "ik":
            lines += [_IK_PROTOCOL, ""]
            solved = rows[~rows["metric"].str.startswith("hard_")].rename(columns={"integrator": "solver"})
            lines += _table(solved, _IK_COLUMNS, ["engine", "solver"])
            lines += _hard_table(rows)
        elif kind == "dynamics":
            per_dt = rows[rows["dt"].notna()]
            lines += _table(per_dt, _DYNAMICS_COLUMNS, ["engine", "integrator", "dt"])
            orders = rows[rows["dt"].isna()]
            if not orders.empty:
                lines += ["", "Observed order of convergence: slope of log(error max) against log(dt) over the "
                          "finest time steps whose local slopes agree (the asymptotic range); errors at the rounding "
                          "floor or saturated are left out.", ""]
                lines += _table(orders, _ORDER_COLUMNS, ["engine", "integrator"])
                lines += _fits(orders)
        else:
            lines += _table(rows, _KINEMATICS_COLUMNS, ["engine"])
        lines += _notes(rows)
    return "\n".join(lines) + "\n"
