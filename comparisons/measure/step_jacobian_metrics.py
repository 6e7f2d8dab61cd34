"""The Jacobian of a time step judged (issue #44): an engine's ∂x'/∂(x, τ) of one step of its scheme against the
complex-step truth carried through that scheme's formula (:mod:`references.derivatives.step_truth`).

A judge: it imports core's data model only.

- ``step_jacobian_error_max``: per state, the larger of the two blocks' max |D - T| over the block's max |T|
  (∂x'/∂x's is the identity's at least: its representation rounds to ε of that, whatever the step's own change; a
  differenced Jacobian's error is held to its scheme by the excess below, with any declared step above
  ``SANE_STEP`` judged at it), divided by κ₁(M) at the state (M the truth's): a step's Jacobian carries M⁻¹ (∂x'/∂τ = h M⁻¹ for an Euler step),
  whose every computation, the truth's own solve included, rounds to ~ε κ(M) (measured 3e-11 relative on a 20-link
  chain with κ 6.6e5, 4.5e-17 over κ), so its error is judged against its conditioning as an inverse is
  (``derivative_identity_residual``); a wrong term is O(1) relative, read as 1/κ (1e-6 at κ = 1e6);
- ``step_jacobian_step_excess``: a Jacobian an engine declares differenced (MuJoCo's ``mjd_transitionFD``) against
  the error of the truth's own step differenced by the same scheme at the same steps, or :data:`STEP_ROUNDING` ε
  (|x'| + κ₁(M) |q̇' - q̇|) / h where that is larger (a step rounds as its solve does: the velocity change through M⁻¹
  to ~ε κ of itself; the truth's own solve may round less than an engine's in another frame: chain-20 turned, MuJoCo
  7e-6 relative at κ 1e6, 825 times the truth's own differences): ~1 for a scheme that is what it claims.
"""

from __future__ import annotations

import numpy as np

from simparity.comparisons.measure.derivative_metrics import worst_excess
from simparity.comparisons.measure.rows import Measured
from simparity.core.model.derivatives import StepJacobian
from simparity.core.model.metric_catalogue import STEP_JACOBIAN_ERROR_MAX, STEP_JACOBIAN_STEP_EXCESS, units

STEP_ROUNDING = 1.0
"""[ε] A step's rounding, in units of ε (|x'| + κ₁(M) |q̇' - q̇|) / h: a few operations on x and one solve, whose
worst case, ε κ of its result, is the margin itself (MuJoCo's own differences of a well-conditioned arm round to
~1/200 of it, of chain-20 turned to ~1e-4; a forward difference claimed centred reads ~100 on the driven arm)."""
STEP_JACOBIAN_METRICS = units(STEP_JACOBIAN_ERROR_MAX, STEP_JACOBIAN_STEP_EXCESS)
"""The step-Jacobian rows of a joint-motion case, in row order."""


def _block_errors(own: StepJacobian, truth: StepJacobian) -> list[tuple[str, np.ndarray]]:
    """(block, per-state |D - T| max over the block's max |T| (B,)) of each block; a block zero in truth is judged
    against 1."""
    out = []
    for name in ("by_state", "by_force"):
        scale = np.max(np.abs(getattr(truth, name)), axis=(-1, -2))
        error = np.max(np.abs(getattr(own, name) - getattr(truth, name)), axis=(-1, -2))
        out.append((name, error / np.where(scale > 0, scale, 1.0)))
    return out


def step_jacobian_error(own: StepJacobian, truth: StepJacobian, mass: np.ndarray) -> Measured:
    """``step_jacobian_error_max`` of ``own`` against ``truth`` (the same B states); ``mass`` (B, n, n): the truth's
    M at the states."""
    conditioning = np.linalg.cond(mass, 1)
    worst = max(((name, errors / conditioning, errors) for name, errors in _block_errors(own, truth)),
                key=lambda item: float(np.max(item[1])))
    k = int(np.argmax(worst[1]))
    return Measured(float(worst[1][k]), "1", note=f"largest in {worst[0]}: relative {worst[2][k]:.3g} at kappa_1(M) "
                                                  f"{conditioning[k]:.3g} (state {k})")


def step_jacobian_excess(own: StepJacobian, truth: StepJacobian, expected: StepJacobian,
                         scale: np.ndarray) -> Measured:
    """``step_jacobian_step_excess``: ``own``'s error over ``expected``'s (the truth's step differenced as ``own``
    declares) or the rounding allowance :data:`STEP_ROUNDING` ε ``scale`` / h (``scale`` (B,): each state's
    |x'| + κ₁(M) |q̇' - q̇|, largest entries); n/a for an analytic Jacobian."""
    differences = own.differences
    if differences is None:
        return Measured(np.nan, "1", unmeasurable="an analytic step Jacobian: no step whose truncation to hold it to")
    rounding = STEP_ROUNDING * np.finfo(float).eps * scale
    value, name, k = worst_excess([(name, getattr(own, name), getattr(truth, name), getattr(expected, name),
                                    rounding / step) for name, step in (("by_state", differences.step_q),
                                                                        ("by_force", differences.step_qdot))])
    return Measured(value, "1", note=f"largest in {name} at state {k}, {differences.kind} at steps "
                                     f"{differences.step_q[k]:.3g} (x), {differences.step_qdot[k]:.3g} (tau)")
