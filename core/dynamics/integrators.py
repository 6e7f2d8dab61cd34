"""Time integrators for the rigid-body state S = (x, R, P, L), batched over bodies.

Schemes
-------
explicit_euler, average_velocity (Heun / trapezoid: the lecture's average of beginning and
ending velocities), midpoint, rk4
    Explicit Runge-Kutta methods on dS/dt = (v, omega* R, F, tau).
semi_implicit_euler
    Symplectic Euler: momenta first, then position and orientation with the new velocities.
engine_euler
    The first-order scheme of MuJoCo (integrator Euler), PyBullet and Pinocchio-with-aba:
    linear velocity and BODY-frame angular velocity first, with the explicit gyroscopic
    term I_b^-1 (tau_b - omega_b x I_b omega_b), then x += dt v and R = R exp(dt omega_b).

Orientation updates (every scheme but engine_euler, which always uses the exponential map)
------------------------------------------------------------------------------------------
matrix
    Additive dR = omega* R dt, re-orthonormalised (polar decomposition) after the step.
quaternion
    Additive dq = 1/2 (0, omega) q dt, normalised after the step.
expmap
    Lie-group update R <- exp(u) R. Runge-Kutta stages use the Runge-Kutta-Munthe-Kaas
    construction (stage increments corrected by the inverse of dexp), which keeps the
    scheme's order.

The quaternion updates and engine_euler are implemented on a component-major packed state in
:mod:`core.dynamics.quaternion_integrators` (the speed path); the matrix and expmap updates here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, cast

import numpy as np

from simparity.core.dynamics.quaternion_integrators import state_step
from simparity.core.dynamics.rigid_body import MassProperties, State, Wrench, velocities
from simparity.core.dynamics.tableau import TABLEAUX
from simparity.core.rotations import (
    cross,
    orthonormalize,
    skew,
    so3_exp,
)

ORIENTATION_UPDATES = ("quaternion", "matrix", "expmap")

EULER_STEPS = ("semi_implicit_euler", "engine_euler")
"""The schemes that are no Runge-Kutta tableau: first order, one evaluation of the forces at the step's start."""

SCHEMES = tuple(TABLEAUX) + EULER_STEPS

ORDER = {scheme: tableau.order for scheme, tableau in TABLEAUX.items()} | {scheme: 1 for scheme in EULER_STEPS}
"""Theoretical order of global accuracy of each scheme (a tableau's :attr:`~core.dynamics.tableau.Tableau.order`)."""

STAGES = {scheme: tableau.stages for scheme, tableau in TABLEAUX.items()} | {scheme: 1 for scheme in EULER_STEPS}
"""Evaluations of the scene's wrench per step of each scheme, whatever its orientation update: one per stage of a
Runge-Kutta tableau (explicit Euler 1, midpoint and average velocity 2, RK4 4), one for the Euler steps that take
the forces at the step's start."""

# Below this rotation angle [rad] dexpinv uses its series; its error there is ~1e-17.
_DEXPINV_SERIES_ANGLE = 1e-3

Step = Callable[[float, State, float], State]


