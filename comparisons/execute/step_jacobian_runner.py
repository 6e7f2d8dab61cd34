"""The step-Jacobian rows of a joint-motion case (issue #44): the engine's ∂x'/∂(x, τ) of one step of its scheme at
the scene's initial states under its constant joint forces, against the complex-step truth carried through the
scheme's formula (:mod:`references.derivatives.step_truth`, imported where a case runs) and, where the engine
declares its Jacobian differenced, against the truncation of that scheme at its steps.
:mod:`comparisons.execute.motion_runner` calls it.
"""

from __future__ import annotations

import math

import numpy as np

from simparity.comparisons.common.error_text import error_text
from simparity.comparisons.measure.derivative_metrics import SANE_STEP
from simparity.comparisons.measure.finite_differences import difference_map
from simparity.comparisons.measure.joint_motion_metrics import reach
from simparity.comparisons.measure.rows import Measured
from simparity.comparisons.measure.step_jacobian_metrics import (
    STEP_JACOBIAN_METRICS,
    step_jacobian_error,
    step_jacobian_excess,
)
from simparity.core.model.derivatives import StepJacobian
from simparity.core.model.engine import JointSimulation
from simparity.core.model.metric_catalogue import STEP_JACOBIAN_ERROR_MAX, STEP_JACOBIAN_STEP_EXCESS
from simparity.core.model.scenes.joint_motion import JointMotionScene


def _not_measured(why: str) -> dict[str, Measured]:
    return {m: Measured(math.nan, u, unmeasurable=why) for m, u in STEP_JACOBIAN_METRICS.items()}


MOVING_STATES = 3
"""Seeded states beside the scene's initial ones: a chain that starts at rest would leave every velocity term of an
Euler step's Jacobian unjudged (found by a held-out review: a Jacobian without its Coriolis terms read 0 error)."""
SEED = 44


def jacobian_states(scene: JointMotionScene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, q̇, τ), each (B + :data:`MOVING_STATES`, n): the scene's initial states under its constant joint forces,
    then seeded ones in the chain's own scales: q within 0.5 rad (or half the reach for a slide) of the first initial
    state, q̇ up to the larger of its initial speed and sqrt(|g| / reach) (the chain's swing rate), τ the constant
    forces plus up to the chain's weight times its reach."""
    q0, qdot0 = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (scene.q0, scene.qdot0))
    n = q0.shape[1]
    length = reach(scene.chain)
    gravity = 0.0 if scene.gravity_world is None else float(np.linalg.norm(scene.gravity_world))
    rate = max(float(np.max(np.abs(qdot0))), np.sqrt(gravity / length), np.finfo(float).tiny)
    mass = sum(j.link.mass for j in scene.chain.joints if j.link is not None)
    force = max(float(np.max(np.abs(scene.torque), initial=0.0)), mass * gravity * length, np.finfo(float).tiny)
    offset = np.array([0.5 if j.type == "revolute" else 0.5 * length for j in scene.chain.joints])
    rng = np.random.default_rng(SEED)
    unit = rng.uniform(-1.0, 1.0, (3, MOVING_STATES, n))
    torque = np.broadcast_to(np.asarray(scene.torque, dtype=float), (len(q0) + MOVING_STATES, n))
    return (np.concatenate([q0, q0[:1] + offset * unit[0]]), np.concatenate([qdot0, rate * unit[1]]),
            torque + np.concatenate([np.zeros_like(q0), force * unit[2]]))


def step_jacobian_values(sim: JointSimulation, scene: JointMotionScene, scheme: str,
                         dt: float) -> tuple[dict[str, Measured], str]:
    """(the step-Jacobian values of ``sim`` (n/a with why where the engine reports none or the scheme has no truth),
    the kind its Jacobian declares ("" when none)). ``scheme``: the case's declared scheme kind (its last part: a
    held load's prefix says how a timed torque meets the steps, which the Jacobian leaves out)."""
    kind = scheme.split("+")[-1]
    if scene.chain.floating_base:
        return _not_measured("the step's complex-step truth is carried on a fixed base only (a floating base's "
                             "quaternion step is not differentiated yet)"), ""
    q, qdot, tau = jacobian_states(scene)
    try:
        from simparity.references.derivatives import complex_step, step_truth  # Pinocchio's parser: where a case runs

        if kind not in step_truth.SCHEMES:
            return _not_measured(step_truth.UNSUPPORTED.get(kind, f"no truth of the step of the scheme "
                                                                  f"{scheme or '(undeclared)'!r} (truths: "
                                                                  f"{', '.join(step_truth.SCHEMES)})")), ""
        tree = complex_step.tree_from_chain(scene.chain, scene.gravity_world)
        truth = step_truth.step_jacobian(tree, kind, dt, q, qdot, tau)
        mass, _ = complex_step.mass_and_bias(tree, q, qdot)
    except Exception as err:  # noqa: BLE001 - every step-Jacobian row says why
        return _not_measured(f"no complex-step truth of the step: {error_text(err)}"), ""
    try:
        own = sim.step_jacobian(q, qdot, tau)
    except NotImplementedError as err:
        return _not_measured(str(err)), ""
    expected_shape = truth.by_state.shape
    if own.by_state.shape != expected_shape:
        raise ValueError(f"step_jacobian: by_state has shape {own.by_state.shape}, expected {expected_shape}")
    if not (np.all(np.isfinite(own.by_state)) and np.all(np.isfinite(own.by_force))):
        raise ValueError("step_jacobian: non-finite entries")
    values = {STEP_JACOBIAN_ERROR_MAX: step_jacobian_error(own, truth, mass)}
    if own.differences is None:
        values[STEP_JACOBIAN_STEP_EXCESS] = step_jacobian_excess(own, truth, truth, np.ones(len(q)))
        return values, own.kind
    n = q.shape[1]

    def stepped(x: np.ndarray) -> np.ndarray:
        return step_truth.step(tree, kind, dt, x[:, :n], x[:, n:2 * n], x[:, 2 * n:]).real

    state = np.concatenate([q, qdot], axis=1)
    by_state = difference_map(lambda x, owner: stepped(np.concatenate([x, tau[owner]], axis=1)), state,
                              np.minimum(own.differences.step_q, SANE_STEP), own.differences.centred)
    by_force = difference_map(lambda x, owner: stepped(np.concatenate([state[owner], x], axis=1)), tau,
                              np.minimum(own.differences.step_qdot, SANE_STEP), own.differences.centred)
    after = stepped(np.concatenate([state, tau], axis=1))
    scale = (np.max(np.abs(after), axis=1)
             + np.linalg.cond(mass, 1) * np.max(np.abs(after[:, n:] - qdot), axis=1))
    values[STEP_JACOBIAN_STEP_EXCESS] = step_jacobian_excess(own, truth, StepJacobian(by_state, by_force), scale)
    return values, own.kind
