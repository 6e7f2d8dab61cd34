"""Runs scenes on engines and measures them against each scene's reference.

Every scene x engine x integrator x dt gets one row per metric: ``ok`` with a value, or
``n/a`` / ``failed`` / ``diverged`` with the reason in ``detail``. An engine that raises
becomes ``failed`` rows; the run goes on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from simparity.comparisons.contact_metrics import contact_metrics
from simparity.comparisons.divergence import blow_up
from simparity.comparisons.ik_runner import run_ik_scene
from simparity.comparisons.metrics import (
    KINEMATICS_METRICS,
    ORDER_METRICS,
    ORDER_SOURCES,
    ROTATIONAL_ORDERS,
    SATURATED_ORIENTATION,
    conserved_changes,
    drifts,
    dynamics_metrics,
    kinematics_errors,
    observed_order,
    rounding_floors,
    trajectory_errors,
)
from simparity.comparisons.rows import Case, Measured, error_text, warnings_into_rows
from simparity.comparisons.series import dynamics_series
from simparity.comparisons.stability import STABILITY_METRICS, stable_dt_max
from simparity.comparisons.timing import best_of
from simparity.core.engine import Engine, Support
from simparity.core.errors import DivergedError
from simparity.core.results import DIVERGED, FAILED, NOT_AVAILABLE, OK, ResultRow, SeriesRecord
from simparity.core.scene import PENALTY_PREFIX, DynamicsScene, IKScene, KinematicsScene

Progress = Callable[[str, str], None]
"""Called with (engine, integrator or solver) after each case of a scene."""

DEFAULT_REPEATS = 3
"""Timed repeats per measurement (the minimum is kept), after one warm-up run."""


@dataclass
class _CaseResult:
    """One dynamics case: its rows, and what the order fits need from it.

    ``errors`` are the raw error values (saturated ones included), ``floors`` their rounding
    floors; both empty when nothing was measured.
    """

    rows: list[ResultRow]
    errors: dict[str, float] = field(default_factory=dict)
    floors: dict[str, float] = field(default_factory=dict)
    integrates_rotation: bool = True


@dataclass
class _Ladder:
    """The cases of one engine x integrator over the scene's time steps, for the order fits."""

    dts: list[float] = field(default_factory=list)
    cases: list[_CaseResult] = field(default_factory=list)

    @property
    def integrates_rotation(self) -> bool:
        return all(case.integrates_rotation for case in self.cases)


def _integrators(scene: DynamicsScene, engine: Engine) -> tuple[list[str], str]:
    """(the engine's integrators the scene runs, reason when none)."""
    offered = list(engine.scene_integrators(scene))
    chosen = [i for i in offered if not scene.integrators or i in scene.integrators]
    reason = "" if chosen else (
        f"the scene runs only {', '.join(scene.integrators)}; {engine.name} offers {', '.join(offered)}")
    return chosen, reason


def _dynamics(scene: DynamicsScene, engines: list[Engine], reference: Engine, repeats: int,
              series: list[SeriesRecord] | None, progress: Progress) -> list[ResultRow]:
    rows: list[ResultRow] = []
    metrics = dynamics_metrics(scene)
    ref_integrator = reference.scene_integrators(scene)[0]
    ref_label = f"{reference.name}:{ref_integrator}"
    try:
        ref_support = reference.supports_dynamics(scene, ref_integrator)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        ref_support = Support.no(f"failed: {error_text(err)}")
    ladders: dict[tuple[str, str], _Ladder] = {}
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
                with warnings_into_rows(rows):
                    result = _dynamics_case(scene, engine, case, metrics, n, ref_traj, (ref_problem, ref_status),
                                            repeats, is_reference, series)
                    rows += result.rows
                ladder = ladders.setdefault((engine.name, integrator), _Ladder())
                ladder.dts.append(dt)
                ladder.cases.append(result)
                progress(engine.name, integrator)
    if len(scene.dts) > 1:
        rows += _orders(scene, ladders, ref_label)
    if scene.contact is not None:
        rows += _stability_limits(scene, engines, ref_label)
    return rows


