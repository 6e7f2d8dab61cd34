"""Loads that change with time, evaluated by the references themselves from the scene's fields.

Written independently of ``core.dynamics.time_loads`` (a reference must not borrow the code it checks): the
polynomial by Horner's rule (NumPy's ``polyval``), a hold's sample by a sorted search of its instants. The
convention is the scene model's (``core.model.scenes.time_functions``): a hold is 0 before its first instant and
holds each sample from its instant to the next; seen from inside a step [t0, t0 + dt], a stage at t0 takes the value
at t0, a later stage the value just before its time (:func:`held_in_step`).
"""

from __future__ import annotations

import numpy as np
from numpy.polynomial import polynomial

from simparity.core.model.scenes.time_functions import BODY, HeldFunction, SmoothFunction, TimedLoad, TimeFunction

INSTANT_TOLERANCE = 1e-9
"""[control periods] A time this close to a sample instant is on it: step times (sums of dt) and instants
(phase + k period) round differently by ~1e-16 relative, and stage times are simple fractions of dt away from an
instant they are not on."""


def smooth_at(function: SmoothFunction, t: float) -> np.ndarray:
    """f(t) (d,) of a smooth function at one time t [s]."""
    value = polynomial.polyval(t, function.polynomial) if len(function.polynomial) else np.zeros(function.size)
    for term in function.sinusoids:
        value = value + term.amplitude * np.sin(2.0 * np.pi * term.frequency_hz * t + term.phase_rad)
    return np.asarray(value, dtype=float)


def _instants(function: HeldFunction) -> np.ndarray:
    return function.phase_s + function.period_s * np.arange(len(function.samples))


def held_at(function: HeldFunction, t: float, before: bool = False) -> np.ndarray:
    """The hold's value at t [s] (d,), or just before t when ``before``."""
    slack = INSTANT_TOLERANCE * function.period_s
    instants = _instants(function)
    # the number of instants passed: those <= t (at t itself), or < t (just before it), within the slack
    count = (np.searchsorted(instants, t - slack, side="left") if before
             else np.searchsorted(instants, t + slack, side="right"))
    return np.zeros(function.size) if count == 0 else function.samples[count - 1].astype(float)


def held_in_step(function: HeldFunction, t: float, step_start: float) -> np.ndarray:
    """The hold as a stage at time t of the step starting at ``step_start`` sees it (module docstring)."""
    return held_at(function, t, before=t > step_start)


def at(function: TimeFunction, t: float, step_start: float | None = None) -> np.ndarray:
    """``function`` at time t [s]: a stage's of the step starting at ``step_start``, or (None) the value at t."""
    if isinstance(function, SmoothFunction):
        return smooth_at(function, t)
    return held_in_step(function, t, t if step_start is None else step_start)


def load_world(load: TimedLoad, t: float, rotation_world: np.ndarray,
               step_start: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(force_world (3,) [N], torque_world (3,) [N m]) of one load at time t on a body whose rotation (body to world)
    is ``rotation_world`` (3, 3): body-axes values turned into the world; the torque without the force's moment."""
    rotation = np.asarray(rotation_world, dtype=float)
    force = at(load.force, t, step_start) if load.force is not None else np.zeros(3)
    torque = at(load.torque, t, step_start) if load.torque is not None else np.zeros(3)
    if load.frame == BODY:
        force, torque = rotation @ force, rotation @ torque
    return force, torque


def load_wrench_world(load: TimedLoad, t: float, rotation_world: np.ndarray,
                      step_start: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """As :func:`load_world`, with the torque about the COM including the force's moment (R point) x F."""
    force, torque = load_world(load, t, rotation_world, step_start)
    return force, torque + np.cross(np.asarray(rotation_world, dtype=float) @ load.point_body, force)


def jump_times(functions, duration: float) -> np.ndarray:
    """The sorted sample instants of the holds among ``functions`` inside (0, duration): where a solver must stop
    and restart (the load jumps there)."""
    instants = [_instants(f) for f in functions if isinstance(f, HeldFunction)]
    if not instants:
        return np.zeros(0)
    every = np.unique(np.concatenate(instants))
    return every[(every > 0) & (every < duration)]
