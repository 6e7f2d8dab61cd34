"""Derivatives of the dynamics judged (issue #44): an engine's ∂τ/∂q, ∂τ/∂q̇ and ∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ against the
complex-step truth (:mod:`references.derivatives.complex_step`), and ∂q̈/∂τ M = I with its own M.

A judge: it imports core's data model only. Each error is relative to the truth's own largest entry of the partial,
floored as the joint forces are (:mod:`comparisons.measure.joint_force_scale`): a partial's terms are forces per unit
of the variable, so its floor is the chain's force floor per radian (or metre) for q and per the sample's largest
|q̇| for q̇. A partial that is tiny but not zero (a one-joint arm whose axis is 3e-6 rad off the vertical: ∂τ/∂q ~1e-6
N m/rad beside a weight of 0.04 N m) is then judged against the forces its rounding comes from, not against itself
(found by a held-out review: a correct engine read 1.7e-11 there). The worst partial is reported:

- RNEA: max |D - T| over the floored max |T|, for D in ∂τ/∂q and ∂τ/∂q̇ (a partial with no scale at all, such as
  ∂τ/∂q̇ of a chain at rest without damping and without gravity, is skipped: nothing to be relative to);
- ABA, in torque space as forward dynamics is judged (a solve amplifies rounding by M's condition number, the force
  does not): max |M (D - T)| over the floored max |M T|, M the truth's (M ∂q̈/∂τ = I: scale 1);
- the identity: max over states of |∂q̈/∂τ M - I| over κ₁(M), M the engine's own: an inverse rounds to ~ε κ(M)
  (~1e9 with a 1 g link at the tip), so the residual is judged against its conditioning;
- a difference's step excess: partials an engine declares differenced (:class:`FiniteDifferences`: forward or
  centred, its steps) are held to the error the truth's own RNEA gives under the same scheme at the same steps (its
  truncation; rounding ~ ε |τ| / h where that is larger): the ratio is ~1 for a scheme that is what it claims, ~1e3
  for a forward difference claimed centred.
"""

from __future__ import annotations

import numpy as np

from simparity.comparisons.measure.rows import Measured
from simparity.core.model.derivatives import DynamicsDerivatives
from simparity.core.model.metric_catalogue import (
    ABA_DERIVATIVE_ERROR_MAX,
    DERIVATIVE_IDENTITY_RESIDUAL,
    DERIVATIVE_STEP_EXCESS,
    RNEA_DERIVATIVE_ERROR_MAX,
    units,
)

DERIVATIVE_METRICS = units(RNEA_DERIVATIVE_ERROR_MAX, ABA_DERIVATIVE_ERROR_MAX, DERIVATIVE_IDENTITY_RESIDUAL,
                           DERIVATIVE_STEP_EXCESS)
"""The derivative rows of a joint-dynamics case, in row order."""

SANE_STEP = 1e-3
"""[rad, m, rad/s, m/s, N m or N] The largest step whose truncation a declared difference is held to: a claim of a
coarser step is judged as if it were this one (a forward difference at 1e-3 rad errs by ~5e-4 of the partial, at
1.0 by half of it), so that no declared step excuses an error a useful one would not make (found by a held-out
review: a step Jacobian 10 % off, declared forward at 1.0, passed)."""

DIFFERENCE_ROUNDING = 64.0
"""[ε] A difference's rounding, in units of ε |τ| / h: an inverse dynamics rounds to a few tens of ε of the largest
joint force (sums over the links of an arm of up to ~30), and the difference of two such values divided by h
carries that. Where the truth's own difference at the claimed step is smaller than this, the engine is held to this
(a centred difference at 1e-5 on a slow arm is at its rounding, not its truncation)."""

_RNEA = ("dtau_dq", "dtau_dqdot")
_ABA = ("dqddot_dq", "dqddot_dqdot", "dqddot_dtau")


def _worst(pairs: list[tuple[str, float]], what: str) -> Measured:
    """The largest of (partial, relative error), named; n/a when every partial was skipped (zero in truth, floor and
    engine alike)."""
    if not pairs:
        return Measured(np.nan, "1", unmeasurable=f"every {what} partial is zero at every state: nothing to be "
                                                  "relative to")
    name, value = max(pairs, key=lambda pair: pair[1])
    return Measured(value, "1", note=f"largest in {name}")


def partial_floors(force_floor: float, qdot: np.ndarray) -> dict[str, float]:
    """Each partial's floor: the chain's force floor [N m or N] (:attr:`ForceScale.floor`) per radian (or metre) for
    the q partials, per the sample's largest |q̇| for the q̇ ones (none without velocity), 1 for ∂q̈/∂τ (M ∂q̈/∂τ = I)."""
    speed = float(np.max(np.abs(qdot), initial=0.0))
    by_qdot = force_floor / speed if speed > 0 else 0.0
    return {"dtau_dq": force_floor, "dtau_dqdot": by_qdot, "dqddot_dq": force_floor, "dqddot_dqdot": by_qdot,
            "dqddot_dtau": 0.0}


