"""The truth of a time step's Jacobian (issue #44): ∂x_{k+1}/∂(x_k, τ) of one step of a chain's joints under a
declared scheme, x = (q, q̇), τ the joint forces held over the step, carried by complex step through the scheme's own
formula around the complex-safe dynamics of :mod:`references.derivatives.complex_step` (q̈ = M⁻¹ (τ - h - D q̇), M from
RNEA's columns, a linear solve: analytic in every input).

The schemes are written here, from their definitions, not taken from core (``SCHEME_KINDS``):

- Runge-Kutta tableaux (:data:`TABLEAUX`): explicit Euler, the midpoint rule, Heun's average velocity, classical RK4,
  on ẋ = (q̇, q̈(q, q̇, τ));
- semi-implicit Euler (and engine_euler, the same on a chain's joints): q̇' = q̇ + h q̈(q, q̇), q' = q + h q̇';
- implicit damping (MuJoCo's Euler with eulerdamp, implicitfast on a chain, core's implicit_damping): q̇' = q̇ + h
  (M + h D)⁻¹ (τ - h(q, q̇) - D q̇), q' = q + h q̇'.

``implicit_velocity`` (every velocity-dependent force linearised, MuJoCo's implicit) needs ∂h/∂q̇ inside the step, a
derivative the complex step would have to nest: no truth (:data:`UNSUPPORTED`).
"""

from __future__ import annotations

import numpy as np

from simparity.core.model.derivatives import StepJacobian
from simparity.references.derivatives.complex_step import STEP, Tree, complex_directions, complex_mass_and_bias

TABLEAUX = {
    "explicit_euler": (np.zeros((1, 1)), np.array([1.0])),
    "midpoint": (np.array([[0.0, 0.0], [0.5, 0.0]]), np.array([0.0, 1.0])),
    "average_velocity": (np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([0.5, 0.5])),
    "rk4": (np.array([[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, 0.0, 0.0], [0.0, 0.5, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]),
            np.array([1.0, 2.0, 2.0, 1.0]) / 6.0),
}
"""Explicit Runge-Kutta schemes: (the matrix a, the weights b) of their Butcher tableaux."""
SEMI_IMPLICIT = ("semi_implicit_euler", "engine_euler")
IMPLICIT_DAMPING = "implicit_damping"
UNSUPPORTED = {"implicit_velocity": "no truth for implicit_velocity: its step takes dh/dqdot, which a complex step "
                                    "cannot carry without nesting one in another"}
SCHEMES = tuple(TABLEAUX) + SEMI_IMPLICIT + (IMPLICIT_DAMPING,)


def _damping(tree: Tree, n: int) -> np.ndarray:
    """D (n,) in the chain's joint order."""
    out = np.zeros(n)
    out[tree.columns] = tree.damping
    return out


def _acceleration(tree: Tree, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray, implicit: float = 0.0) -> np.ndarray:
    """(M + implicit D)⁻¹ (τ - h - D q̇) (K, n), complex-safe; ``implicit`` the step h of implicit damping, 0 without."""
    mass, bias = complex_mass_and_bias(tree, q, qdot)
    if implicit:
        mass = mass + implicit * np.diag(_damping(tree, q.shape[1]))
    return np.linalg.solve(mass, (tau - bias)[:, :, None])[:, :, 0]


def step(tree: Tree, scheme: str, dt: float, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """x' = (q', q̇') (K, 2n) after one step of ``scheme`` (:data:`SCHEMES`) of length ``dt`` [s] from K states (q, q̇)
    (K, n) under joint forces ``tau`` (K, n) held over the step (real or complex)."""
    if scheme in UNSUPPORTED:
        raise ValueError(UNSUPPORTED[scheme])
    if scheme in SEMI_IMPLICIT or scheme == IMPLICIT_DAMPING:
        rates = qdot + dt * _acceleration(tree, q, qdot, tau, dt if scheme == IMPLICIT_DAMPING else 0.0)
        return np.concatenate([q + dt * rates, rates], axis=1)
    if scheme not in TABLEAUX:
        raise ValueError(f"no truth for the scheme {scheme!r} (allowed: {', '.join(SCHEMES)})")
    a, b = TABLEAUX[scheme]
    slopes: list[tuple[np.ndarray, np.ndarray]] = []
    for i in range(len(b)):
        stage_q = q + dt * sum((a[i, j] * slopes[j][0] for j in range(i)), np.zeros_like(q))
        stage_qdot = qdot + dt * sum((a[i, j] * slopes[j][1] for j in range(i)), np.zeros_like(qdot))
        slopes.append((stage_qdot, _acceleration(tree, stage_q, stage_qdot, tau)))
    return np.concatenate([q + dt * sum(w * s[0] for w, s in zip(b, slopes)),
                           qdot + dt * sum(w * s[1] for w, s in zip(b, slopes))], axis=1)


def step_jacobian(tree: Tree, scheme: str, dt: float, q: np.ndarray, qdot: np.ndarray,
                  tau: np.ndarray) -> StepJacobian:
    """∂x'/∂x (B, 2n, 2n) and ∂x'/∂τ (B, 2n, n) of one step at B states (each (B, n)), by complex step through
    :func:`step`: 3n directions per state (q_j, q̇_j, τ_j), each perturbed by i h."""
    count, n = q.shape
    slopes = (step(tree, scheme, dt, *complex_directions(q, qdot, tau)).imag / STEP).reshape(count, 3 * n, 2 * n).transpose(0, 2, 1)
    return StepJacobian(slopes[:, :, :2 * n], slopes[:, :, 2 * n:])