def dexpinv_so3(u: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Inverse of the derivative of exp on so(3), applied to omega: du/dt for R = exp(u) R0.

    For a body-frame (right) increment R = R0 exp(u) with body angular velocity omega, du/dt is
    ``dexpinv_so3(-u, omega)``.

    dexp_u^-1(w) = w - u x w / 2 + (1 - (a/2) cot(a/2)) / a^2  u x (u x w), a = |u|.
    (B, 3) x (B, 3) -> (B, 3).
    """
    angle = np.linalg.norm(u, axis=-1)
    small = angle < _DEXPINV_SERIES_ANGLE
    a = np.where(small, 1.0, angle)
    coef = np.where(small, 1 / 12 + angle**2 / 720, (1 - (a / 2) / np.tan(a / 2)) / (a * a))
    ux_w = cross(u, omega)
    return omega - 0.5 * ux_w + coef[:, None] * cross(u, ux_w)


def _project(state: State) -> State:
    """Re-orthonormalise the rotation matrix after an additive update."""
    return State(state.position_world, orthonormalize(state.orientation), state.momentum_world,
                 state.angular_momentum_world)


def _orientation_rate(rotation: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """dR/dt = omega* R. World omega (B, 3)."""
    return skew(omega) @ rotation


def _rotate(rotation: np.ndarray, rotvec_world: np.ndarray) -> np.ndarray:
    """exp(rotvec) applied on the left (a world-frame increment) to R (B, 3, 3)."""
    return so3_exp(rotvec_world) @ rotation


@dataclass(frozen=True)
class _Derivative:
    velocity_world: np.ndarray
    omega_world: np.ndarray
    force_world: np.ndarray
    torque_world: np.ndarray


def _derivative(t: float, state: State, props: MassProperties, wrench: Wrench,
                step_start: float | None = None) -> _Derivative:
    """The state's rate at stage time ``t`` of the step starting at ``step_start`` (None: ``t``)."""
    rotation = state.rotation_world
    v, omega = velocities(state, props, rotation)
    force, torque = wrench(t, state.position_world, rotation, v, omega, step_start)
    return _Derivative(v, omega, force, torque)


def runge_kutta_step(
    scheme: str, orientation_update: str, props: MassProperties, wrench: Wrench
) -> Step:
    """One step of an explicit Runge-Kutta scheme (:data:`core.dynamics.tableau.TABLEAUX`). Returns
    ``step(t, state, dt) -> state``. Each stage's and the step's increments are summed from 0 over every
    coefficient, sum_j (dt a_ij) k_j, then added to the state."""
    tableau = TABLEAUX[scheme]
    a, b, c = tableau.a, tableau.b, tableau.c
    lie = orientation_update == "expmap"

    def step(t: float, s: State, dt: float) -> State:
        ks: list[_Derivative] = []
        rot_incs: list[np.ndarray] = []  # RKMK: dexpinv-corrected omegas, or additive rates
        for i in range(len(b)):
            def combine(field: str) -> np.ndarray | float:  # 0.0 at the first stage
                return sum((dt * aij * getattr(k, field) for aij, k in zip(a[i], ks)), start=0.0)

            if lie:
                u = sum((dt * aij * w for aij, w in zip(a[i], rot_incs)), start=np.zeros_like(s.position_world))
                orientation = _rotate(s.orientation, u) if i else s.orientation
            else:
                orientation = s.orientation + sum((dt * aij * r for aij, r in zip(a[i], rot_incs)), start=0.0)
            stage = State(
                s.position_world + combine("velocity_world"),
                orientation,
                s.momentum_world + combine("force_world"),
                s.angular_momentum_world + combine("torque_world"),
            )
            k = _derivative(t + c[i] * dt, stage, props, wrench, t)
            ks.append(k)
            rot_incs.append(
                dexpinv_so3(u, k.omega_world) if lie else _orientation_rate(stage.orientation, k.omega_world)
            )

        def total(field: str) -> np.ndarray:
            return sum(dt * bi * getattr(k, field) for bi, k in zip(b, ks))

        # Every tableau has a stage, so the sum is an array, never sum's start 0.
        increment = cast(np.ndarray, sum(dt * bi * r for bi, r in zip(b, rot_incs)))
        new = State(
            s.position_world + total("velocity_world"),
            _rotate(s.orientation, increment) if lie else s.orientation + increment,
            s.momentum_world + total("force_world"),
            s.angular_momentum_world + total("torque_world"),
        )
        return new if lie else _project(new)

    return step


def semi_implicit_euler_step(orientation_update: str, props: MassProperties, wrench: Wrench) -> Step:
    """Symplectic Euler: P, L with the forces at the start, then x, R with the new v, omega."""

    def step(t: float, s: State, dt: float) -> State:
        k = _derivative(t, s, props, wrench)
        momentum = s.momentum_world + dt * k.force_world
        angular_momentum = s.angular_momentum_world + dt * k.torque_world
        rotation = s.rotation_world
        omega = np.einsum("bij,bj->bi", props.inertia_world_inv(rotation), angular_momentum)
        position = s.position_world + dt * momentum / props.mass[:, None]
        if orientation_update == "expmap":
            orientation = _rotate(s.orientation, dt * omega)
        else:
            orientation = s.orientation + dt * _orientation_rate(s.orientation, omega)
        new = State(position, orientation, momentum, angular_momentum)
        return new if orientation_update == "expmap" else _project(new)

    return step


def make_step(scheme: str, orientation_update: str, props: MassProperties, wrench: Wrench) -> Step:
    """The step function of ``scheme`` with ``orientation_update`` (see module docstring).

    Quaternion updates and ``engine_euler`` run on the packed layout of
    :mod:`core.dynamics.quaternion_integrators`; matrix and exponential-map updates here.
    """
    if scheme not in SCHEMES:
        raise ValueError(f"unknown scheme '{scheme}' (known: {', '.join(SCHEMES)})")
    if orientation_update == "quaternion" or scheme == "engine_euler":
        return state_step(scheme, props, wrench)
    if scheme in TABLEAUX:
        return runge_kutta_step(scheme, orientation_update, props, wrench)
    return semi_implicit_euler_step(orientation_update, props, wrench)