def worst_excess(blocks: list[tuple[str, np.ndarray, np.ndarray, np.ndarray, np.ndarray]]) -> tuple[float, str, int]:
    """(the largest ratio, its block, its state) over ``blocks`` of (name, an engine's differenced block (B, ., .), the
    truth's, the truth's own differences of the declared scheme, the rounding allowance (B,) [the block's units]):
    per state, the engine's max |D - T| over the larger of the claimed scheme's max |E - T| and the allowance."""
    worst: tuple[float, str, int] = (-1.0, "", 0)
    for name, own, truth, expected, rounding in blocks:
        own_error = np.max(np.abs(own - truth), axis=(-1, -2))
        allowed = np.maximum(np.max(np.abs(expected - truth), axis=(-1, -2)), rounding)
        ratios = own_error / np.maximum(allowed, np.finfo(float).tiny)  # no allowance at all: any error is too much
        k = int(np.argmax(ratios))
        if ratios[k] > worst[0]:
            worst = (float(ratios[k]), name, k)
    return worst


def step_excess(own: DynamicsDerivatives, truth: DynamicsDerivatives, expected: dict[str, np.ndarray],
                tau_scale: np.ndarray) -> Measured:
    """How many times the error of ``own``'s differenced ∂τ/∂q and ∂τ/∂q̇ exceeds that of its declared scheme:
    ``expected`` ({partial: (B, n, n)}) is the truth's own inverse dynamics differenced the same way at the same
    steps, ``tau_scale`` (B,) [N m or N] each state's largest joint force (floored), setting the rounding
    allowance :data:`DIFFERENCE_ROUNDING` ε |τ| / h. The largest ratio over states and partials (1); n/a for
    analytic partials."""
    differences = own.differences
    if differences is None:
        return Measured(np.nan, "1", unmeasurable="analytic derivatives: no step whose truncation to hold them to")
    rounding = DIFFERENCE_ROUNDING * np.finfo(float).eps * tau_scale
    value, name, k = worst_excess([(name, getattr(own, name), getattr(truth, name), expected[name], rounding / step)
                                   for name, step in (("dtau_dq", differences.step_q),
                                                      ("dtau_dqdot", differences.step_qdot))])
    return Measured(value, "1", note=f"largest in {name} at state {k}, {differences.kind} at steps "
                                     f"{differences.step_q[k]:.3g} (q), {differences.step_qdot[k]:.3g} (qdot)")


def derivative_errors(own: DynamicsDerivatives, truth: DynamicsDerivatives, own_mass: np.ndarray,
                      floors: dict[str, float]) -> dict[str, Measured]:
    """Every derivative row of an engine's ``own`` partials against the ``truth`` (same states), each partial's scale
    floored at ``floors`` (:func:`partial_floors`), its identity with its own M (B, n, n)."""
    rnea = []
    for name in _RNEA:
        reference = getattr(truth, name)
        scale = max(float(np.max(np.abs(reference))), floors[name])
        error = float(np.max(np.abs(getattr(own, name) - reference)))
        if scale > 0 or error > 0:  # a partial zero in truth and floor: the engine's own entries, against 1
            rnea.append((name, error / (scale if scale > 0 else 1.0)))
    out = {RNEA_DERIVATIVE_ERROR_MAX: _worst(rnea, "RNEA")}
    if own.dqddot_dtau is None or truth.dqddot_dtau is None:
        missing = Measured(np.nan, "1", unmeasurable=own.forward_missing or truth.forward_missing)
        return out | {ABA_DERIVATIVE_ERROR_MAX: missing, DERIVATIVE_IDENTITY_RESIDUAL: missing}
    mass = np.linalg.inv(truth.dqddot_dtau)
    aba = []
    for name in _ABA:
        reference = getattr(truth, name)
        scale = max(float(np.max(np.abs(mass @ reference))), floors[name])
        error = float(np.max(np.abs(mass @ (getattr(own, name) - reference))))
        if scale > 0 or error > 0:
            aba.append((name, error / (scale if scale > 0 else 1.0)))
    out[ABA_DERIVATIVE_ERROR_MAX] = _worst(aba, "ABA")
    identity = np.max(np.abs(own.dqddot_dtau @ own_mass - np.eye(own_mass.shape[-1])), axis=(-1, -2))
    conditioning = np.linalg.cond(own_mass, 1)
    worst = int(np.argmax(identity / conditioning))
    out[DERIVATIVE_IDENTITY_RESIDUAL] = Measured(float(identity[worst] / conditioning[worst]), "1",
                                                 note=f"|dqddot/dtau M - I| {identity[worst]:.3g} at kappa_1(M) "
                                                      f"{conditioning[worst]:.3g} (state {worst})")
    return out
