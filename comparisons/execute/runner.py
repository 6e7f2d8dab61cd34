"""Runs cases on engines and measures them against each scene's reference.

Every scene x engine x integrator x dt gets one row per metric: ``ok`` with a value, or
``n/a`` / ``failed`` / ``diverged`` with the reason in ``detail``. An engine that raises
becomes ``failed`` rows; the run goes on.

A scene is planned into groups of cases (:mod:`comparisons.cases`); :func:`run_group` runs one
group wherever it is sent (this process, a worker process, a Dask worker), yielding each case's
outcome as it finishes; :func:`assemble_scene` puts a scene's outcomes together in its stored
order, with the observed orders of convergence and the IK agreement matrix
(:mod:`comparisons.execute.session` runs scenes through them, wherever their cases execute).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Iterator, cast

import numpy as np

from simparity.comparisons.execute.cases import (
    DYNAMICS,
    IK,
    JOINT_DYNAMICS,
    JOINT_MOTION,
    KINEMATICS,
    NO_INTEGRATOR,
    STABILITY,
    CaseGroup,
    CaseOutcome,
    CaseSpec,
)
from simparity.comparisons.measure.contact_metrics import contact_metrics
from simparity.comparisons.measure.divergence import blow_up
from simparity.comparisons.execute.ik_runner import failed_ik_outcome, ik_case, ik_scene_series, prepare_ik
from simparity.comparisons.measure.metrics import (
    KINEMATICS_METRICS,
    ORDER_METRICS,
    ORDER_SOURCES,
    ROTATIONAL_ORDERS,
    at_rounding_floor,
    conserved_changes,
    drifts,
    dynamics_metrics,
    frame_validity,
    kinematics_errors,
    observed_order,
    rounding_floors,
    saturation_ratios,
    saturation_scales,
    state_validity,
    trajectory_errors,
)
from simparity.comparisons.measure.joint_dynamics_metrics import (
    JOINT_DYNAMICS_METRICS,
    REFERENCE_ERRORS,
    identities,
    reference_errors,
    reference_values,
    shape_problem,
    timed_values,
)
from simparity.comparisons.measure.joint_motion_metrics import (
    JOINT_MOTION_ORDERS, JOINT_ORDER_SOURCES, motion_metrics,
)
from simparity.comparisons.measure.rows import Case, Measured, declared_scheme, error_text, warnings_into_rows
from simparity.comparisons.measure.series import dynamics_series
from simparity.comparisons.measure.stability import STABILITY_METRICS, stable_dt_max
from simparity.comparisons.execute.case_cost import case_cost, theory
from simparity.comparisons.execute.motion_runner import motion_case, prepare_motion
from simparity.comparisons.execute.timing import best_of
from simparity.core.model.engine import TRUTH_SCHEMES, Engine, Support
from simparity.core.model.errors import DivergedError, SimparityError
from simparity.core.model.results import DIVERGED, FAILED, NOT_AVAILABLE, OK, ResultRow, SeriesRecord
from simparity.core.model.scene import DynamicsScene, IKScene, JointDynamicsScene, JointMotionScene, KinematicsScene
from simparity.core.model.trajectory import Trajectory
from simparity.core.model.metric_catalogue import (
    STABLE_DT_MAX, TIME_PER_FK, TIME_PER_JACOBIAN, TIME_PER_STEP,
)

EngineFor = Callable[[str], Engine]
"""The engine of a name (the run's engines, the scene's reference)."""

OnStart = Callable[[int | None], None]
"""Called before a group's shared part (None: the reference) and before each case (its index)."""

DEFAULT_REPEATS = 3
"""Timed repeats per measurement (the minimum is kept), after one warm-up run."""

TIME_GRID_TOLERANCE = 1e-3
"""How far [steps] a trajectory's sample time may be from k * dt: a clock kept as t += dt drifts at most
~n^2 eps steps (1e-4 at the 10^6 steps a scene may have); a sample a thousandth of a step off is on another
grid, and every error measured against the reference's samples would be wrong."""


