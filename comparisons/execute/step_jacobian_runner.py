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
from simparity.comparisons.measure.finite_differences import difference_map
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


def step_jacobian_values(sim: JointSimulation, scene: JointMotionScene, scheme: str,
                         dt: float) -> tuple[dict[str, Measured], str]:
    """(the step-Jacobian values of ``sim`` (n/a with why where the engine reports none or the scheme has no truth),
    the kind its Jacobian declares ("" when none)). ``scheme``: the case's declared scheme kind (its last part: a
    held load's prefix says how a timed torque meets the steps, which the Jacobian leaves out)."""
    kind = scheme.split("+")[-1]
    q, qdot = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (scene.q0, scene.qdot0))
    tau = np.broadcast_to(np.asarray(scene.torque, dtype=float), q.shape).copy()
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
                              own.differences.step_q, own.differences.centred)
    by_force = difference_map(lambda x, owner: stepped(np.concatenate([state[owner], x], axis=1)), tau,
                              own.differences.step_qdot, own.differences.centred)
    after = stepped(np.concatenate([state, tau], axis=1))
    scale = (np.max(np.abs(after), axis=1)
             + np.linalg.cond(mass, 1) * np.max(np.abs(after[:, n:] - qdot), axis=1))
    values[STEP_JACOBIAN_STEP_EXCESS] = step_jacobian_excess(own, truth, StepJacobian(by_state, by_force), scale)
    return values, own.kind
