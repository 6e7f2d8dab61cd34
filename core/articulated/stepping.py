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

A floating base (``chain.floating_base``) is stepped in the project's convention: q = (position, quat_wxyz, joints)
(nq = 7 + n), qdot = (the base origin's velocity and the base's angular velocity in world axes, joint rates)
(nv = 6 + n), qddot by the floating-base ABA (:mod:`core.articulated.floating`). The schemes above step q by its
rate dq/dt = (v, 1/2 (0, omega) x quat, joint rates) (:func:`configuration_rate`: the quaternion in R^4, its
kinematic equation for an angular velocity in world axes) in place of qdot, and normalise the quaternion after each
step (:func:`normalised`); stages evaluate the dynamics at the stage quaternion normalised. A Runge-Kutta scheme keeps
its order (the equation is smooth in R^4 and normalising changes a step by the step's own error).

Applied joint forces are the scene's constant ones plus its timed torque (a function of time,
:mod:`core.model.scenes.time_functions`) evaluated at each stage's own time t + c_i dt, a held one as seen from inside
the step (:mod:`core.dynamics.time_loads`); the Euler steps take it at the step's start.

With contact (``scene.contact``), every evaluation of the accelerations adds the plane's penalty forces on the chain's
spheres at that stage's state, through the spheres' Jacobians (:mod:`core.articulated.chain_contact`): the contact is a
force of the state like any other, stepped by the same scheme (the lecture's penalty method, stiff as its spring).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable

import numpy as np

from simparity.core.articulated.chain_arrays import chain_arrays
from simparity.core.articulated.chain_contact import ChainContactForces
from simparity.core.articulated.floating import FloatingRecursiveDynamics
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

Rate = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""dq/dt (nq, B) of (q (nq, B), qdot (nv, B)): qdot itself for a fixed base (:func:`configuration_rate`)."""
Project = Callable[[np.ndarray], np.ndarray]
"""q (nq, B) after a step -> the configuration stepped on (its quaternion normalised; q itself for a fixed base)."""
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


def _fixed_rate(q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
    """A fixed base's dq/dt: qdot itself."""
    return qdot


def _unchanged(q: np.ndarray) -> np.ndarray:
    """A fixed base's configuration after a step: q itself."""
    return q


def configuration_rate(q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
    """A floating base's dq/dt (7 + n, B) of q (7 + n, B) and qdot (6 + n, B): the base origin's velocity, the
    quaternion's rate 1/2 (0, omega) x quat (omega in world axes: the product on the left), the joint rates."""
    w, x, y, z = q[3:7]
    ox, oy, oz = qdot[3:6]
    quat_rate = 0.5 * np.stack([-ox * x - oy * y - oz * z, ox * w + oy * z - oz * y, oy * w + oz * x - ox * z,
                                oz * w + ox * y - oy * x])
    return np.concatenate([qdot[:3], quat_rate, qdot[6:]])


def normalised(q: np.ndarray) -> np.ndarray:
    """q (7 + n, B) with its quaternion rows scaled to unit length."""
    out = q.copy()
    out[3:7] /= np.sqrt(np.einsum("ib,ib->b", q[3:7], q[3:7]))
    return out


def runge_kutta(tableau: Tableau, qddot: Acceleration, dt: float, rate: Rate = _fixed_rate,
                project: Project = _unchanged) -> Step:
    """One step of the explicit Runge-Kutta scheme ``tableau`` on y = (q, qdot), dy/dt = (rate(q, qdot),
    qddot(q, qdot, t)): stage i at (q_i, qdot_i) = y + dt sum_j a_ij k_j with k_j = (rate(q_j, qdot_j), qddot(q_j,
    qdot_j, t + c_j dt)), then y' = y + dt / d sum_i n_i k_i (the weights over their common denominator d, summed by
    :func:`_weighted`), its q projected (a floating base's quaternion normalised)."""
    scale = dt / tableau.weight_denominator

    def step(t: float, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        velocities: list[np.ndarray] = []
        accelerations: list[np.ndarray] = []
        for row, c in zip(tableau.a, tableau.c):
            q_i, qdot_i = _stage(q, row, velocities, dt), _stage(qdot, row, accelerations, dt)
            velocities.append(rate(q_i, qdot_i))
            accelerations.append(qddot(q_i, qdot_i, t + c * dt, t))
        return project(q + scale * _weighted(tableau, velocities)), qdot + scale * _weighted(tableau, accelerations)
    return step


Response = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""M^-1 f (n, B) of (q (n, B), f (n, B)): the joints' acceleration under the joint forces f alone (no gravity, no
velocity), with the M the scheme steps with (armature + dt D under implicit damping)."""
Constraint = Callable[[np.ndarray, np.ndarray, np.ndarray, Response], np.ndarray]
"""qddot (n, B) of (q, qdot, the unconstrained qddot, the scheme's :data:`Response`): a rigid contact's correction of
the accelerations (:mod:`core.articulated.chain_impulse`)."""


def stepper(scene: JointMotionScene, scheme: str, dt: float, constraint: Constraint | None = None) -> Step:
    """One step (q, qdot) -> (q', qdot') of ``scheme`` at ``dt`` [s] for the scene's chain, gravity and torques;
    q and qdot (n, B). A ``constraint`` corrects every evaluation of the accelerations (fixed base only)."""
    return sized_stepper(scene, scheme, constraint)(dt)


def sized_stepper(scene: JointMotionScene, scheme: str,
                  constraint: Constraint | None = None) -> Callable[[float], Step]:
    """:func:`stepper` of any step size: the dynamics built once, the step for each dt [s] made on demand."""
    if scheme not in SCHEMES:
        raise ValueError(f"unknown joint-motion integrator {scheme!r} (allowed: {', '.join(SCHEMES)})")
    gravity = np.zeros(3) if scene.gravity_world is None else scene.gravity_world
    floating = scene.chain.floating_base
    rate, project = (configuration_rate, normalised) if floating else (_fixed_rate, _unchanged)
    dynamics = _forward_dynamics(scene.chain, gravity)
    constant, timed = scene.torque[:, None], scene.timed_torque
    contact = (ChainContactForces(scene.chain, scene.contact)
               if scene.contact is not None and not scene.contact.rigid else None)

    def torque(qdot: np.ndarray, t: float, step_start: float) -> np.ndarray:
        """The applied forces (nv, B) at stage time t: the joints', none on a floating base."""
        joints = constant if timed is None else constant + value_in_step(timed, t, step_start)[:, None]
        if floating:
            joints = np.concatenate([np.zeros((6, 1)), joints])
        return np.broadcast_to(joints, qdot.shape)

    def applied(q: np.ndarray, qdot: np.ndarray, t: float, step_start: float) -> np.ndarray:
        """The applied forces and, with soft contact, the plane's generalized force at the state (nv, B)."""
        tau = torque(qdot, t, step_start)
        return tau if contact is None else tau + contact.generalized(normalised(q) if floating else q, qdot)

    def constrained(forward: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
                    chain: Chain) -> Acceleration:
        """The accelerations by ``forward`` (of ``chain``), corrected by the constraint where there is one."""
        if constraint is None:
            return lambda q, qdot, t, step_start: forward(q, qdot, applied(q, qdot, t, step_start))
        unforced = _forward_dynamics(chain, np.zeros(3))

        def response(q: np.ndarray, force: np.ndarray) -> np.ndarray:
            return unforced(q, np.zeros_like(force), force)

        def qddot(q: np.ndarray, qdot: np.ndarray, t: float, step_start: float) -> np.ndarray:
            return constraint(q, qdot, forward(q, qdot, applied(q, qdot, t, step_start)), response)
        return qddot

    if scheme in RUNGE_KUTTA:
        explicit = constrained(dynamics, scene.chain)
        return lambda dt: runge_kutta(TABLEAUX[scheme], explicit, dt, rate, project)
    if scheme == SEMI_IMPLICIT_EULER:
        accelerations = constrained(dynamics, scene.chain)

        def semi_implicit_step(dt: float) -> Step:
            def semi_implicit(t: float, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
                qdot = qdot + dt * accelerations(q, qdot, t, t)
                return project(q + dt * rate(q, qdot)), qdot
            return semi_implicit
        return semi_implicit_step

    def implicit_damping_step(dt: float) -> Step:
        damped = damped_armature(scene.chain, dt)
        implicit = constrained(_forward_dynamics(damped, gravity), damped)

        def implicit_damping(t: float, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            qdot = qdot + dt * implicit(q, qdot, t, t)
            return project(q + dt * rate(q, qdot)), qdot
        return implicit_damping
    return implicit_damping_step


def _forward_dynamics(chain: Chain, gravity: np.ndarray) -> Callable[[np.ndarray, np.ndarray, np.ndarray],
                                                                       np.ndarray]:
    """qddot (nv, B) of (q (nq, B), qdot (nv, B), tau (nv, B)): ABA, with a floating root where the chain has one
    (the stage's quaternion normalised)."""
    if not chain.floating_base:
        return Recursive(chain_arrays(chain), gravity).forward_dynamics
    floating = FloatingRecursiveDynamics(chain, gravity)

    def forward(q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        return floating.forward_dynamics(normalised(q).T, qdot.T, tau.T).T
    return forward


def run(step: Step, q0: np.ndarray, qdot0: np.ndarray, n_steps: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """(q, qdot), (n_steps + 1, B, nq) and (n_steps + 1, B, nv), of ``n_steps`` steps of ``dt`` [s] from (q0, qdot0),
    (B, nq) and (B, nv) at t = 0; step k starts at (k - 1) dt."""
    q_out = np.empty((n_steps + 1,) + q0.shape)
    qdot_out = np.empty((n_steps + 1,) + qdot0.shape)
    q, qdot = np.ascontiguousarray(q0.T), np.ascontiguousarray(qdot0.T)
    q_out[0], qdot_out[0] = q0, qdot0
    for k in range(1, n_steps + 1):
        q, qdot = step((k - 1) * dt, q, qdot)
        q_out[k], qdot_out[k] = q.T, qdot.T
    return q_out, qdot_out
