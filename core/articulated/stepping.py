"""Core's joint-space time stepping: a chain's joints stepped from their initial states, batched over copies.

The state is (q, qdot), each (n, B) (component-major, the recursive algorithms' layout); the acceleration is
Featherstone's ABA, qddot = M^-1 (tau - h - D qdot) (:mod:`core.articulated.recursive`). The schemes are the
free-body family's, on the joints:

- ``explicit_euler``, ``midpoint`` (RK2), ``rk4``: the explicit Runge-Kutta schemes of
  :data:`core.dynamics.tableau.TABLEAUX` on y = (q, qdot), dy/dt = (qdot, qddot(q, qdot)); their order and stages
  are the tableau's. Explicit Euler is q' = q + dt qdot, qdot' = qdot + dt qddot(q, qdot).
- ``semi_implicit_euler``: qdot' = qdot + dt qddot(q, qdot), q' = q + dt qdot'. First order.
- ``implicit_damping``: semi-implicit Euler with the joint damping taken implicitly,
  (M + dt D) (qdot' - qdot) = dt (tau - h - D qdot), q' = q + dt qdot'. First order; unconditionally stable for
  damping alone (MuJoCo's ``euler`` with ``eulerdamp``, and ``implicitfast`` on a chain without Coriolis
  derivatives). ABA solves it: dt D is an armature, so the articulated-body solve of a chain whose armature
  is increased by dt D gives (M + dt D)^-1 (tau - h - D qdot) in O(n).

Applied joint forces are the scene's constant ones plus its timed torque (a function of time,
:mod:`core.model.scenes.time_functions`) evaluated at each stage's own time t + c_i dt, a held one as seen from inside
the step (:mod:`core.dynamics.time_loads`); the Euler steps take it at the step's start.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np

from simparity.core.articulated.chain_arrays import chain_arrays
from simparity.core.articulated.recursive import Recursive
from simparity.core.dynamics.time_loads import value_in_step
from simparity.core.dynamics.tableau import TABLEAUX, Tableau
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.joint_motion import JointMotionScene

EXPLICIT_EULER, SEMI_IMPLICIT_EULER, MIDPOINT, RK4, IMPLICIT_DAMPING = (
    "explicit_euler", "semi_implicit_euler", "midpoint", "rk4", "implicit_damping")
SCHEMES = (EXPLICIT_EULER, SEMI_IMPLICIT_EULER, MIDPOINT, RK4, IMPLICIT_DAMPING)
"""Core's joint-motion integrators, each named as its kind of scheme (:data:`core.model.engine.SCHEME_KINDS`)."""
RUNGE_KUTTA = (EXPLICIT_EULER, MIDPOINT, RK4)
"""The schemes stepped by their tableau (:data:`core.dynamics.tableau.TABLEAUX`)."""
EULER_STEPS = (SEMI_IMPLICIT_EULER, IMPLICIT_DAMPING)
"""The schemes that are no tableau: first order, one forward dynamics per step."""
ORDER = {scheme: TABLEAUX[scheme].order for scheme in RUNGE_KUTTA} | {scheme: 1 for scheme in EULER_STEPS}
"""Each scheme's order of global accuracy."""
STAGES = {scheme: TABLEAUX[scheme].stages for scheme in RUNGE_KUTTA} | {scheme: 1 for scheme in EULER_STEPS}
"""Evaluations of the forward dynamics (ABA) per step: a tableau's stages, one for the Euler steps."""