def _stability_limits(scene: DynamicsScene, engines: list[Engine], ref_label: str) -> list[ResultRow]:
    """The measured stability limit of every penalty-method integrator of the scene (:mod:`comparisons.stability`)."""
    rows: list[ResultRow] = []
    for engine in engines:
        for integrator in _integrators(scene, engine)[0]:
            if not integrator.startswith(PENALTY_PREFIX):
                continue
            case = Case(scene.name, engine.name, integrator, math.nan, ref_label)
            with warnings_into_rows(rows):
                try:
                    support = engine.supports_dynamics(scene, integrator)
                    if not support.ok:
                        rows += case.rows(STABILITY_METRICS, NOT_AVAILABLE, support.reason)
                        continue
                    limit = stable_dt_max(scene, engine, integrator)
                    rows += case.rows(STABILITY_METRICS, OK, f"measured by bisection on {scene.name}",
                                      {"stable_dt_max": limit})
                except Exception as err:  # noqa: BLE001 - reported in the rows
                    rows += case.rows(STABILITY_METRICS, FAILED, error_text(err))
    return rows


def _orders(scene: DynamicsScene, ladders: dict[tuple[str, str], _Ladder], ref_label: str) -> list[ResultRow]:
    """Observed orders of convergence per engine and integrator over the scene's time steps."""
    rows = []
    for (engine, integrator), ladder in ladders.items():
        case = Case(scene.name, engine, integrator, math.nan, ref_label)
        values = {}
        for metric, source in ORDER_SOURCES.items():
            if scene.contact is not None:
                values[metric] = Measured(math.nan, "1", unmeasurable=(
                    "contact: an impact timed a fraction of a step off makes the error jump with dt; the error "
                    "has no asymptotic order"))
                continue
            if metric in ROTATIONAL_ORDERS and not ladder.integrates_rotation:
                values[metric] = Measured(math.nan, "1", unmeasurable=(
                    "point-mass rule: the integrator does not move orientation, so it has no rotational order"))
                continue
            saturation = SATURATED_ORIENTATION if source == "orientation_error_max" else math.inf
            values[metric] = observed_order(ladder.dts, [c.errors.get(source, math.nan) for c in ladder.cases],
                                            [c.floors.get(source, 0.0) for c in ladder.cases], saturation)
        rows += case.rows(ORDER_METRICS, OK, f"against {ref_label}", values)
    return rows


def _dynamics_case(scene, engine: Engine, case: Case, metrics: dict, n: int, ref_traj, ref_problem: tuple[str, str],
                   repeats: int, is_reference: bool, series: list[SeriesRecord] | None) -> _CaseResult:
    """One case; ``ref_problem`` is (why there is no reference trajectory, the status that gives).
    The case's sampled series go to ``series`` unless it is None."""
    try:
        support = engine.supports_dynamics(scene, case.integrator)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return _CaseResult(case.rows(metrics, FAILED, error_text(err)))
    if not support.ok:
        return _CaseResult(case.rows(metrics, NOT_AVAILABLE, support.reason))
    try:
        sim = engine.build_dynamics(scene, case.integrator, case.dt)
        with np.errstate(all="ignore"):  # a diverging run overflows; it is reported as diverged
            seconds, traj = best_of(lambda: sim.run(n), repeats)
    except DivergedError as err:
        return _CaseResult(case.rows(metrics, DIVERGED, str(err)))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return _CaseResult(case.rows(metrics, FAILED, error_text(err)))
    values = {"time_per_step": Measured(seconds / n, "s")}
    with np.errstate(all="ignore"):
        blown, reading = blow_up(scene, traj)
        if blown:
            return _CaseResult(case.rows(metrics, DIVERGED, f"{blown}; {sim.detail}", values),
                               integrates_rotation=sim.integrates_rotation)
        changes = conserved_changes(scene, traj)
        values.update(drifts(scene, traj, changes))
        if series is not None:
            heights = None if reading is None else reading.distance[:, 0].min(axis=-1)
            series += dynamics_series(case, traj, ref_traj, changes, heights)
        floors = rounding_floors(scene, traj, n)
        if ref_traj is None:
            if reading is not None:
                values.update(contact_metrics(scene, traj, None, reading))
            problem, status = ref_problem
            return _CaseResult(case.partial_rows(metrics, values, sim.detail, status, problem), {}, floors,
                               sim.integrates_rotation)
        values.update(trajectory_errors(traj, ref_traj))
        if reading is not None:
            values.update(contact_metrics(scene, traj, ref_traj, reading))
    detail = ("this is the reference; " if is_reference else "") + sim.detail
    return _CaseResult(case.rows(metrics, OK, detail, values), {m: v.value for m, v in values.items()}, floors,
                       sim.integrates_rotation)


