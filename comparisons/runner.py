"""Runs scenes on engines and measures them against each scene's reference.

Every scene x engine x integrator x dt gets one row per metric: ``ok`` with a value, or
``n/a`` / ``failed`` / ``diverged`` with the reason in ``detail``. An engine that raises
becomes ``failed`` rows; the run goes on.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from simparity.comparisons.metrics import (
    KINEMATICS_METRICS,
    ORDER_METRICS,
    drifts,
    dynamics_metrics,
    kinematics_errors,
    observed_order,
    trajectory_errors,
)
from simparity.comparisons.ik_runner import run_ik_scene
from simparity.comparisons.rows import Case, error_text
from simparity.comparisons.timing import best_of
from simparity.core.engine import Engine
from simparity.core.errors import DivergedError
from simparity.core.results import DIVERGED, FAILED, NOT_AVAILABLE, OK, ResultRow
from simparity.core.scene import DynamicsScene, IKScene, KinematicsScene

DEFAULT_REPEATS = 3
"""Timed repeats per measurement (the minimum is kept), after one warm-up run."""

BLOW_UP_FACTOR = 1e6
"""A run whose speed or spin exceeds this many times what the scene could plausibly reach
(initial speed plus what gravity adds over the duration, plus 1) has blown up: diverged."""


def _integrators(scene: DynamicsScene, engine: Engine) -> tuple[list[str], str]:
    """(the engine's integrators the scene runs, reason when none)."""
    offered = list(engine.integrators())
    chosen = [i for i in offered if not scene.integrators or i in scene.integrators]
    reason = "" if chosen else (
        f"the scene runs only {', '.join(scene.integrators)}; {engine.name} offers {', '.join(offered)}")
    return chosen, reason


def _dynamics(scene: DynamicsScene, engines: list[Engine], reference: Engine, repeats: int) -> list[ResultRow]:
    rows: list[ResultRow] = []
    metrics = dynamics_metrics(scene)
    ref_integrator = reference.integrators()[0]
    ref_label = f"{reference.name}:{ref_integrator}"
    ref_support = reference.supports_dynamics(scene, ref_integrator)
    errors: dict[tuple[str, str], list[tuple[float, dict]]] = {}
    for dt in scene.dts:
        n = scene.n_steps(dt)
        ref_traj, ref_problem, ref_status = None, "", NOT_AVAILABLE
        if not ref_support.ok:
            ref_problem = f"reference {ref_label} cannot do this scene: {ref_support.reason}"
        else:
            try:
                with np.errstate(all="ignore"):
                    ref_traj = reference.build_dynamics(scene, ref_integrator, dt).run(n)
                if not ref_traj.is_finite():
                    ref_traj, ref_problem = None, f"reference {ref_label} diverged (non-finite state)"
            except Exception as err:  # noqa: BLE001 - reported in the rows
                ref_problem, ref_status = f"reference {ref_label} failed: {error_text(err)}", FAILED
        for engine in engines:
            chosen, reason = _integrators(scene, engine)
            if not chosen:
                rows += Case(scene.name, engine.name, "-", dt, ref_label).rows(metrics, NOT_AVAILABLE, reason)
            for integrator in chosen:
                case = Case(scene.name, engine.name, integrator, dt, ref_label)
                is_reference = engine.name == reference.name and integrator == ref_integrator
                case_rows = _dynamics_case(scene, engine, case, metrics, n, ref_traj, (ref_problem, ref_status),
                                           repeats, is_reference)
                rows += case_rows
                errors.setdefault((engine.name, integrator), []).append(
                    (dt, {r.metric: r.value for r in case_rows if r.status == OK}))
    if len(scene.dts) > 1:
        rows += _orders(scene, errors, ref_label)
    return rows


def _blown_up(scene: DynamicsScene, traj) -> str:
    """Why the trajectory counts as blown up (see BLOW_UP_FACTOR), or "" when it does not."""
    g = 0.0 if scene.forces.gravity_world is None else float(np.linalg.norm(scene.forces.gravity_world))
    for name, values, start in (
        ("speed", traj.velocity_world, [b.velocity_world for b in scene.bodies]),
        ("angular speed", traj.angular_velocity_world, [b.angular_velocity_world for b in scene.bodies]),
    ):
        bound = BLOW_UP_FACTOR * (np.linalg.norm(start, axis=-1).max() + g * scene.duration + 1.0)
        peak = float(np.linalg.norm(values, axis=-1).max())
        if peak > bound:
            return f"{name} reached {peak:.3g} (bound {bound:.3g})"
    return ""


def _orders(scene: DynamicsScene, errors: dict, ref_label: str) -> list[ResultRow]:
    """Observed order of convergence per engine and integrator over the scene's time steps."""
    rows = []
    for (engine, integrator), per_dt in errors.items():
        dts = [dt for dt, _ in per_dt]
        for metric, source in (("order_position", "position_error_max"), ("order_orientation", "orientation_error_max")):
            slope, detail = observed_order(dts, [values.get(source, math.nan) for _, values in per_dt])
            status = NOT_AVAILABLE if math.isnan(slope) else OK
            rows.append(ResultRow(scene.name, engine, integrator, math.nan, metric, slope, ORDER_METRICS[metric],
                                  ref_label, status, detail))
    return rows


def _dynamics_case(scene, engine: Engine, case: Case, metrics: dict, n: int, ref_traj, ref_problem: tuple[str, str],
                   repeats: int, is_reference: bool) -> list[ResultRow]:
    """Rows of one case; ``ref_problem`` is (why there is no reference trajectory, the status that gives)."""
    support = engine.supports_dynamics(scene, case.integrator)
    if not support.ok:
        return case.rows(metrics, NOT_AVAILABLE, support.reason)
    try:
        sim = engine.build_dynamics(scene, case.integrator, case.dt)
        with np.errstate(all="ignore"):  # a diverging run overflows; it is reported as diverged
            seconds, traj = best_of(lambda: sim.run(n), repeats)
    except DivergedError as err:
        return case.rows(metrics, DIVERGED, str(err))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return case.rows(metrics, FAILED, error_text(err))
    values = {"time_per_step": (seconds / n, "s")}
    if not traj.is_finite():
        return case.rows(metrics, DIVERGED, "non-finite state; " + sim.detail, values)
    blown = _blown_up(scene, traj)
    if blown:
        return case.rows(metrics, DIVERGED, f"{blown}; {sim.detail}", values)
    with np.errstate(all="ignore"):
        values.update(drifts(scene, traj))
    if ref_traj is None:
        problem, status = ref_problem
        return case.partial_rows(metrics, values, sim.detail, status, problem)
    values.update(trajectory_errors(traj, ref_traj))
    detail = ("this is the reference; " if is_reference else "") + sim.detail
    return case.rows(metrics, OK, detail, values)


def _kinematics(scene: KinematicsScene, engines: list[Engine], reference: Engine, repeats: int) -> list[ResultRow]:
    q = scene.configurations()
    ref_label = f"{reference.name}:fk"
    ref, ref_problem, ref_status = None, "", NOT_AVAILABLE
    ref_support = reference.supports_kinematics(scene.chain)
    if not ref_support.ok:
        ref_problem = f"reference {ref_label} cannot do this chain: {ref_support.reason}"
    else:
        try:
            model = reference.build_kinematics(scene.chain)
            ref = (model.forward_kinematics(q), model.jacobian_world(q))
        except Exception as err:  # noqa: BLE001 - reported in the rows
            ref_problem, ref_status = f"reference {ref_label} failed: {error_text(err)}", FAILED
    rows: list[ResultRow] = []
    for engine in engines:
        case = Case(scene.name, engine.name, "", math.nan, ref_label)
        support = engine.supports_kinematics(scene.chain)
        if not support.ok:
            rows += case.rows(KINEMATICS_METRICS, NOT_AVAILABLE, support.reason)
            continue
        try:
            model = engine.build_kinematics(scene.chain)
            fk_seconds, poses = best_of(lambda: model.forward_kinematics(q), repeats)
            jac_seconds, jac = best_of(lambda: model.jacobian_world(q), repeats)
        except Exception as err:  # noqa: BLE001 - reported in the rows
            rows += case.rows(KINEMATICS_METRICS, FAILED, error_text(err))
            continue
        values = {"time_per_fk": (fk_seconds / len(q), "s"), "time_per_jacobian": (jac_seconds / len(q), "s")}
        if not (np.all(np.isfinite(poses.position_world)) and np.all(np.isfinite(jac))):
            rows += case.rows(KINEMATICS_METRICS, DIVERGED, "non-finite FK or Jacobian", values)
            continue
        if ref is None:
            rows += case.partial_rows(KINEMATICS_METRICS, values, model.detail, ref_status, ref_problem)
            continue
        values.update(kinematics_errors(poses, jac, *ref))
        detail = ("this is the reference; " if engine.name == reference.name else "") + model.detail
        rows += case.rows(KINEMATICS_METRICS, OK, detail, values)
    return rows


def run_scene(
    scene, engines: list[Engine], make_reference: Callable[[str], Engine], repeats: int = DEFAULT_REPEATS
) -> list[ResultRow]:
    """All rows of one scene on ``engines``, measured against ``make_reference(scene.reference)``."""
    if isinstance(scene, IKScene):
        return run_ik_scene(scene, engines, make_reference, repeats)
    reference = make_reference(scene.reference)
    if isinstance(scene, DynamicsScene):
        return _dynamics(scene, engines, reference, repeats)
    return _kinematics(scene, engines, reference, repeats)
