"""Runs a joint-motion group (:class:`JointMotionScene` at one time step): the reference's motion once, then each
engine x integrator's, measured by :mod:`comparisons.measure.joint_motion_metrics`.

Two kinds of accuracy:

- against the reference (``segments = 0``): every engine's trajectory against the reference's at the same
  samples, over the reference's horizon (where its runs at two tolerances agree, :func:`reference_horizon`);
- self-consistency (``segments = k``, Erez, Tassa and Todorov 2015): the reference's motion gives k start states
  one segment apart; each engine steps all k segments at the group's dt and at dt / :data:`REFINEMENT`, and the
  error is the difference at the segments' ends, averaged over them, so that a chaotic chain's divergence (which
  no scheme can avoid) is not counted as its error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from simparity.comparisons.execute.case_cost import case_cost, theory
from simparity.comparisons.common.integrators import NO_INTEGRATOR
from simparity.comparisons.execute.cases import CaseGroup, CaseOutcome, EngineFor
from simparity.comparisons.execute.derivative_runner import with_derivative_scheme
from simparity.comparisons.execute.step_jacobian_runner import step_jacobian_values
from simparity.comparisons.execute.timing import best_of
from simparity.comparisons.measure.joint_motion_metrics import (
    REFERENCE_ERRORS, Horizon, OwnReading, configuration_gap, divergence, energy_metrics, momentum_metrics,
    motion_metrics, parting_times, reach, read_own, reference_errors, reference_horizon, state_scales, velocity_gap,
)
from simparity.comparisons.measure.chain_contact_metrics import contact_metrics
from simparity.comparisons.measure.held_forcing import forcing_scheme
from simparity.comparisons.measure.step_jacobian_metrics import STEP_JACOBIAN_METRICS
from simparity.comparisons.measure.rows import Case, Measured, declared_scheme, warnings_into_rows
from simparity.comparisons.common.error_text import error_text
from simparity.core.model.engine import Engine, JointSimulation, Support
from simparity.core.model.errors import ContactError, DivergedError
from simparity.core.model.metric_catalogue import (
    END_EFFECTOR_ERROR_MAX, JOINT_ANGLE_ERROR_MAX, JOINT_VELOCITY_ERROR_MAX, SEGMENT_REFERENCE_ERROR_MAX,
    SELF_PARTING_TIME, TIME_PER_STEP,
)
from simparity.core.model.results import DIVERGED, FAILED, NO_REFERENCE, NOT_AVAILABLE, OK, SATURATED, ResultRow
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.core.model.trajectory import JointTrajectory

COARSE_SUFFIX = "_coarse"
"""A reference integrator ``x`` whose engine also offers ``x_coarse`` (the same solve at a looser tolerance) has a
horizon: where the two part, the reference's own error has grown past use (:func:`reference_horizon`)."""

NO_CONTACT_REFERENCE = ("a scene with soft contact is run against no reference: each engine's contact is its own (core's "
                        "penalty springs, MuJoCo's soft constraints, Pinocchio's and PyBullet's rigid contacts), so each "
                        "is held to truths that need no engine (the contact metrics)")


def against_reference(scene: JointMotionScene) -> bool:
    """Whether the scene's engines are compared with its reference's run: without contact, or with a rigid contact
    (one law, Newton's restitution, which a closed form or a rigid engine follows); a soft contact's penetration is
    each engine's own."""
    return scene.contact is None or scene.contact.rigid
REFINEMENT = 16
"""A self-consistency case compares dt with dt / 16: a first-order scheme's error at dt / 16 is 1/16 of its error
at dt, so the difference measures the coarse run's error within 7 %; a fourth-order one's within 1e-5."""


@dataclass(frozen=True)
class MotionShared:
    """What the cases of a joint-motion group share.

    Attributes
    ----------
    trajectory : JointTrajectory or None
        The reference's motion at the group's dt (against-the-reference scenes), None otherwise or when it has none.
    end_effector : ndarray or None
        (S, B, 3) [m] the reference's end effector at the samples :func:`read_own` reads.
    horizon : Horizon or None
    starts, ends : tuple of ndarray or None
        (q, qdot), each (k, n): the segments' start and end states on the reference's motion (a self-consistency
        scene).
    problem : tuple of str
        (why there is no reference, the status that gives).
    """

    trajectory: JointTrajectory | None
    end_effector: np.ndarray | None
    horizon: Horizon | None
    starts: tuple[np.ndarray, np.ndarray] | None
    problem: tuple[str, str]
    ends: tuple[np.ndarray, np.ndarray] | None = None