def _kinematics(scene: KinematicsScene, engines: list[Engine], reference: Engine, repeats: int,
                progress: Progress) -> list[ResultRow]:
    q = scene.configurations()
    ref_label = f"{reference.name}:fk"
    ref, ref_problem, ref_status = None, "", NOT_AVAILABLE
    try:
        ref_support = reference.supports_kinematics(scene.chain)
        if not ref_support.ok:
            ref_problem = f"reference {ref_label} cannot do this chain: {ref_support.reason}"
        else:
            model = reference.build_kinematics(scene.chain)
            ref = (model.forward_kinematics(q), model.jacobian_world(q))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        ref_problem, ref_status = f"reference {ref_label} failed: {error_text(err)}", FAILED
    rows: list[ResultRow] = []
    for engine in engines:
        case = Case(scene.name, engine.name, "", math.nan, ref_label)
        with warnings_into_rows(rows):
            rows += _kinematics_case(scene, engine, case, q, ref, (ref_problem, ref_status), repeats,
                                     engine.name == reference.name)
        progress(engine.name, "")
    return rows


def _kinematics_case(scene: KinematicsScene, engine: Engine, case: Case, q: np.ndarray, ref, ref_problem: tuple[str, str],
                     repeats: int, is_reference: bool) -> list[ResultRow]:
    """Rows of one engine's FK and Jacobian at configurations ``q`` against ``ref`` = (poses, Jacobians) or None."""
    try:
        support = engine.supports_kinematics(scene.chain)
        if not support.ok:
            return case.rows(KINEMATICS_METRICS, NOT_AVAILABLE, support.reason)
        model = engine.build_kinematics(scene.chain)
        fk_seconds, poses = best_of(lambda: model.forward_kinematics(q), repeats)
        jac_seconds, jac = best_of(lambda: model.jacobian_world(q), repeats)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return case.rows(KINEMATICS_METRICS, FAILED, error_text(err))
    values = {"time_per_fk": Measured(fk_seconds / len(q), "s"), "time_per_jacobian": Measured(jac_seconds / len(q), "s")}
    if not (np.all(np.isfinite(poses.position_world)) and np.all(np.isfinite(jac))):
        return case.rows(KINEMATICS_METRICS, DIVERGED, "non-finite FK or Jacobian", values)
    if ref is None:
        problem, status = ref_problem
        return case.partial_rows(KINEMATICS_METRICS, values, model.detail, status, problem)
    values.update(kinematics_errors(poses, jac, *ref))
    return case.rows(KINEMATICS_METRICS, OK, ("this is the reference; " if is_reference else "") + model.detail, values)


def run_scene(
    scene, engines: list[Engine], make_reference: Callable[[str], Engine], repeats: int = DEFAULT_REPEATS,
    series: list[SeriesRecord] | None = None, progress: Progress | None = None,
) -> list[ResultRow]:
    """All rows of one scene on ``engines``, measured against ``make_reference(scene.reference)``.

    When ``series`` is a list, the scene's sampled series (:mod:`comparisons.series`) are appended to it;
    ``progress(engine, integrator)`` is called after each case (:func:`count_cases` of them).
    """
    progress = progress or _no_progress
    if isinstance(scene, IKScene):
        return run_ik_scene(scene, engines, make_reference, repeats, series, progress)
    reference = make_reference(scene.reference)
    if isinstance(scene, DynamicsScene):
        return _dynamics(scene, engines, reference, repeats, series, progress)
    return _kinematics(scene, engines, reference, repeats, progress)


def count_cases(scene, engines: list[Engine]) -> int:
    """How many times :func:`run_scene` calls ``progress`` for ``scene``: its cases, order fits aside."""
    if isinstance(scene, IKScene):
        return sum(len(engine.ik_solvers() or ("-",)) for engine in engines)
    if isinstance(scene, DynamicsScene):
        return len(scene.dts) * sum(len(_integrators(scene, engine)[0]) for engine in engines)
    return len(engines)


def _no_progress(engine: str, integrator: str) -> None:
    return None
