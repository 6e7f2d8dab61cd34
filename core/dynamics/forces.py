"""External forces of a scene as a wrench function (the lecture's "Forces").

F = M g - b (v - w) - c |v - w| (v - w) + sum f_i
tau = -k omega - k_q |omega| omega + sum (R p_i) x f_i      (torques about each COM)

with w the air velocity (wind), f_i constant world-frame forces applied at body-fixed
points p_i, plus each timed load's force and torque at the stage's time (:mod:`core.dynamics.time_loads`).
Terms absent from the scene contribute nothing and cost nothing.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from simparity.core.dynamics.rigid_body import MassProperties, Wrench
from simparity.core.dynamics.time_loads import load_world
from simparity.core.model.scenes.bodies import Forces
from simparity.core.rotations import vector_lengths


def make_wrench(forces: Forces, props: MassProperties) -> Wrench:
    """f(t, x, R, v, omega, step_start) -> (force_world (B, 3) [N], torque_world (B, 3) [N m])."""
    n = len(props.mass)
    constant = np.zeros((n, 3))
    if forces.gravity_world is not None:
        constant += props.mass[:, None] * forces.gravity_world
    air = np.zeros(3) if forces.air_velocity_world is None else forces.air_velocity_world
    applied_body = np.array([a.body for a in forces.applied], dtype=int)
    applied_force = np.array([a.force_world for a in forces.applied]).reshape(-1, 3)
    applied_point = np.array([a.point_body for a in forces.applied]).reshape(-1, 3)
    np.add.at(constant, applied_body, applied_force)
    b, c = forces.linear_drag, forces.quadratic_drag
    k, kq = forces.angular_linear_drag, forces.angular_quadratic_drag
    timed = forces.timed

    def wrench(t, x, rotation, v, omega, step_start=None):
        force = constant.copy()
        torque = np.zeros_like(force)
        if b is not None or c is not None:
            relative = v - air
            if b is not None:
                force -= b[:, None] * relative
            if c is not None:
                force -= c[:, None] * vector_lengths(relative) * relative
        if k is not None:
            torque -= k[:, None] * omega
        if kq is not None:
            torque -= kq[:, None] * vector_lengths(omega) * omega
        if len(applied_body):
            lever = np.einsum("aij,aj->ai", rotation[applied_body], applied_point)
            np.add.at(torque, applied_body, np.cross(lever, applied_force))
        for load in timed:
            start = t if step_start is None else step_start
            at = (lambda time: time) if np.ndim(t) == 0 else (lambda time: np.asarray(time)[load.body])
            f, tau = load_world(load, at(t), at(start), rotation[load.body])
            force[load.body] += f
            torque[load.body] += tau
        return force, torque

    return wrench


def without_gravity(forces: Forces) -> Forces:
    """The same forces minus gravity, for engines that apply gravity themselves."""
    return replace(forces, gravity_world=None)
