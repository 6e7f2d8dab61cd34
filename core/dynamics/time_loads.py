"""Core's evaluation of loads that change with time (:mod:`core.model.scenes.time_functions`), at a Runge-Kutta
stage's own time.

A stage of the step that starts at t_start is evaluated at s = t_start + c dt. A smooth function is evaluated at s.
A zero-order hold is evaluated as seen from inside the step: its value at s for s = t_start, its value just before
s for s > t_start (:data:`ON_INSTANT` decides when s is a sample instant), so that a step whose ends are sample
instants sees one constant value.
"""

from __future__ import annotations

import numpy as np

from simparity.core.model.scenes.time_functions import BODY, HeldFunction, SmoothFunction, TimedLoad, TimeFunction

ON_INSTANT = 1e-9
"""A time within this many control periods of a sample instant is on it: step times are sums of dt, sample instants
phase + k period, and the two round differently (~1e-16 relative); 1e-9 is far above that and far below any stage's
distance from an instant that is not on it (a stage is c dt away from the step's start, c a simple fraction)."""


def smooth_value(function: SmoothFunction, t: float | np.ndarray) -> np.ndarray:
    """f(t), (d,) for a float t or (B, d) for (B,) times."""
    times = np.asarray(t, dtype=float)
    value = np.zeros(times.shape + (function.size,))
    power = np.ones_like(times)
    for coefficient in function.polynomial:  # c_0 + c_1 t + ...: powers built by products, t^k exact for k <= 1
        value += power[..., None] * coefficient
        power = power * times
    for sinusoid in function.sinusoids:
        value += np.sin(2 * np.pi * sinusoid.frequency_hz * times + sinusoid.phase_rad)[..., None] * sinusoid.amplitude
    return value


def held_value(function: HeldFunction, t: float | np.ndarray, step_start: float | np.ndarray) -> np.ndarray:
    """The hold at stage time ``t`` of the step starting at ``step_start`` (module docstring): (d,) or (B, d)."""
    times = np.asarray(t, dtype=float)
    periods = (times - function.phase_s) / function.period_s
    right = np.floor(periods + ON_INSTANT)  # the sample in force at t
    left = np.ceil(periods - ON_INSTANT) - 1  # the sample in force just before t
    index = np.where(times > np.asarray(step_start, dtype=float), left, right).astype(int)
    last = len(function.samples) - 1
    value = function.samples[np.clip(index, 0, last)]
    return np.where((index < 0)[..., None], 0.0, value)


def value_in_step(function: TimeFunction, t: float | np.ndarray, step_start: float | np.ndarray) -> np.ndarray:
    """``function`` at stage time ``t`` [s] of the step that starts at ``step_start`` [s]."""
    if isinstance(function, SmoothFunction):
        return smooth_value(function, t)
    return held_value(function, t, step_start)


def load_world(load: TimedLoad, t, step_start, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The load's (force_world, torque_world about the COM), each (3,) or (B, 3) with ``t``, for the body's rotation
    (3, 3) (or (B, 3, 3)): body-axes values turned by R, the force's torque (R point) x F."""
    zero = np.zeros(np.shape(t) + (3,))
    force = zero if load.force is None else value_in_step(load.force, t, step_start)
    torque = zero if load.torque is None else value_in_step(load.torque, t, step_start)
    if load.frame == BODY:
        force, torque = rotation @ force[..., None], rotation @ torque[..., None]
        force, torque = force[..., 0], torque[..., 0]
    lever = rotation @ load.point_body
    return force, torque + np.cross(lever, force)
