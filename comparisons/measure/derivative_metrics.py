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
  (~1e9 with a 1 g link at the tip), so the residual is judged against its conditioning.
"""

from __future__ import annotations

import numpy as np

from simparity.comparisons.measure.rows import Measured
from simparity.core.model.derivatives import DynamicsDerivatives
from simparity.core.model.metric_catalogue import (
    ABA_DERIVATIVE_ERROR_MAX,
    DERIVATIVE_IDENTITY_RESIDUAL,
    RNEA_DERIVATIVE_ERROR_MAX,
    units,
)

DERIVATIVE_METRICS = units(RNEA_DERIVATIVE_ERROR_MAX, ABA_DERIVATIVE_ERROR_MAX, DERIVATIVE_IDENTITY_RESIDUAL)
"""The derivative rows of a joint-dynamics case, in row order."""

_RNEA = ("dtau_dq", "dtau_dqdot")
_ABA = ("dqddot_dq", "dqddot_dqdot", "dqddot_dtau")


def _worst(pairs: list[tuple[str, float]], what: str) -> Measured:
    """The largest of (partial, relative error), named; n/a when every partial was skipped."""
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


def derivative_errors(own: DynamicsDerivatives, truth: DynamicsDerivatives, own_mass: np.ndarray,
                      floors: dict[str, float]) -> dict[str, Measured]:
    """Every derivative row of an engine's ``own`` partials against the ``truth`` (same states), each partial's scale
    floored at ``floors`` (:func:`partial_floors`), its identity with its own M (B, n, n)."""
    rnea = []
    for name in _RNEA:
        reference = getattr(truth, name)
        scale = max(float(np.max(np.abs(reference))), floors[name])
        if scale > 0:
            rnea.append((name, float(np.max(np.abs(getattr(own, name) - reference))) / scale))
    out = {RNEA_DERIVATIVE_ERROR_MAX: _worst(rnea, "RNEA")}
    if own.dqddot_dtau is None or truth.dqddot_dtau is None:
        missing = Measured(np.nan, "1", unmeasurable=own.forward_missing or truth.forward_missing)
        return out | {ABA_DERIVATIVE_ERROR_MAX: missing, DERIVATIVE_IDENTITY_RESIDUAL: missing}
    mass = np.linalg.inv(truth.dqddot_dtau)
    aba = []
    for name in _ABA:
        reference = getattr(truth, name)
        scale = max(float(np.max(np.abs(mass @ reference))), floors[name])
        if scale > 0:
            aba.append((name, float(np.max(np.abs(mass @ (getattr(own, name) - reference)))) / scale))
    out[ABA_DERIVATIVE_ERROR_MAX] = _worst(aba, "ABA")
    identity = np.max(np.abs(own.dqddot_dtau @ own_mass - np.eye(own_mass.shape[-1])), axis=(-1, -2))
    conditioning = np.linalg.cond(own_mass, 1)
    worst = int(np.argmax(identity / conditioning))
    out[DERIVATIVE_IDENTITY_RESIDUAL] = Measured(float(identity[worst] / conditioning[worst]), "1",
                                                 note=f"|dqddot/dtau M - I| {identity[worst]:.3g} at kappa_1(M) "
                                                      f"{conditioning[worst]:.3g} (state {worst})")
    return out