@dataclass
class _Ladder:
    """The cases of one engine x integrator over the scene's time steps, for the order fits."""

    dts: list[float] = field(default_factory=list)
    cases: list[CaseOutcome] = field(default_factory=list)

    @property
    def integrates_rotation(self) -> bool:
        return all(case.integrates_rotation for case in self.cases)

    @property
    def scheme(self) -> str:
        """The kind of scheme the engine declared for the integrator (its cases' rows'; "" when they disagree)."""
        schemes = {row.scheme for case in self.cases for row in case.rows}
        return schemes.pop() if len(schemes) == 1 else ""

    @property
    def theory(self) -> int | None:
        """The theoretical order the engine declares for the integrator (None unless its cases that say one agree)."""
        orders = {case.theoretical_order for case in self.cases if case.theoretical_order is not None}
        return orders.pop() if len(orders) == 1 else None


def _ignore_start(index: int | None) -> None:
    return None


@dataclass(frozen=True)
class _Kind:
    """How a kind of group runs: ``prepare(group, engine_for, reference_failure)`` computes what its cases share
    (the reference), ``case(group, shared, index, engine_for)`` one case's outcome."""

    prepare: Callable
    case: Callable


def prepare_group(group: CaseGroup, engine_for: EngineFor, reference_failure: str = "") -> object:
    """What the cases of ``group`` share (its reference trajectory, FK or targets), computed once.

    ``reference_failure``, when given, is why it is not to be computed again (it took its worker down): the
    cases run without it.
    """
    return _KINDS[group.kind].prepare(group, engine_for, reference_failure)


def run_case(group: CaseGroup, shared: object, index: int, engine_for: EngineFor) -> CaseOutcome:
    """The outcome of case ``index`` of ``group``, given what :func:`prepare_group` computed."""
    return _KINDS[group.kind].case(group, shared, index, engine_for)


def run_group(group: CaseGroup, engine_for: EngineFor, on_start: OnStart = _ignore_start,
              skip: frozenset[int] = frozenset(), reference_failure: str = "") -> Iterator[tuple[int, CaseOutcome]]:
    """(index, outcome) of every case of ``group`` but those in ``skip``, as each finishes, in this process."""
    on_start(None)
    shared = prepare_group(group, engine_for, reference_failure)
    for index in range(len(group.cases)):
        if index not in skip:
            on_start(index)
            yield index, run_case(group, shared, index, engine_for)


@dataclass(frozen=True)
class _DynamicsShared:
    """What the cases of a dynamics group share: the reference, its trajectory at the group's dt (None when
    there is none) and (why there is none, the status that gives)."""

    reference: str
    integrator: str
    trajectory: object
    problem: tuple[str, str]


