"""The derivatives of a chain's joint-space dynamics at a sample of states (issue #44): :class:`DynamicsDerivatives`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.model.arrays import readonly

PARTIALS = ("dtau_dq", "dtau_dqdot", "dqddot_dq", "dqddot_dqdot", "dqddot_dtau")
"""The fields of :class:`DynamicsDerivatives`, in the order they are compared."""


@dataclass(frozen=True)
class DynamicsDerivatives:
    """Partial derivatives of inverse dynamics τ(q, q̇, q̈) = M q̈ + h + D q̇ (RNEA) and forward dynamics
    q̈(q, q̇, τ) (ABA) at B states, each (B, n, n) with column j the derivative by joint j's variable (row i: joint
    i's output). ∂τ/∂q̈ = M and is not repeated.

    Attributes
    ----------
    dtau_dq, dtau_dqdot : (B, n, n) ndarray
        [N m / rad, N m s / rad, or N and m mixed as the joints are].
    dqddot_dq, dqddot_dqdot, dqddot_dtau : (B, n, n) ndarray or None
        At q̈ = the forward dynamics of the states' τ; None, all three, for an engine without forward-dynamics
        derivatives (``forward_missing`` says why).
    forward_missing : str
        Why the forward partials are None ("" when they are given).
    """

    dtau_dq: np.ndarray
    dtau_dqdot: np.ndarray
    dqddot_dq: np.ndarray | None = None
    dqddot_dqdot: np.ndarray | None = None
    dqddot_dtau: np.ndarray | None = None
    forward_missing: str = ""

    def __post_init__(self) -> None:
        shape = np.shape(self.dtau_dq)
        if len(shape) != 3 or shape[1] != shape[2]:
            raise ValueError(f"dtau_dq has shape {shape}, expected (B, n, n)")
        given = [getattr(self, name) is not None for name in PARTIALS[2:]]
        if any(given) != all(given) or (not all(given) and not self.forward_missing):
            raise ValueError("the forward partials are all given, or all None with forward_missing saying why")
        for name in PARTIALS:
            if getattr(self, name) is not None:
                object.__setattr__(self, name, readonly(np.asarray(getattr(self, name), dtype=float), shape=shape))