def _reference_run(scene: JointMotionScene, engine: Engine, integrator: str, dt: float,
                   n_steps: int) -> tuple[JointTrajectory, JointSimulation]:
    sim = engine.build_joint_motion(scene, integrator, dt)
    with np.errstate(all="ignore"):
        traj = sim.run(n_steps)
    problem = sampling_problem(scene, traj, n_steps, dt)
    if problem:
        raise ValueError(f"its trajectory does not sample the scene: {problem}")
    if not traj.is_finite():
        raise DivergedError("non-finite joint state")
    return traj, sim


def prepare_motion(group: CaseGroup, engine_for: EngineFor, reference_failure: str) -> MotionShared:
    """The reference's motion at the group's dt (or the segments' start states), computed once."""
    scene, label = group.joint_motion_scene, group.reference_label
    integrator = label.split(":", 1)[1]
    if reference_failure:
        return MotionShared(None, None, None, None, (f"reference {label} failed: {reference_failure}", FAILED))
    if not against_reference(scene):
        return MotionShared(None, None, None, None, (NO_CONTACT_REFERENCE, NOT_AVAILABLE))
    reference = engine_for(scene.reference)
    try:
        support = (reference.supports_joint_motion(scene, integrator) if integrator != NO_INTEGRATOR else
                   Support.no(f"{reference.name} steps no chain through time"))
        if not support.ok:
            return MotionShared(None, None, None, None,
                                (f"reference {label} cannot do this scene: {support.reason}", NOT_AVAILABLE))
        if scene.segments:
            length = scene.duration / scene.segments
            traj, _ = _reference_run(scene, reference, integrator, length, scene.segments)
            starts = (np.ascontiguousarray(traj.q[:-1, 0]), np.ascontiguousarray(traj.qdot[:-1, 0]))
            ends = (np.ascontiguousarray(traj.q[1:, 0]), np.ascontiguousarray(traj.qdot[1:, 0]))
            return MotionShared(None, None, None, starts, ("", NOT_AVAILABLE), ends)
        n = scene.n_steps(group.dt)
        traj, sim = _reference_run(scene, reference, integrator, group.dt, n)
        coarse = None
        if integrator + COARSE_SUFFIX in reference.joint_motion_integrators():
            coarse, _ = _reference_run(scene, reference, integrator + COARSE_SUFFIX, group.dt, n)
        own = read_own(sim, traj)
        return MotionShared(traj, own.end_effector, reference_horizon(scene, traj, coarse), None, ("", NOT_AVAILABLE))
    except DivergedError as err:
        return MotionShared(None, None, None, None, (f"reference {label} diverged ({err})", NOT_AVAILABLE))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return MotionShared(None, None, None, None, (f"reference {label} failed: {error_text(err)}", FAILED))


def sampling_problem(scene: JointMotionScene, traj: object, n: int, dt: float) -> str:
    """What is wrong with ``traj`` as the samples of ``n`` steps of ``dt`` of ``scene`` ("" when nothing)."""
    if not isinstance(traj, JointTrajectory):
        return (f"run() returned a value of type {type(traj).__name__} "
                "(allowed: a simparity.core.trajectory.JointTrajectory)")
    expected = (n + 1, scene.copies, scene.chain.nq)
    if traj.q.shape != expected:
        return f"its joint values have shape {traj.q.shape} (expected {expected}: samples, copies, joints)"
    if traj.qdot.shape != expected[:2] + (scene.chain.nv,):
        return (f"its joint velocities have shape {traj.qdot.shape} (expected {expected[:2] + (scene.chain.nv,)}: "
                "samples, copies, velocity components)")
    with np.errstate(all="ignore"):
        off = np.abs(np.asarray(traj.times) - np.arange(n + 1) * dt) / dt
    bad = np.flatnonzero(~(off <= 1e-3))
    if bad.size:
        k = int(bad[0])
        return f"sample {k} is at t = {float(traj.times[k]):.9g} s (expected {k * dt:.9g} s)"
    return ""


def motion_case(group: CaseGroup, shared: MotionShared, index: int, engine_for: EngineFor) -> CaseOutcome:
    """The outcome of case ``index`` of a joint-motion group."""
    scene, spec = group.joint_motion_scene, group.cases[index]
    engine = engine_for(spec.engine)
    case = Case(scene.name, spec.engine, spec.integrator, group.dt,
                group.reference_label if against_reference(scene) else NO_REFERENCE,
                forcing_scheme(declared_scheme(engine, spec.integrator, scene), scene))
    rows: list[ResultRow] = []
    with warnings_into_rows(rows):
        if spec.integrator == NO_INTEGRATOR:
            outcome = CaseOutcome(_no_integrator_rows(scene, engine, case))
        else:
            outcome = _motion_case(scene, engine, case, shared, group.repeats,
                                   f"{spec.engine}:{spec.integrator}" == group.reference_label)
        rows += outcome.rows
    outcome.rows = rows
    outcome.theoretical_order = theory(engine, spec.integrator)
    return outcome


