"""The derivative rows of a joint-dynamics case (issue #44): the complex-step truth at the scene's states, an engine's
partials against it (and, where it declares them differenced, against the truncation of its scheme at its steps),
and the finite-difference step sweep of the engine's own inverse dynamics (its best steps as rows, the V as series).
:mod:`comparisons.execute.chain_runner` calls it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from simparity.comparisons.common.error_text import error_text
from simparity.comparisons.measure.derivative_metrics import (
    DERIVATIVE_METRICS,
    SANE_STEP,
    derivative_errors,
    partial_floors,
    step_excess,
)
from simparity.comparisons.measure.finite_differences import (
    SWEEP_STATES,
    Retraction,
    additive,
    difference_partial,
    floating_retraction,
    step_sweep,
)
from simparity.comparisons.measure.rows import Case, Measured
from simparity.core.model.derivatives import PARTIALS, DynamicsDerivatives
from simparity.core.model.engine import JointDynamicsModel
from simparity.core.model.metric_catalogue import (
    CENTRAL_DIFFERENCE_BEST_STEP,
    CENTRAL_DIFFERENCE_FLOOR,
    DERIVATIVE_STEP_EXCESS,
    FORWARD_DIFFERENCE_BEST_STEP,
    FORWARD_DIFFERENCE_FLOOR,
    units,
)
from simparity.core.model.results import ResultRow, SeriesRecord
from simparity.core.model.scenes.joint_dynamics import JointDynamicsScene

SWEEP_METRICS = units(FORWARD_DIFFERENCE_BEST_STEP, FORWARD_DIFFERENCE_FLOOR, CENTRAL_DIFFERENCE_BEST_STEP,
                      CENTRAL_DIFFERENCE_FLOOR)
"""The step sweep's rows of a joint-dynamics case, in row order."""
ALL_DERIVATIVE_METRICS = DERIVATIVE_METRICS | SWEEP_METRICS
SWEEP_QUANTITIES = {False: "forward_difference_error", True: "central_difference_error"}
"""The series of the step sweep (x: the step [rad or m]), by centred."""


@dataclass(frozen=True)
class DerivativeTruth:
    """The complex-step truth at a scene's states: the partials, the reference's own tree (to difference its real
    RNEA as a declared scheme does) and its q̈ of the states' τ (B, n)."""

    partials: DynamicsDerivatives
    tree: Any
    qddot: np.ndarray


MJCF_TRUTH = ("no complex-step truth for an MJCF file: the truth runs on the tree Pinocchio's parser compiles, and "
              "Pinocchio's MJCF parser reads some files otherwise than MuJoCo, MJCF's own reader (docs/robots.md)")
"""Why a chain from an MJCF file has no derivative rows."""


def derivative_truth(scene: JointDynamicsScene, states: tuple[np.ndarray, ...]) -> tuple[DerivativeTruth | None, str]:
    """(the complex-step truth at the scene's states, "") or (None, why there is none)."""
    q, qd, _, tau = states
    if scene.chain.mjcf_path is not None:
        return None, MJCF_TRUTH
    try:
        from simparity.references.derivatives import complex_step  # Pinocchio's parser: only where a case runs

        tree = complex_step.tree_from_chain(scene.chain, scene.gravity_world)
        return DerivativeTruth(complex_step.derivatives(tree, q, qd, tau), tree,
                               complex_step.forward_dynamics(tree, q, qd, tau)), ""
    except Exception as err:  # noqa: BLE001 - every derivative row says why
        return None, f"no complex-step truth: {error_text(err)}"


def _not_measured(metrics: dict[str, str], why: str) -> dict[str, Measured]:
    return {m: Measured(math.nan, u, unmeasurable=why) for m, u in metrics.items()}


def _expected(truth: DerivativeTruth, own: DynamicsDerivatives, q: np.ndarray, qd: np.ndarray) -> dict[str, np.ndarray]:
    """The truth's own inverse dynamics differenced as ``own`` declares (scheme and steps): what its partials' errors
    are held to."""
    from simparity.references.derivatives import complex_step

    differences = own.differences
    assert differences is not None

    def inverse_dynamics(*state: np.ndarray) -> np.ndarray:
        return complex_step.inverse_dynamics(truth.tree, *state)

    return {name: difference_partial(inverse_dynamics, q, qd, truth.qddot, wrt, np.minimum(step, SANE_STEP),
                                     differences.centred, _retraction(q, qd))
            for name, wrt, step in (("dtau_dq", "q", differences.step_q), ("dtau_dqdot", "qdot", differences.step_qdot))}


