"""Core's joint-space time stepping: a chain's joints stepped from their initial states, batched over copies.

The state is (q, qdot), each (n, B) (component-major, the recursive algorithms' layout); the acceleration is
Featherstone's ABA, qddot = M^-1 (tau - h - D qdot) (:mod:`core.articulated.recursive`). The schemes are the
free-body family's, on the joints:

- ``explicit_euler``: q' = q + dt qdot, qdot' = qdot + dt qddot(q, qdot). First order.
- ``semi_implicit_euler``: qdot' = qdot + dt qddot(q, qdot), q' = q + dt qdot'. First order.
- ``midpoint``: the explicit midpoint rule (RK2). Second order.
- ``rk4``: classical Runge-Kutta. Fourth order.
- ``implicit_damping``: semi-implicit Euler with the joint damping taken implicitly,
  (M + dt D) (qdot' - qdot) = dt (tau - h - D qdot), q' = q + dt qdot'. First order; unconditionally stable for
  damping alone (MuJoCo's ``euler`` with ``eulerdamp``, and ``implicitfast`` on a chain without Coriolis
  derivatives). ABA solves it: dt D is an armature, so the articulated-body solve of a chain whose armature
  is increased by dt D gives (M + dt D)^-1 (tau - h - D qdot) in O(n).

Applied joint forces are the scene's, constant, so every stage sees the same.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np

from simparity.core.articulated.chain_arrays import chain_arrays
from simparity.core.articulated.recursive import Recursive
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.joint_motion import JointMotionScene

EXPLICIT_EULER, SEMI_IMPLICIT_EULER, MIDPOINT, RK4, IMPLICIT_DAMPING = (
    "explicit_euler", "semi_implicit_euler", "midpoint", "rk4", "implicit_damping")
SCHEMES = (EXPLICIT_EULER, SEMI_IMPLICIT_EULER, MIDPOINT, RK4, IMPLICIT_DAMPING)
"""Core's joint-motion integrators, each named as its kind of scheme (:data:`core.model.engine.SCHEME_KINDS`)."""
ORDER = {EXPLICIT_EULER: 1, SEMI_IMPLICIT_EULER: 1, MIDPOINT: 2, RK4: 4, IMPLICIT_DAMPING: 1}
STAGES = {EXPLICIT_EULER: 1, SEMI_IMPLICIT_EULER: 1, MIDPOINT: 2, RK4: 4, IMPLICIT_DAMPING: 1}
"""Evaluations of the forward dynamics (ABA) per step, counted in the code below."""

Acceleration = Callable[[np.ndarray, np.ndarray], np.ndarray]
Step = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]


def _damped_armature(chain: Chain, dt: float) -> Chain:
    """``chain`` with each joint's armature increased by dt times its damping (the implicit damping's M + dt D)."""
    return replace(chain, joints=tuple(replace(j, armature=j.armature + dt * j.damping) for j in chain.joints))


def stepper(scene: JointMotionScene, scheme: str, dt: float) -> Step:
    """One step (q, qdot) -> (q', qdot') of ``scheme`` at ``dt`` [s] for the scene's chain, gravity and torques;
    q and qdot (n, B)."""
    gravity = np.zeros(3) if scene.gravity_world is None else scene.gravity_world
    dynamics = Recursive(chain_arrays(scene.chain), gravity)
    torque = scene.torque[:, None]

    def qddot(q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        return dynamics.forward_dynamics(q, qdot, np.broadcast_to(torque, q.shape))

    if scheme == EXPLICIT_EULER:
        return lambda q, qdot: (q + dt * qdot, qdot + dt * qddot(q, qdot))
    if scheme == SEMI_IMPLICIT_EULER:
        def semi_implicit(q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            qdot = qdot + dt * qddot(q, qdot)
            return q + dt * qdot, qdot
        return semi_implicit
    if scheme == MIDPOINT:
        def midpoint(q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            half = qdot + 0.5 * dt * qddot(q, qdot)
            return q + dt * half, qdot + dt * qddot(q + 0.5 * dt * qdot, half)
        return midpoint
    if scheme == RK4:
        def rk4(q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            a1 = qddot(q, qdot)
            v2 = qdot + 0.5 * dt * a1
            a2 = qddot(q + 0.5 * dt * qdot, v2)
            v3 = qdot + 0.5 * dt * a2
            a3 = qddot(q + 0.5 * dt * v2, v3)
            v4 = qdot + dt * a3
            a4 = qddot(q + dt * v3, v4)
            return (q + dt / 6.0 * (qdot + 2.0 * v2 + 2.0 * v3 + v4),
                    qdot + dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4))
        return rk4
    if scheme == IMPLICIT_DAMPING:
        implicit = Recursive(chain_arrays(_damped_armature(scene.chain, dt)), gravity)

        def implicit_damping(q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            qdot = qdot + dt * implicit.forward_dynamics(q, qdot, np.broadcast_to(torque, q.shape))
            return q + dt * qdot, qdot
        return implicit_damping
    raise ValueError(f"unknown joint-motion integrator {scheme!r} (allowed: {', '.join(SCHEMES)})")


def run(step: Step, q0: np.ndarray, qdot0: np.ndarray, n_steps: int) -> tuple[np.ndarray, np.ndarray]:
    """(q, qdot), each (n_steps + 1, B, n), of ``n_steps`` steps from (q0, qdot0), each (B, n)."""
    batch, n = q0.shape
    q_out = np.empty((n_steps + 1, batch, n))
    qdot_out = np.empty((n_steps + 1, batch, n))
    q, qdot = np.ascontiguousarray(q0.T), np.ascontiguousarray(qdot0.T)
    q_out[0], qdot_out[0] = q0, qdot0
    for k in range(1, n_steps + 1):
        q, qdot = step(q, qdot)
        q_out[k], qdot_out[k] = q.T, qdot.T
    return q_out, qdot_out
