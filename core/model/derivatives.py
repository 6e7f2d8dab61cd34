"""The derivatives of a chain's joint-space dynamics at a sample of states (issue #44): :class:`DynamicsDerivatives`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.model.arrays import readonly

DIFFERENCE_KINDS = {False: "forward_differences", True: "central_differences"}
"""The scheme kind (:data:`simparity.core.model.engine.SCHEME_KINDS`) of partials differenced forward or centred."""
ANALYTIC = "analytic_derivatives"
"""The scheme kind of partials an engine computes in closed form (or to rounding): no step."""

PARTIALS = ("dtau_dq", "dtau_dqdot", "dqddot_dq", "dqddot_dqdot", "dqddot_dtau")
"""The fields of :class:`DynamicsDerivatives`, in the order they are compared."""


@dataclass(frozen=True)
class FiniteDifferences:
    """How an engine's RNEA partials were differenced: forward or ``centred``, at per-state steps.

    Attributes
    ----------
    centred : bool
        (f(x + h) - f(x - h)) / 2h when True, (f(x + h) - f(x)) / h when False.
    step_q, step_qdot : (B,) ndarray
        The step h at each state for q [rad or m, as the joint is] and for q̇ [rad/s or m/s].
    """

    centred: bool
    step_q: np.ndarray
    step_qdot: np.ndarray

    def __post_init__(self) -> None:
        for name in ("step_q", "step_qdot"):
            step = np.asarray(getattr(self, name), dtype=float)
            if step.ndim != 1 or not np.all(np.isfinite(step)) or not np.all(step > 0):
                raise ValueError(f"{name} must be (B,) finite steps > 0, got {step!r}")
            object.__setattr__(self, name, readonly(step))

    @property
    def kind(self) -> str:
        """"central_differences" or "forward_differences" (:data:`DIFFERENCE_KINDS`)."""
        return DIFFERENCE_KINDS[self.centred]


@dataclass(frozen=True)
class StepJacobian:
    """The Jacobian of one time step of a chain's joints at B states: x = (q, q̇) (2n), τ the joint forces held over
    the step; row i is x'_i, column j the variable.

    Attributes
    ----------
    by_state : (B, 2n, 2n) ndarray
        ∂x'/∂x: columns q_1..q_n, then q̇_1..q̇_n [1, s, 1/s as the blocks are].
    by_force : (B, 2n, n) ndarray
        ∂x'/∂τ [s²/kg m² and s/kg m², or per kg for slides].
    differences : FiniteDifferences or None
        How the engine differenced its step (its steps for x, ``step_q``, and for τ, ``step_qdot``); None for a
        Jacobian carried analytically.
    """

    by_state: np.ndarray
    by_force: np.ndarray
    differences: FiniteDifferences | None = None

    def __post_init__(self) -> None:
        state, force = np.shape(self.by_state), np.shape(self.by_force)
        if len(state) != 3 or state[1] != state[2] or state[1] % 2 or force != (state[0], state[1], state[1] // 2):
            raise ValueError(f"step Jacobian blocks of shapes {state} and {force}, expected (B, 2n, 2n) and (B, 2n, n)")
        object.__setattr__(self, "by_state", readonly(np.asarray(self.by_state, dtype=float), shape=state))
        object.__setattr__(self, "by_force", readonly(np.asarray(self.by_force, dtype=float), shape=force))
        if self.differences is not None and len(self.differences.step_q) != state[0]:
            raise ValueError(f"{len(self.differences.step_q)} difference steps for {state[0]} states")

    @property
    def kind(self) -> str:
        """:data:`ANALYTIC` or the differences' kind."""
        return ANALYTIC if self.differences is None else self.differences.kind


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
    differences : FiniteDifferences or None
        How ∂τ/∂q and ∂τ/∂q̇ were differenced; None for analytic partials. The gate holds a difference to the
        truncation of the scheme it claims at its steps, analytic partials to rounding.
    """

    dtau_dq: np.ndarray
    dtau_dqdot: np.ndarray
    dqddot_dq: np.ndarray | None = None
    dqddot_dqdot: np.ndarray | None = None
    dqddot_dtau: np.ndarray | None = None
    forward_missing: str = ""
    differences: FiniteDifferences | None = None

    @property
    def kind(self) -> str:
        """The scheme kind of the RNEA partials: :data:`ANALYTIC` or the differences'."""
        return ANALYTIC if self.differences is None else self.differences.kind

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
        if self.differences is not None and len(self.differences.step_q) != shape[0]:
            raise ValueError(f"{len(self.differences.step_q)} difference steps for {shape[0]} states")
