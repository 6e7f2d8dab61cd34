"""A chain's groups without time stepping: forward kinematics and Jacobians at sampled configurations, and joint
dynamics (M, h, RNEA, ABA) at sampled states, each engine's values against the reference's there.
:mod:`comparisons.execute.runner` dispatches groups here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, cast

import numpy as np

from simparity.comparisons.execute.cases import CaseGroup, CaseOutcome, EngineFor
from simparity.comparisons.execute.derivative_runner import (
    DerivativeTruth,
    derivative_truth,
    derivative_values,
    with_derivative_scheme,
)
from simparity.comparisons.measure.metrics import KINEMATICS_METRICS, frame_validity, kinematics_errors
from simparity.comparisons.measure.model_parity import (
    GROUP_METRICS,
    JOINT_METRICS,
    configurations,
    joint_parity,
    model_parity,
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
from simparity.comparisons.measure.joint_force_scale import ForceScale, force_scale
from simparity.comparisons.measure.rows import Case, Measured, declared_scheme, warnings_into_rows
from simparity.comparisons.common.error_text import error_text
from simparity.comparisons.execute.timing import best_of
from simparity.core.model.engine import Engine, JointDynamicsModel, Support
from simparity.core.model.errors import SimparityError
from simparity.core.model.results import DIVERGED, FAILED, NOT_AVAILABLE, OK, ResultRow, SeriesRecord
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene
from simparity.core.model.rigid_groups import FIELDS, CompiledJoints, RigidGroups
from simparity.core.model.scenes.kinematics import KinematicsScene
from simparity.core.model.metric_catalogue import TIME_PER_FK, TIME_PER_JACOBIAN


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


def prepare_kinematics(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> _KinematicsShared:
    scene = group.kinematics_scene
    q = scene.configurations()

    def evaluate() -> tuple:
        model = engine_for(scene.reference).build_kinematics(scene.chain)
        return model.forward_kinematics(q), model.jacobian_world(q)

    values, problem = _reference_values(group.reference_label, reference_failure,
                                        lambda: engine_for(scene.reference).supports_kinematics(scene.chain), evaluate)
    return _KinematicsShared(q, cast(tuple | None, values), problem)


def kinematics_case(group: CaseGroup, shared: _KinematicsShared, index: int, engine_for: EngineFor) -> CaseOutcome:
    scene, spec = group.kinematics_scene, group.cases[index]
    case = Case(scene.name, spec.engine, "", math.nan, group.reference_label)
    rows: list[ResultRow] = []
    with warnings_into_rows(rows):
        rows += _kinematics_rows(scene, engine_for(spec.engine), case, shared.q, shared.reference, shared.problem,
                                 group.repeats, spec.engine == scene.reference)
    return CaseOutcome(rows)


def _kinematics_rows(scene: KinematicsScene, engine: Engine, case: Case, q: np.ndarray, ref, ref_problem: tuple[str, str],
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
    """The states of a joint-dynamics group, the reference's values there and its force scale (None when there are
    none) and (why there are none, the status that gives)."""

    states: tuple[np.ndarray, ...]
    reference: dict | None
    problem: tuple[str, str]
    scale: ForceScale | None = None
    groups: RigidGroups | None = None
    groups_problem: str = ""
    joints: CompiledJoints | None = None
    joints_problem: str = ""
    truth: DerivativeTruth | None = None
    truth_problem: str = ""


def prepare_joint_dynamics(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> _JointDynamicsShared:
    scene, label = group.joint_dynamics_scene, group.reference_label
    states, method = scene.states(), label.split(":", 1)[1]
    truth, truth_why = derivative_truth(scene, states)

    def evaluate() -> tuple[dict, ForceScale, JointDynamicsModel]:
        model = engine_for(scene.reference).build_joint_dynamics(scene.chain, method, scene.gravity_world)
        values = reference_values(model, states)
        problem = shape_problem(values, len(states[0]), scene.chain.nv)
        if problem:
            raise SimparityError(f"unusable: {problem}")
        return values, _force_scale(scene, engine_for(scene.reference), method, model, states, values), model

    evaluated, problem = _reference_values(label, reference_failure,
                                           lambda: engine_for(scene.reference).supports_joint_dynamics(scene.chain,
                                                                                                      method), evaluate)
    if evaluated is None:
        return _JointDynamicsShared(states, None, problem, truth=truth, truth_problem=truth_why)
    values, scale, built = cast(tuple[dict, ForceScale, JointDynamicsModel], evaluated)
    groups, why = _reported(lambda: built.rigid_groups(configurations(scene.chain.joint_values(states[0]))), label)
    joints, joints_why = _reported(built.compiled_joints, label)
    return _JointDynamicsShared(states, values, problem, scale, groups, why, joints, joints_why, truth, truth_why)


def _reported(report: Callable[[], Any], label: str) -> tuple[Any, str]:
    """(what the reference ``label`` reports of its compiled model, "") or (None, why it reports nothing)."""
    try:
        return report(), ""
    except NotImplementedError as err:
        return None, f"the reference {label} reports no compiled model: {err}"
    except Exception as err:  # noqa: BLE001 - a user's reference: its model rows say why
        return None, f"the reference {label}'s compiled model could not be read: {error_text(err)}"


def _not_measured(metrics: dict[str, str], why: str) -> dict[str, Measured]:
    return {m: Measured(math.nan, u, unmeasurable=why) for m, u in metrics.items()}


def _model_parity(model: JointDynamicsModel, shared: _JointDynamicsShared, chain) -> dict[str, Measured]:
    """The model-parity values of ``model`` against the reference's compiled model (n/a with why where either
    engine reports none; an engine's failure to report one fails the case with its error)."""
    names = tuple(j.name for j in chain.joints)
    out = _not_measured(GROUP_METRICS, shared.groups_problem) | _not_measured(JOINT_METRICS, shared.joints_problem)
    if shared.groups is not None:
        try:
            own = model.rigid_groups(configurations(chain.joint_values(shared.states[0])))
        except NotImplementedError as err:
            out |= _not_measured(GROUP_METRICS, str(err))
        else:
            bad = [f for f in FIELDS if not np.all(np.isfinite(getattr(own, f)))]
            if bad:
                raise ValueError(f"non-finite {', '.join(bad)}")
            out |= model_parity(own, shared.groups, names)
    if shared.joints is not None:
        try:
            compiled = model.compiled_joints()
        except NotImplementedError as err:
            out |= _not_measured(JOINT_METRICS, str(err))
        else:
            if np.any(np.isnan(compiled.lower)) or np.any(np.isnan(compiled.upper)):
                raise ValueError("non-finite limits (NaN)")
            out |= joint_parity(compiled, shared.joints, names)
    return out


