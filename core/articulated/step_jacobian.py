"""Core's Jacobian of one time step of a chain's joints (issue #44): ∂x'/∂(x, τ), x = (q, q̇), τ held over the step,
carried analytically through the scheme by the chain rule with core's own derivatives of the forward dynamics
(:meth:`core.articulated.model.RecursiveDynamics.derivatives`: q̈_q, q̈_q̇, q̈_τ at each stage's state).

With f(x) = (q̇, q̈(q, q̇, τ)), f_x = [[0, I], [q̈_q, q̈_q̇]] and f_τ = [[0], [q̈_τ]]:

- an explicit Runge-Kutta tableau (a, b): X_i = x + h Σ_j a_ij K_j, K_i = f(X_i), so dK_i = f_x(X_i) (dx + h Σ_j a_ij
  dK_j) (+ f_τ(X_i) dτ), and x' = x + h Σ_i b_i K_i;
- semi-implicit Euler: q̇' = q̇ + h q̈(q, q̇), q' = q + h q̇';
- implicit damping: the same with q̈ the forward dynamics of the chain whose armature is increased by h D (its
  stepping's own model: (M + h D)⁻¹ (τ - h - D q̇)).
"""

from __future__ import annotations

import numpy as np

from simparity.core.articulated import stepping
from simparity.core.articulated.model import RecursiveDynamics
from simparity.core.dynamics.tableau import TABLEAUX
from simparity.core.model.derivatives import StepJacobian


def _slopes(model: RecursiveDynamics, q: np.ndarray, qdot: np.ndarray,
            tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q̈ (B, n), f_x (B, 2n, 2n), f_τ (B, 2n, n)) at B states."""
    count, n = q.shape
    found = model.derivatives(q, qdot, tau)
    by_state, by_force = np.zeros((count, 2 * n, 2 * n)), np.zeros((count, 2 * n, n))
    by_state[:, :n, n:] = np.eye(n)
    by_state[:, n:, :n], by_state[:, n:, n:] = found.dqddot_dq, found.dqddot_dqdot
    by_force[:, n:] = found.dqddot_dtau
    return model.forward_dynamics(q, qdot, tau), by_state, by_force


def step_jacobian(model: RecursiveDynamics, scheme: str, dt: float, q: np.ndarray, qdot: np.ndarray,
                  tau: np.ndarray) -> StepJacobian:
    """∂x'/∂x (B, 2n, 2n) and ∂x'/∂τ (B, 2n, n) of one step of core's ``scheme`` (:data:`stepping.SCHEMES`) of
    length ``dt`` [s] at B states (each (B, n)); ``model`` the chain's recursive dynamics (for implicit damping, the
    chain with armature + dt D)."""
    count, n = q.shape
    if scheme in stepping.EULER_STEPS:
        _, f_x, f_tau = _slopes(model, q, qdot, tau)
        by_state, by_force = np.zeros((count, 2 * n, 2 * n)), np.zeros((count, 2 * n, n))
        by_state[:, n:] = dt * f_x[:, n:]
        by_state[:, n:, n:] += np.eye(n)
        by_force[:, n:] = dt * f_tau[:, n:]
        by_state[:, :n] = dt * by_state[:, n:]
        by_state[:, :n, :n] += np.eye(n)
        by_force[:, :n] = dt * by_force[:, n:]
        return StepJacobian(by_state, by_force)
    tableau = TABLEAUX[scheme]
    stages: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []  # (K_i, dK_i/dx, dK_i/dτ) per stage
    for i, row in enumerate(tableau.a):
        stage_x = np.concatenate([q, qdot], axis=1) + dt * sum((row[j] * stages[j][0] for j in range(i)),
                                                                np.zeros((count, 2 * n)))
        moved_x = np.eye(2 * n) + dt * sum((row[j] * stages[j][1] for j in range(i)), np.zeros((count, 2 * n, 2 * n)))
        moved_tau = dt * sum((row[j] * stages[j][2] for j in range(i)), np.zeros((count, 2 * n, n)))
        acceleration, f_x, f_tau = _slopes(model, stage_x[:, :n], stage_x[:, n:], tau)
        slope = np.concatenate([stage_x[:, n:], acceleration], axis=1)
        stages.append((slope, f_x @ moved_x, f_x @ moved_tau + f_tau))
    by_state = np.eye(2 * n) + dt * np.einsum("s,sbij->bij", np.array(tableau.b), np.stack([k[1] for k in stages]))
    by_force = dt * np.einsum("s,sbij->bij", np.array(tableau.b), np.stack([k[2] for k in stages]))
    return StepJacobian(by_state, by_force)