Acceleration = Callable[[np.ndarray, np.ndarray, float, float], np.ndarray]
"""qddot(q, qdot, t, step_start): the accelerations (n, B) at stage time t [s] of the step starting at step_start."""
Step = Callable[[float, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]
"""step(t, q, qdot) -> (q', qdot'): one step from time t [s]; q and qdot (n, B)."""


def damped_armature(chain: Chain, dt: float) -> Chain:
    """``chain`` with each joint's armature increased by dt times its damping (the implicit damping's M + dt D)."""
    return replace(chain, joints=tuple(replace(j, armature=j.armature + dt * j.damping) for j in chain.joints))


def _stage(y: np.ndarray, row: tuple[float, ...], ks: list[np.ndarray], dt: float) -> np.ndarray:
    """y + sum_j (dt a_ij) k_j, added term by term in stage order, zero coefficients skipped (y itself when all
    are zero)."""
    for aij, k in zip(row, ks):
        if aij:
            y = y + (dt * aij) * k
    return y


def _weighted(tableau: Tableau, ks: list[np.ndarray]) -> np.ndarray:
    """sum_i n_i k_i over the stages of nonzero weight, n_i = b_i d (:attr:`Tableau.weight_numerators`), left to
    right, k_i itself for n_i = 1: the step's increment is dt / d times it, as dt / 6 (k1 + 2 k2 + 2 k3 + k4)."""
    total: np.ndarray | None = None
    for numerator, k in zip(tableau.weight_numerators, ks):
        if numerator:
            term = k if numerator == 1.0 else numerator * k
            total = term if total is None else total + term
    assert total is not None, "a tableau has a stage of nonzero weight"
    return total


def runge_kutta(tableau: Tableau, qddot: Acceleration, dt: float) -> Step:
    """One step of the explicit Runge-Kutta scheme ``tableau`` on y = (q, qdot), dy/dt = (qdot, qddot(q, qdot, t)):
    stage i at (q_i, qdot_i) = y + dt sum_j a_ij k_j with k_j = (qdot_j, qddot(q_j, qdot_j, t + c_j dt)), then
    y' = y + dt / d sum_i n_i k_i (the weights over their common denominator d, summed by :func:`_weighted`)."""
    scale = dt / tableau.weight_denominator

    def step(t: float, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        velocities: list[np.ndarray] = []
        accelerations: list[np.ndarray] = []
        for row, c in zip(tableau.a, tableau.c):
            q_i, qdot_i = _stage(q, row, velocities, dt), _stage(qdot, row, accelerations, dt)
            velocities.append(qdot_i)
            accelerations.append(qddot(q_i, qdot_i, t + c * dt, t))
        return q + scale * _weighted(tableau, velocities), qdot + scale * _weighted(tableau, accelerations)
    return step


def stepper(scene: JointMotionScene, scheme: str, dt: float) -> Step:
    """One step (q, qdot) -> (q', qdot') of ``scheme`` at ``dt`` [s] for the scene's chain, gravity and torques;
    q and qdot (n, B)."""
    gravity = np.zeros(3) if scene.gravity_world is None else scene.gravity_world
    dynamics = Recursive(chain_arrays(scene.chain), gravity)
    constant, timed = scene.torque[:, None], scene.timed_torque

    def torque(q: np.ndarray, t: float, step_start: float) -> np.ndarray:
        """The joints' applied forces (n, B) at stage time t."""
        if timed is None:
            return np.broadcast_to(constant, q.shape)
        return np.broadcast_to(constant + value_in_step(timed, t, step_start)[:, None], q.shape)

    def qddot(q: np.ndarray, qdot: np.ndarray, t: float, step_start: float) -> np.ndarray:
        return dynamics.forward_dynamics(q, qdot, torque(q, t, step_start))

    if scheme in RUNGE_KUTTA:
        return runge_kutta(TABLEAUX[scheme], qddot, dt)
    if scheme == SEMI_IMPLICIT_EULER:
        def semi_implicit(t: float, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            qdot = qdot + dt * qddot(q, qdot, t, t)
            return q + dt * qdot, qdot
        return semi_implicit
    if scheme == IMPLICIT_DAMPING:
        implicit = Recursive(chain_arrays(damped_armature(scene.chain, dt)), gravity)

        def implicit_damping(t: float, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            qdot = qdot + dt * implicit.forward_dynamics(q, qdot, torque(q, t, t))
            return q + dt * qdot, qdot
        return implicit_damping
    raise ValueError(f"unknown joint-motion integrator {scheme!r} (allowed: {', '.join(SCHEMES)})")


def run(step: Step, q0: np.ndarray, qdot0: np.ndarray, n_steps: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """(q, qdot), each (n_steps + 1, B, n), of ``n_steps`` steps of ``dt`` [s] from (q0, qdot0), each (B, n) at
    t = 0; step k starts at (k - 1) dt."""
    batch, n = q0.shape
    q_out = np.empty((n_steps + 1, batch, n))
    qdot_out = np.empty((n_steps + 1, batch, n))
    q, qdot = np.ascontiguousarray(q0.T), np.ascontiguousarray(qdot0.T)
    q_out[0], qdot_out[0] = q0, qdot0
    for k in range(1, n_steps + 1):
        q, qdot = step((k - 1) * dt, q, qdot)
        q_out[k], qdot_out[k] = q.T, qdot.T
    return q_out, qdot_out