def _force_scale(scene: JointDynamicsScene, engine: Engine, method: str, model: JointDynamicsModel,
                 states: tuple[np.ndarray, ...], values: dict) -> ForceScale:
    """The chain's force scale by ``engine``'s ``model`` (method ``method``) and its ``values`` at ``states``."""
    return force_scale(model, lambda gravity: engine.build_joint_dynamics(scene.chain, method, gravity),
                       scene.gravity_world, states, values)


def joint_dynamics_case(group: CaseGroup, shared: _JointDynamicsShared, index: int,
                            engine_for: EngineFor) -> CaseOutcome:
    scene, spec = group.joint_dynamics_scene, group.cases[index]
    engine = engine_for(spec.engine)
    case = Case(scene.name, spec.engine, spec.integrator, math.nan, group.reference_label,
                declared_scheme(engine, spec.integrator, scene))
    rows: list[ResultRow] = []
    series: list[SeriesRecord] = []
    with warnings_into_rows(rows):
        rows += _joint_dynamics_rows(scene, engine, case, shared, group.repeats,
                                     f"{spec.engine}:{spec.integrator}" == group.reference_label, series)
    return CaseOutcome(rows, series)


def _joint_dynamics_rows(scene: JointDynamicsScene, engine: Engine, case: Case, shared: _JointDynamicsShared,
                         repeats: int, is_reference: bool, series: list[SeriesRecord]) -> list[ResultRow]:
    """Rows of one engine's joint-space dynamics at the scene's states: errors against the reference's values,
    the identities of its own, its derivatives, its times; the step sweep's series appended to ``series``."""
    kind = ""
    try:
        support = engine.supports_joint_dynamics(scene.chain, case.integrator)
        if not support.ok:
            return case.rows(JOINT_DYNAMICS_METRICS, NOT_AVAILABLE, support.reason)
        model = engine.build_joint_dynamics(scene.chain, case.integrator, scene.gravity_world)
        own, values = timed_values(model, shared.states, lambda fn: best_of(fn, repeats))
        problem = shape_problem(own, len(shared.states[0]), scene.chain.nv)
        if problem:
            status = DIVERGED if problem.startswith("non-finite") else FAILED
            return case.rows(JOINT_DYNAMICS_METRICS, status, problem, values)
        scale = (shared.scale if shared.scale is not None  # else its own: identities need no reference
                 else _force_scale(scene, engine, case.integrator, model, shared.states, own))
        values.update(identities(model, scene.chain, shared.states, own, scale, scene.gravity_world))
        derivatives, kind, found = derivative_values(model, shared.truth, shared.truth_problem, shared.states, own,
                                                     scale.floor, case)
        values.update(derivatives)
        series += found
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return case.rows(JOINT_DYNAMICS_METRICS, FAILED, error_text(err))
    return with_derivative_scheme(_judged_rows(scene, case, shared, model, own, values, scale, is_reference), kind)


def _judged_rows(scene: JointDynamicsScene, case: Case, shared: _JointDynamicsShared, model: JointDynamicsModel,
                 own: dict, values: dict[str, Measured], scale: ForceScale, is_reference: bool) -> list[ResultRow]:
    """The case's rows from its measured ``values``, with the errors against the reference's and model parity where
    there is a reference."""
    detail = ("this is the reference; " if is_reference else "") + model.detail
    if shared.reference is None:
        problem, status = shared.problem
        order = list(JOINT_DYNAMICS_METRICS)
        return sorted(case.partial_rows({m: u for m, u in JOINT_DYNAMICS_METRICS.items() if m not in REFERENCE_ERRORS},
                                        values, detail, status, problem)
                      + case.rows({m: JOINT_DYNAMICS_METRICS[m] for m in REFERENCE_ERRORS}, status, problem),
                      key=lambda row: order.index(row.metric))
    values.update(reference_errors(own, shared.reference, scale))
    try:
        values.update(_model_parity(model, shared, scene.chain))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return case.rows(JOINT_DYNAMICS_METRICS, FAILED, f"its compiled model (rigid_groups): {error_text(err)}")
    return case.rows(JOINT_DYNAMICS_METRICS, OK, detail, {m: values[m] for m in JOINT_DYNAMICS_METRICS})