def _prepare_dynamics(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> _DynamicsShared:
    scene = group.dynamics_scene
    reference = engine_for(scene.reference)
    integrator = reference.scene_integrators(scene)[0]
    traj, problem = _reference_trajectory(scene, reference, integrator, group.dt, group.reference_label,
                                          reference_failure)
    return _DynamicsShared(reference.name, integrator, traj, problem)


def _dynamics_case_at(group: CaseGroup, shared: _DynamicsShared, index: int, engine_for: EngineFor) -> CaseOutcome:
    scene, dt, spec = group.dynamics_scene, group.dt, group.cases[index]
    metrics = dynamics_metrics(scene)
    engine = engine_for(spec.engine)
    case = Case(scene.name, spec.engine, spec.integrator, dt, group.reference_label,
                declared_scheme(engine, spec.integrator, scene))
    if spec.integrator == NO_INTEGRATOR:
        return CaseOutcome(_no_integrator_rows(scene, engine, case, metrics))
    rows: list[ResultRow] = []
    is_reference = (spec.engine, spec.integrator) == (shared.reference, shared.integrator)
    with warnings_into_rows(rows):
        outcome = _dynamics_case(scene, engine, case, metrics, scene.n_steps(dt), shared.trajectory, shared.problem,
                                 group.repeats, is_reference)
        rows += outcome.rows
    outcome.rows = rows
    outcome.theoretical_order = theory(engine, spec.integrator)
    return outcome


def _no_integrator_rows(scene: DynamicsScene, engine: Engine, case: Case, metrics: dict) -> list[ResultRow]:
    """The rows of an engine that runs none of the scene's integrators: n/a with why (the engine's own refusal
    when it offers none, e.g. its library does not import), failed when it cannot even say."""
    try:
        offered = tuple(engine.scene_integrators(scene))
        if offered:
            reason = f"the scene runs only {', '.join(scene.integrators)}; {engine.name} offers {', '.join(offered)}"
        else:
            reason = engine.supports_dynamics(scene, NO_INTEGRATOR).reason or f"{engine.name} offers no integrator"
    except Exception as err:  # noqa: BLE001 - a user's engine failed to describe itself
        return case.rows(metrics, FAILED, error_text(err))
    return case.rows(metrics, NOT_AVAILABLE, reason)


def _reference_trajectory(scene: DynamicsScene, reference: Engine, integrator: str, dt: float, label: str,
                          reference_failure: str) -> tuple[object, tuple[str, str]]:
    """(the reference trajectory at ``dt`` or None, (why there is none, the status that gives)); ``label`` names
    the reference in the reasons."""
    if reference_failure:
        return None, (f"reference {label} failed: {reference_failure}", FAILED)
    try:
        support = reference.supports_dynamics(scene, integrator)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        support = Support.no(f"failed: {error_text(err)}")
    if not support.ok:
        return None, (f"reference {label} cannot do this scene: {support.reason}", NOT_AVAILABLE)
    try:
        with np.errstate(all="ignore"):
            traj = reference.build_dynamics(scene, integrator, dt).run(scene.n_steps(dt))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return None, (f"reference {label} failed: {error_text(err)}", FAILED)
    if not traj.is_finite():
        return None, (f"reference {label} diverged (non-finite state)", NOT_AVAILABLE)
    return traj, ("", NOT_AVAILABLE)


def _prepare_nothing(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> None:
    """The stability limits share nothing: each case bisects on its own."""
    return None


def _stability_case_at(group: CaseGroup, shared: None, index: int, engine_for: EngineFor) -> CaseOutcome:
    """The measured stability limit of one penalty-method integrator (:mod:`comparisons.stability`)."""
    scene, spec = group.dynamics_scene, group.cases[index]
    engine = engine_for(spec.engine)
    case = Case(scene.name, spec.engine, spec.integrator, math.nan, group.reference_label,
                declared_scheme(engine, spec.integrator, scene))
    rows: list[ResultRow] = []
    with warnings_into_rows(rows):
        try:
            support = engine.supports_dynamics(scene, spec.integrator)
            if not support.ok:
                rows += case.rows(STABILITY_METRICS, NOT_AVAILABLE, support.reason)
            else:
                limit = stable_dt_max(scene, engine, spec.integrator)
                rows += case.rows(STABILITY_METRICS, OK, f"measured by bisection on {scene.name}",
                                  {STABLE_DT_MAX: limit})
        except Exception as err:  # noqa: BLE001 - reported in the rows
            rows += case.rows(STABILITY_METRICS, FAILED, error_text(err))
    return CaseOutcome(rows)


def _dynamics_case(scene, engine: Engine, case: Case, metrics: dict, n: int, ref_traj, ref_problem: tuple[str, str],
                   repeats: int, is_reference: bool) -> CaseOutcome:
    """One case; ``ref_problem`` is (why there is no reference trajectory, the status that gives). The outcome's
    ``errors`` are the raw error values (saturated ones included), ``floors`` their rounding floors, for the order
    fits; both empty when nothing was measured."""
    try:
        support = engine.supports_dynamics(scene, case.integrator)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return CaseOutcome(case.rows(metrics, FAILED, error_text(err)))
    if not support.ok:
        return CaseOutcome(case.rows(metrics, NOT_AVAILABLE, support.reason))
    try:
        sim = engine.build_dynamics(scene, case.integrator, case.dt)
        with np.errstate(all="ignore"):  # a diverging run overflows; it is reported as diverged
            seconds, traj = best_of(lambda: sim.run(n), repeats)
            cost = case_cost(engine, sim, case, n, repeats)
    except DivergedError as err:
        return CaseOutcome(case.rows(metrics, DIVERGED, str(err)))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return CaseOutcome(case.rows(metrics, FAILED, error_text(err)))
    try:
        problem = sampling_problem(scene, traj, n, case.dt)
        if problem:
            return CaseOutcome(case.rows(metrics, FAILED, f"its trajectory does not sample the scene: {problem}"))
        return _measured_case(scene, sim, case, metrics, n, traj, {TIME_PER_STEP: Measured(seconds / n, "s")} | cost,
                              ref_traj, ref_problem, is_reference)
    except Exception as err:  # noqa: BLE001 - a user's engine returned what cannot be measured
        return CaseOutcome(case.rows(metrics, FAILED, f"its trajectory cannot be measured: {error_text(err)}"))


def sampling_problem(scene: DynamicsScene, traj, n: int, dt: float) -> str:
    """What is wrong with ``traj`` as the samples of ``n`` steps of ``dt`` of ``scene`` ("" when nothing): a
    Trajectory of n + 1 samples of every body, at times k * dt (within :data:`TIME_GRID_TOLERANCE` steps)."""
    if not isinstance(traj, Trajectory):
        return f"run() returned a value of type {type(traj).__name__} (allowed: a simparity.core.trajectory.Trajectory)"
    times = np.asarray(traj.times)
    if times.shape != (n + 1,):
        return f"its times have shape {times.shape} (expected ({n + 1},): the initial state and {n} steps)"
    if traj.n_bodies != len(scene.bodies):
        return f"it has {traj.n_bodies} bodies (the scene has {len(scene.bodies)})"
    with np.errstate(all="ignore"):
        off = np.abs(times - np.arange(n + 1) * dt) / dt
    bad = np.flatnonzero(~(off <= TIME_GRID_TOLERANCE))
    if bad.size:
        k = int(bad[0])
        return (f"sample {k} is at t = {float(times[k]):.9g} s (expected {k * dt:.9g} s, k * dt within "
                f"{TIME_GRID_TOLERANCE:g} steps)")
    return ""


def _measured_case(scene, sim, case: Case, metrics: dict, n: int, traj, timed: dict[str, Measured], ref_traj,
                   ref_problem: tuple[str, str], is_reference: bool) -> CaseOutcome:
    """The rows of a case whose simulation ran: ``traj`` measured against ``ref_traj``; ``timed``: its time and
    cost, measured as it ran."""
    values = dict(timed)
    with np.errstate(all="ignore"):
        blown, reading = blow_up(scene, traj)
        if blown:
            return CaseOutcome(case.rows(metrics, DIVERGED, f"{blown}; {sim.detail}", values),
                               integrates_rotation=sim.integrates_rotation)
        changes = conserved_changes(scene, traj)
        values.update(drifts(scene, traj, changes) | state_validity(traj))
        heights = None if reading is None else reading.distance[:, 0].min(axis=-1)
        series = dynamics_series(case, traj, ref_traj, changes, heights)
        floors = rounding_floors(scene, traj, n)
        if ref_traj is None:
            if reading is not None:
                values.update(contact_metrics(scene, traj, None, reading))
            problem, status = ref_problem
            return CaseOutcome(case.partial_rows(metrics, values, sim.detail, status, problem), series, floors=floors,
                               integrates_rotation=sim.integrates_rotation)
        scales = saturation_scales(scene, ref_traj)
        values.update(at_rounding_floor(trajectory_errors(traj, ref_traj, scales), floors))
        saturation = saturation_ratios(traj, ref_traj, scales)
        if reading is not None:
            values.update(contact_metrics(scene, traj, ref_traj, reading))
    detail = ("this is the reference; " if is_reference else "") + sim.detail
    return CaseOutcome(case.rows(metrics, OK, detail, values), series, {m: v.value for m, v in values.items()},
                       floors, sim.integrates_rotation, saturation=saturation)


@dataclass(frozen=True)
class _KinematicsShared:
    """The configurations of a kinematics group, the reference's (poses, Jacobians) there (None when there
    are none) and (why there are none, the status that gives)."""

    q: np.ndarray
    reference: tuple | None
    problem: tuple[str, str]


def _reference_values(label: str, reference_failure: str, supports: Callable[[], Support],
                      evaluate: Callable[[], object]) -> tuple[object | None, tuple[str, str]]:
    """(the reference's values at a chain group's samples, ("", n/a)), or (None, (why there are none, the status
    that gives)): its worker failed, it cannot do the chain (``supports``), or ``evaluate`` raised."""
    if reference_failure:
        return None, (f"reference {label} failed: {reference_failure}", FAILED)
    try:
        support = supports()
        if not support.ok:
            return None, (f"reference {label} cannot do this chain: {support.reason}", NOT_AVAILABLE)
        return evaluate(), ("", NOT_AVAILABLE)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return None, (f"reference {label} failed: {error_text(err)}", FAILED)


def _prepare_kinematics(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> _KinematicsShared:
    scene = group.kinematics_scene
    q = scene.configurations()

    def evaluate() -> tuple:
        model = engine_for(scene.reference).build_kinematics(scene.chain)
        return model.forward_kinematics(q), model.jacobian_world(q)

    values, problem = _reference_values(group.reference_label, reference_failure,
                                        lambda: engine_for(scene.reference).supports_kinematics(scene.chain), evaluate)
    return _KinematicsShared(q, cast(tuple | None, values), problem)


def _kinematics_case_at(group: CaseGroup, shared: _KinematicsShared, index: int, engine_for: EngineFor) -> CaseOutcome:
    scene, spec = group.kinematics_scene, group.cases[index]
    case = Case(scene.name, spec.engine, "", math.nan, group.reference_label)
    rows: list[ResultRow] = []
    with warnings_into_rows(rows):
        rows += _kinematics_case(scene, engine_for(spec.engine), case, shared.q, shared.reference, shared.problem,
                                 group.repeats, spec.engine == scene.reference)
    return CaseOutcome(rows)


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
    values = {TIME_PER_FK: Measured(fk_seconds / len(q), "s"), TIME_PER_JACOBIAN: Measured(jac_seconds / len(q), "s")}
    values.update(frame_validity(poses))
    if not (np.all(np.isfinite(poses.position_world)) and np.all(np.isfinite(jac))):
        return case.rows(KINEMATICS_METRICS, DIVERGED, "non-finite FK or Jacobian", values)
    if ref is None:
        problem, status = ref_problem
        return case.partial_rows(KINEMATICS_METRICS, values, model.detail, status, problem)
    values.update(kinematics_errors(poses, jac, *ref))
    return case.rows(KINEMATICS_METRICS, OK, ("this is the reference; " if is_reference else "") + model.detail, values)


@dataclass(frozen=True)
class _JointDynamicsShared:
    """The states of a joint-dynamics group, the reference's values there (None when there are none) and (why
    there are none, the status that gives)."""

    states: tuple[np.ndarray, ...]
    reference: dict | None
    problem: tuple[str, str]


def _prepare_joint_dynamics(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> _JointDynamicsShared:
    scene, label = group.joint_dynamics_scene, group.reference_label
    states, method = scene.states(), label.split(":", 1)[1]

    def evaluate() -> dict:
        model = engine_for(scene.reference).build_joint_dynamics(scene.chain, method, scene.gravity_world)
        values = reference_values(model, states)
        problem = shape_problem(values, len(states[0]), scene.chain.n_joints)
        if problem:
            raise SimparityError(f"unusable: {problem}")
        return values

    values, problem = _reference_values(label, reference_failure,
                                        lambda: engine_for(scene.reference).supports_joint_dynamics(scene.chain,
                                                                                                   method), evaluate)
    return _JointDynamicsShared(states, cast(dict | None, values), problem)


def _joint_dynamics_case_at(group: CaseGroup, shared: _JointDynamicsShared, index: int,
                            engine_for: EngineFor) -> CaseOutcome:
    scene, spec = group.joint_dynamics_scene, group.cases[index]
    engine = engine_for(spec.engine)
    case = Case(scene.name, spec.engine, spec.integrator, math.nan, group.reference_label,
                declared_scheme(engine, spec.integrator, scene))
    rows: list[ResultRow] = []
    with warnings_into_rows(rows):
        rows += _joint_dynamics_case(scene, engine, case, shared, group.repeats,
                                     f"{spec.engine}:{spec.integrator}" == group.reference_label)
    return CaseOutcome(rows)


def _joint_dynamics_case(scene: JointDynamicsScene, engine: Engine, case: Case, shared: _JointDynamicsShared,
                         repeats: int, is_reference: bool) -> list[ResultRow]:
    """Rows of one engine's joint-space dynamics at the scene's states: errors against the reference's values,
    the identities of its own, its times."""
    try:
        support = engine.supports_joint_dynamics(scene.chain, case.integrator)
        if not support.ok:
            return case.rows(JOINT_DYNAMICS_METRICS, NOT_AVAILABLE, support.reason)
        model = engine.build_joint_dynamics(scene.chain, case.integrator, scene.gravity_world)
        own, values = timed_values(model, shared.states, lambda fn: best_of(fn, repeats))
        problem = shape_problem(own, len(shared.states[0]), scene.chain.n_joints)
        if problem:
            status = DIVERGED if problem.startswith("non-finite") else FAILED
            return case.rows(JOINT_DYNAMICS_METRICS, status, problem, values)
        values.update(identities(model, scene.chain, shared.states, own))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return case.rows(JOINT_DYNAMICS_METRICS, FAILED, error_text(err))
    detail = ("this is the reference; " if is_reference else "") + model.detail
    if shared.reference is None:
        problem, status = shared.problem
        order = list(JOINT_DYNAMICS_METRICS)
        return sorted(case.partial_rows({m: u for m, u in JOINT_DYNAMICS_METRICS.items() if m not in REFERENCE_ERRORS},
                                        values, detail, status, problem)
                      + case.rows({m: JOINT_DYNAMICS_METRICS[m] for m in REFERENCE_ERRORS}, status, problem),
                      key=lambda row: order.index(row.metric))
    values.update(reference_errors(own, shared.reference))
    return case.rows(JOINT_DYNAMICS_METRICS, OK, detail, {m: values[m] for m in JOINT_DYNAMICS_METRICS})


def _orders(scene: DynamicsScene, ladders: dict[tuple[str, str], _Ladder], ref_label: str) -> list[ResultRow]:
    """Observed orders of convergence per engine and integrator over the scene's time steps."""
    rows = []
    for (engine, integrator), ladder in ladders.items():
        case = Case(scene.name, engine, integrator, math.nan, ref_label, ladder.scheme)
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
            values[metric] = observed_order(ladder.dts, [c.errors.get(source, math.nan) for c in ladder.cases],
                                            [c.floors.get(source, 0.0) for c in ladder.cases],
                                            [c.saturation.get(source, 0.0) for c in ladder.cases], ladder.theory)
        rows += case.rows(ORDER_METRICS, OK, f"against {ref_label}", values)
    return rows


def _joint_orders(scene: JointMotionScene, ladders: dict[tuple[str, str], _Ladder], ref_label: str) -> list[ResultRow]:
    """Observed orders of convergence of the joint values and velocities per engine and integrator."""
    rows = []
    for (engine, integrator), ladder in ladders.items():
        case = Case(scene.name, engine, integrator, math.nan, ref_label, ladder.scheme)
        if ladder.scheme in TRUTH_SCHEMES:  # its error is set by a tolerance or by rounding, not by dt
            values = {metric: Measured(math.nan, "1", unmeasurable=(
                f"a truth ({ladder.scheme.replace('_', ' ')}) does not step at dt: its error has no order"))
                for metric in JOINT_ORDER_SOURCES}
        else:
            values = {metric: observed_order(ladder.dts, [c.errors.get(source, math.nan) for c in ladder.cases],
                                             [c.floors.get(source, 0.0) for c in ladder.cases],
                                             [c.saturation.get(source, 0.0) for c in ladder.cases], ladder.theory)
                      for metric, source in JOINT_ORDER_SOURCES.items()}
        rows += case.rows(JOINT_MOTION_ORDERS, OK, f"against {ref_label}", values)
    return rows


_KINDS = {DYNAMICS: _Kind(_prepare_dynamics, _dynamics_case_at), STABILITY: _Kind(_prepare_nothing, _stability_case_at),
          KINEMATICS: _Kind(_prepare_kinematics, _kinematics_case_at), IK: _Kind(prepare_ik, ik_case),
          JOINT_DYNAMICS: _Kind(_prepare_joint_dynamics, _joint_dynamics_case_at),
          JOINT_MOTION: _Kind(prepare_motion, motion_case)}


def failed_outcome(group: CaseGroup, spec: CaseSpec, cause: str) -> CaseOutcome:
    """The outcome of a case that did not finish (its worker crashed, hung or ran out of memory):
    ``failed`` rows of every metric the case has, naming ``cause``."""
    if group.kind == IK:
        return failed_ik_outcome(group, spec, cause)
    scene = group.scene
    metrics = {DYNAMICS: lambda: dynamics_metrics(group.dynamics_scene), STABILITY: lambda: STABILITY_METRICS,
               KINEMATICS: lambda: KINEMATICS_METRICS, JOINT_DYNAMICS: lambda: JOINT_DYNAMICS_METRICS,
               JOINT_MOTION: lambda: motion_metrics(group.joint_motion_scene)}[group.kind]()
    case = Case(scene.name, spec.engine, spec.integrator, group.dt, group.reference_label)
    return CaseOutcome(case.rows(metrics, FAILED, cause), harness_failure=True)


def assemble_scene(scene, groups: list[CaseGroup],
                   outcomes: list[list[CaseOutcome]]) -> tuple[list[ResultRow], list[SeriesRecord]]:
    """A scene's rows and series in their stored order from every case's outcome (``outcomes[g][c]`` of
    case c of group g), with what needs them all: the observed orders of a dynamics scene (after the
    time steps' rows, before the stability limits), the FK agreement matrix of an IK scene."""
    ladders: dict[tuple[str, str], _Ladder] = {}
    for group, results in zip(groups, outcomes):
        for spec, outcome in zip(group.cases, results):
            if group.kind in (DYNAMICS, JOINT_MOTION) and spec.integrator != NO_INTEGRATOR:
                ladder = ladders.setdefault((spec.engine, spec.integrator), _Ladder())
                ladder.dts.append(group.dt)
                ladder.cases.append(outcome)
    rows = [row for group, results in zip(groups, outcomes) if group.kind != STABILITY
            for outcome in results for row in outcome.rows]
    if isinstance(scene, DynamicsScene) and len(scene.dts) > 1:
        rows += _orders(scene, ladders, groups[0].reference_label)
    if isinstance(scene, JointMotionScene) and len(scene.dts) > 1:
        rows += _joint_orders(scene, ladders, groups[0].reference_label)
    rows += [row for group, results in zip(groups, outcomes) if group.kind == STABILITY
             for outcome in results for row in outcome.rows]
    series = [record for results in outcomes for outcome in results for record in outcome.series]
    if isinstance(scene, IKScene):
        series += ik_scene_series(scene, [outcome for results in outcomes for outcome in results])
    return rows, series
