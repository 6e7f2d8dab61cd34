"""The lecture's update rules for a point mass ("Bodies in Free Fall").

Each rule maps (x, v, a, dt) at the start of a step to (x, v) at its end, with ``a`` the
acceleration at the start of the step. The functions use only +, - , * and / so they
work on any array type: float64 arrays of shape (B, 3) in the engine, or object arrays
of ``fractions.Fraction`` to reproduce the lecture's worked example exactly.
"""

from __future__ import annotations


def constant_velocity_step(x, v, a, dt):
    """x(t + dt) = x(t) + v(t) dt; velocity unchanged ("when the velocity is constant")."""
    del a
    return x + v * dt, v


def explicit_euler_step(x, v, a, dt):
    """x(t + dt) = x(t) + v(t) dt, v(t + dt) = v(t) + a(t) dt (Euler integration)."""
    return x + v * dt, v + a * dt


def average_velocity_step(x, v, a, dt):
    """v(t + dt) = v(t) + a(t) dt, x(t + dt) = x(t) + (v(t) + v(t + dt)) / 2 dt.

    The rule of the lecture's worked example (the average of the beginning and ending
    velocities); exact for constant acceleration.
    """
    v_end = v + a * dt
    return x + (v + v_end) / 2 * dt, v_end


def taylor_step(x, v, a, dt):
    """x(t + dt) = x(t) + v(t) dt + a(t) dt^2 / 2, v(t + dt) = v(t) + a(t) dt."""
    return x + v * dt + a * dt * dt / 2, v + a * dt


RULES = {
    "constant_velocity": constant_velocity_step,
    "taylor2": taylor_step,
}
"""Particle-only rules offered by the in-house engine as integrators of their own.

The Euler and average-velocity rules are offered through the rigid-body integrators,
whose translational part they are (``explicit_euler`` and ``average_velocity``).
"""

FORCE_FREE_RULES = ("constant_velocity",)
"""Rules that never look at the acceleration: the lecture gives them for a point no force acts on."""