def _no_integrator_rows(scene: JointMotionScene, engine: Engine, case: Case) -> list[ResultRow]:
    metrics = motion_metrics(scene)
    try:
        offered = tuple(engine.joint_motion_integrators())
    except Exception as err:  # noqa: BLE001 - a user's engine failed to describe itself
        return case.rows(metrics, FAILED, error_text(err))
    reason = (f"the scene runs only {', '.join(scene.integrators)}; {engine.name} offers {', '.join(offered)}"
              if offered and scene.integrators else
              f"{engine.name} offers {', '.join(offered)} but none was planned (its description when the run was "
              "planned listed none: a harness fault)" if offered else f"{engine.name} steps no chain through time")
    return case.rows(metrics, NOT_AVAILABLE, reason)


def _motion_case(scene: JointMotionScene, engine: Engine, case: Case, shared: MotionShared, repeats: int,
                 is_reference: bool) -> CaseOutcome:
    metrics = motion_metrics(scene)
    try:
        support = engine.supports_joint_motion(scene, case.integrator)
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return CaseOutcome(case.rows(metrics, FAILED, error_text(err)))
    if not support.ok:
        return CaseOutcome(case.rows(metrics, NOT_AVAILABLE, support.reason))
    run_scene = scene
    if scene.segments and shared.starts is not None:
        run_scene = scene.starting_from(*shared.starts, scene.duration / scene.segments)
    n = run_scene.n_steps(case.dt)
    try:
        sim = engine.build_joint_motion(run_scene, case.integrator, case.dt)
        with np.errstate(all="ignore"):  # a diverging run overflows; it is reported as diverged
            seconds, traj = best_of(lambda: sim.run(n), repeats)
            timed = {TIME_PER_STEP: Measured(seconds / (n * run_scene.copies), "s")}
            timed |= case_cost(engine, sim, case, n, repeats)
    except DivergedError as err:
        return CaseOutcome(case.rows(metrics, DIVERGED, str(err)))
    except ContactError as err:  # a contact its method does not resolve, found only as it steps: n/a, saying why
        return CaseOutcome(case.rows(metrics, NOT_AVAILABLE, f"{engine.name} cannot step this contact: {err}"))
    except Exception as err:  # noqa: BLE001 - reported in the rows
        return CaseOutcome(case.rows(metrics, FAILED, error_text(err)))
    problem = sampling_problem(run_scene, traj, n, case.dt)
    if problem:
        return CaseOutcome(case.rows(metrics, FAILED, f"its trajectory does not sample the scene: {problem}",
                                     timed))
    try:
        jacobian, kind = step_jacobian_values(sim, run_scene, case.scheme, case.dt)
        outcome = _measured(run_scene, engine, sim, case, traj, timed | jacobian, shared, is_reference)
        outcome.rows = with_derivative_scheme(outcome.rows, kind, STEP_JACOBIAN_METRICS)
        return outcome
    except Exception as err:  # noqa: BLE001 - a user's engine returned what cannot be measured
        return CaseOutcome(case.rows(metrics, FAILED,
                                     f"its motion cannot be measured: {error_text(err)}", timed))


def _measured(scene: JointMotionScene, engine: Engine, sim: JointSimulation, case: Case, traj: JointTrajectory,
              timed: dict[str, Measured], shared: MotionShared, is_reference: bool) -> CaseOutcome:
    metrics, values = motion_metrics(scene), dict(timed)
    with np.errstate(all="ignore"):
        own = read_own(sim, traj) if traj.is_finite() else None
        blown = divergence(scene, traj, own)
    if blown or own is None:
        return CaseOutcome(case.rows(metrics, DIVERGED, f"{blown}; {sim.detail}", values))
    if scene.contact is None:
        values.update(energy_metrics(scene, traj, own))
    if scene.chain.floating_base:
        values.update(momentum_metrics(scene, sim, traj, own))
    if scene.contact is not None:
        values.update(contact_metrics(scene, sim, traj, own))
    detail = ("this is the reference; " if is_reference else "") + sim.detail
    if scene.segments and shared.starts is not None:
        errors = _consistency_errors(scene, engine, case, traj, own, shared.ends)
        ratios: dict[str, float] = {}
        floors: dict[str, float] = {}
    elif shared.trajectory is not None and shared.end_effector is not None and shared.horizon is not None:
        errors, ratios, floors = reference_errors(scene, traj, own, shared.trajectory, shared.end_effector,
                                                  shared.horizon)
    else:
        problem, status = shared.problem
        rows = case.partial_rows({m: u for m, u in metrics.items() if m not in REFERENCE_ERRORS},
                                 values, detail, status, problem)
        rows += case.rows({m: metrics[m] for m in REFERENCE_ERRORS}, status, problem)
        order = list(metrics)
        return CaseOutcome(sorted(rows, key=lambda row: order.index(row.metric)))
    if errors[JOINT_ANGLE_ERROR_MAX].flag == SATURATED:  # on another orbit: did the energy carry it there?
        pumped = divergence(scene, traj, own, saturated=True)
        if pumped:
            return CaseOutcome(case.rows(metrics, DIVERGED, f"{pumped}; {sim.detail}", values))
    values.update(errors)
    if SELF_PARTING_TIME in metrics:
        values.update(_predictability(scene, engine, case, traj, shared.trajectory))
    return CaseOutcome(case.rows(metrics, OK, detail, values),
                       errors={m: v.value for m, v in errors.items()}, floors=floors, saturation=ratios)