def _retraction(q: np.ndarray, qdot: np.ndarray) -> Retraction:
    """How a difference moves q: the floating base's chart where q has a quaternion (nq = nv + 1), else q + δ."""
    return floating_retraction if q.shape[1] == qdot.shape[1] + 1 else additive


def derivative_values(model: JointDynamicsModel, truth: DerivativeTruth | None, truth_problem: str,
                      states: tuple[np.ndarray, ...], own_values: dict[str, np.ndarray], floor: float,
                      case: Case) -> tuple[dict[str, Measured], str, list[SeriesRecord]]:
    """(the derivative and step-sweep values of ``model`` at the ``states`` against the ``truth`` (n/a with why where
    there is none, or the engine reports no derivatives), the scheme kind its partials declare ("" when it reports
    none), the sweep's series). ``own_values``: the engine's values at the states (its M "M", its q̈ "qdd" of their τ: the
    truth's partials are taken at that q̈, so that the engine's forward solve, ~ε κ(M) off, is judged by
    forward_dynamics_error_max and not again here); ``floor``: the chain's force floor [N m]."""
    if truth is None:
        return _not_measured(ALL_DERIVATIVE_METRICS, truth_problem), "", []
    q, qd, _, tau = states
    sweep, series = _sweep(model, truth, states, floor, case)
    try:
        partials = model.derivatives(q, qd, tau)
    except NotImplementedError as err:
        return _not_measured(DERIVATIVE_METRICS, str(err)) | sweep, "", series
    expected_shape = truth.partials.dtau_dq.shape
    if partials.dtau_dq.shape != expected_shape:
        raise ValueError(f"derivatives: dtau_dq has shape {partials.dtau_dq.shape}, expected {expected_shape} (B "
                         "states x n x n, column j by joint j)")
    bad = [name for name in PARTIALS
           if getattr(partials, name) is not None and not np.all(np.isfinite(getattr(partials, name)))]
    if bad:
        raise ValueError(f"non-finite {', '.join(bad)}")
    from simparity.references.derivatives import complex_step

    at_own = complex_step.derivatives(truth.tree, q, qd, tau, own_values["qdd"])
    values = derivative_errors(partials, at_own, own_values["M"], partial_floors(floor, qd))
    expected = _expected(truth, partials, q, qd) if partials.differences is not None else {}
    tau_scale = np.maximum(np.max(np.abs(tau), axis=-1), floor)
    values[DERIVATIVE_STEP_EXCESS] = step_excess(partials, at_own, expected, tau_scale)
    return values | sweep, partials.kind, series


def _sweep(model: JointDynamicsModel, truth: DerivativeTruth, states: tuple[np.ndarray, ...], floor: float,
           case: Case) -> tuple[dict[str, Measured], list[SeriesRecord]]:
    """The step sweep of ``model``'s own inverse dynamics at the first :data:`SWEEP_STATES` states: its best step
    and smallest error per scheme as values, the errors against the step as series."""
    q, qd, _, _ = (x[:SWEEP_STATES] for x in states)
    found = step_sweep(model.inverse_dynamics, q, qd, truth.qddot[:SWEEP_STATES],
                       truth.partials.dtau_dq[:SWEEP_STATES], floor, retract=_retraction(q, qd))
    values: dict[str, Measured] = {}
    series = []
    for centred, (step_metric, error_metric) in ((False, (FORWARD_DIFFERENCE_BEST_STEP, FORWARD_DIFFERENCE_FLOOR)),
                                                 (True, (CENTRAL_DIFFERENCE_BEST_STEP, CENTRAL_DIFFERENCE_FLOOR))):
        step, error = found.best(centred)
        why = "" if math.isfinite(step) else "the engine's inverse dynamics was not finite at any step"
        values[step_metric] = Measured(step, "1", note=f"dtau/dq error {error:.3g} there", unmeasurable=why)
        values[error_metric] = Measured(error, "1", note=f"at step {step:.3g}", unmeasurable=why)
        errors = found.central if centred else found.forward
        series.append(SeriesRecord(case.scene, case.engine, case.integrator, case.dt, SWEEP_QUANTITIES[centred], "1",
                                   found.steps, errors))
    return values, series


def with_derivative_scheme(rows: list[ResultRow], kind: str,
                           metrics: dict[str, str] = DERIVATIVE_METRICS) -> list[ResultRow]:
    """``rows`` with the scheme of the rows of ``metrics`` (the derivative rows) the case's joined with the kind the
    derivatives declare ("recursive+forward_differences"): the gate keys their bounds by it. Unchanged when the kind
    is unknown."""
    if not kind:
        return rows
    return [replace(r, scheme=f"{r.scheme}+{kind}" if r.scheme else kind) if r.metric in metrics else r
            for r in rows]