def _predictability(scene: JointMotionScene, engine: Engine, case: Case, traj: JointTrajectory,
                    ref: JointTrajectory | None) -> dict[str, Measured]:
    """When the engine's run parts from its own run from the perturbed start, and from the reference's."""
    perturbed_scene = scene.starting_from(scene.q0 + scene.perturbation, scene.qdot0, scene.duration)
    n = scene.n_steps(case.dt)
    with np.errstate(all="ignore"):
        perturbed = engine.build_joint_motion(perturbed_scene, case.integrator, case.dt).run(n)
    problem = sampling_problem(perturbed_scene, perturbed, n, case.dt)
    return parting_times(scene, traj, None if problem else perturbed, ref)


def _consistency_errors(scene: JointMotionScene, engine: Engine, case: Case, traj: JointTrajectory,
                        own: OwnReading, ends: tuple[np.ndarray, np.ndarray] | None) -> dict[str, Measured]:
    """Errors of the segments' ends at dt against the same engine and integrator at dt / :data:`REFINEMENT` from
    the same starts, the largest over segments (unitless as against a reference); and the run at dt / REFINEMENT
    against the reference's segment ends (``ends``): the engine's model against the reference's, which its
    consistency with itself cannot see (a gravity off by 0.1 % is consistent)."""
    fine_dt = case.dt / REFINEMENT
    fine_sim = engine.build_joint_motion(scene, case.integrator, fine_dt)
    n_fine = scene.n_steps(fine_dt)
    with np.errstate(all="ignore"):
        fine = fine_sim.run(n_fine)
    problem = sampling_problem(scene, fine, n_fine, fine_dt)
    if problem or not fine.is_finite():
        why = problem or "non-finite joint state"
        return {m: Measured(math.nan, "1", unmeasurable=f"its run at dt / {REFINEMENT} failed: {why}")
                for m in REFERENCE_ERRORS + (SEGMENT_REFERENCE_ERROR_MAX,)}
    scales, rate_scales = state_scales(scene.chain, fine)
    speed = max(float((velocity_gap(scene.chain, fine.qdot, 0.0) / rate_scales).max()), 1.0 / scene.duration)
    end_effector = np.asarray(fine_sim.end_effector_world(np.asarray(fine.q[-1])), dtype=float)
    note = (f"self-consistency: {scene.copies} segments of {scene.duration:.3g} s from the reference's motion, "
            f"each end against the same integrator at dt / {REFINEMENT}, the largest over segments")
    values = {
        JOINT_ANGLE_ERROR_MAX: float((configuration_gap(scene.chain, traj.q[-1], fine.q[-1]) / scales).max()),
        JOINT_VELOCITY_ERROR_MAX: float((velocity_gap(scene.chain, traj.qdot[-1], fine.qdot[-1]) / rate_scales).max())
                                  / speed,
        END_EFFECTOR_ERROR_MAX: float(np.linalg.norm(own.end_effector[-1] - end_effector, axis=-1).max())
                                / reach(scene.chain),
    }
    out = {m: Measured(v, "1", note=note) for m, v in values.items()}
    out[SEGMENT_REFERENCE_ERROR_MAX] = (
        Measured(float((configuration_gap(scene.chain, fine.q[-1], ends[0]) / scales).max()), "1", note=(
            f"each segment's end at dt / {REFINEMENT} against the reference's, the largest over segments"))
        if ends is not None else Measured(math.nan, "1", unmeasurable="the reference gave no segment ends"))
    return out
