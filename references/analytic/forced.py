"""Closed forms of bodies driven by loads that change with time (``core.model.scenes.time_functions``), written from
the calculus, sharing no code with core.

A load f(t) enters the motion through its first and second time integrals, F1(t) = int_0^t f and
F2(t) = int_0^t F1, each exact:

- a polynomial sum_k c_k t^k: F1 = sum_k c_k t^(k+1) / (k+1), F2 = sum_k c_k t^(k+2) / ((k+1)(k+2));
- a sinusoid A sin(w t + phi), w = 2 pi f > 0: F1 = A (cos(phi) - cos(w t + phi)) / w,
  F2 = A (t cos(phi) / w - (sin(w t + phi) - sin(phi)) / w^2); at f = 0 the constant A sin(phi);
- a zero-order hold, value s_k on [t_k, t_k+1) (0 before t_0): each piece adds s_k clip(t - t_k, 0, T_k) to F1
  and s_k g(t) to F2, with g = (t - t_k)^2 / 2 inside the piece and T_k^2 / 2 + T_k (t - t_k+1) after it.

Then a body whose forces are world-axes loads through nothing but their sum moves as x(t) = x0 + v0 t + g t^2 / 2 +
F2(t) / m, v(t) = v0 + g t + F1(t) / m; a body turning about a fixed principal axis n (moment I_n) under torques
along n turns by theta(t) = |omega0| t + n.T2(t) / I_n with omega(t) = omega0 + n n.T1(t) / I_n.
"""

from __future__ import annotations

import numpy as np

from simparity.core.model.scenes.time_functions import HeldFunction, SmoothFunction, TimeFunction


def _smooth_integrals(function: SmoothFunction, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    first = np.zeros((len(t), function.size))
    second = np.zeros((len(t), function.size))
    for k, coefficient in enumerate(function.polynomial):
        first += np.outer(t ** (k + 1) / (k + 1), coefficient)
        second += np.outer(t ** (k + 2) / ((k + 1) * (k + 2)), coefficient)
    for term in function.sinusoids:
        w, phi = 2.0 * np.pi * term.frequency_hz, term.phase_rad
        if w == 0.0:
            first += np.outer(t * np.sin(phi), term.amplitude)
            second += np.outer(t * t / 2.0 * np.sin(phi), term.amplitude)
            continue
        first += np.outer((np.cos(phi) - np.cos(w * t + phi)) / w, term.amplitude)
        second += np.outer(t * np.cos(phi) / w - (np.sin(w * t + phi) - np.sin(phi)) / (w * w), term.amplitude)
    return first, second


def _held_integrals(function: HeldFunction, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    first = np.zeros((len(t), function.size))
    second = np.zeros((len(t), function.size))
    starts = function.phase_s + function.period_s * np.arange(len(function.samples))
    ends = np.append(starts[1:], np.inf)
    for start, end, value in zip(starts, ends, function.samples):
        inside = np.clip(t - start, 0.0, end - start)
        first += np.outer(inside, value)
        length = end - start
        after = t > end
        area = np.where(after, length * length / 2.0 + length * (t - end) if np.isfinite(length) else 0.0,
                        inside * inside / 2.0)
        second += np.outer(area, value)
    return first, second


def integrals(function: TimeFunction, times) -> tuple[np.ndarray, np.ndarray]:
    """(F1, F2), each (T, d): the first and second integrals from 0 of ``function`` at ``times`` (T,) [s]."""
    t = np.asarray(times, dtype=float)
    if isinstance(function, SmoothFunction):
        return _smooth_integrals(function, t)
    return _held_integrals(function, t)


def forced_translation(position0, velocity0, gravity, mass: float, forces: list[TimeFunction],
                       times) -> tuple[np.ndarray, np.ndarray]:
    """(x (T, 3), v (T, 3)) of a body under gravity and world-axes forces that change with time."""
    t = np.asarray(times, dtype=float)[:, None]
    x = np.asarray(position0, float) + np.asarray(velocity0, float) * t + 0.5 * np.asarray(gravity, float) * t * t
    v = np.asarray(velocity0, float) + np.asarray(gravity, float) * t
    for force in forces:
        first, second = integrals(force, times)
        x, v = x + second / mass, v + first / mass
    return x, v


def fixed_axis_rotation(axis_world: np.ndarray, moment: float, omega0_world: np.ndarray,
                        torques: list[tuple[TimeFunction, np.ndarray]], times) -> tuple[np.ndarray, np.ndarray]:
    """(theta (T,) [rad] about ``axis_world`` from the start, omega_world (T, 3)) of a body turning about a fixed
    principal axis (unit, world axes) of moment ``moment`` [kg m^2] under torques along it, each given with that axis
    in its own axes (the world's, or the body's: the axis is fixed in both)."""
    n = np.asarray(axis_world, dtype=float)
    t = np.asarray(times, dtype=float)
    spin0 = float(n @ omega0_world)
    theta, spin = spin0 * t, np.full(len(t), spin0)
    for torque, axis in torques:
        first, second = integrals(torque, times)
        theta, spin = theta + (second @ axis) / moment, spin + (first @ axis) / moment
    return theta, spin[:, None] * n


_SERIES_BELOW = 1e-2
"""Below this k t the damped ramp x + expm1(-x) is summed as its series (the difference would cancel)."""


def _ramp(x: np.ndarray) -> np.ndarray:
    """x - (1 - exp(-x)) for x >= 0, accurate near 0 (x^2 / 2 - x^3 / 6 + x^4 / 24 - x^5 / 120 there)."""
    small = x < _SERIES_BELOW
    series = x * x * (0.5 - x * (1 / 6 - x * (1 / 24 - x / 120)))
    return np.where(small, series, x + np.expm1(-np.where(small, 1.0, x)))


def _damped_step(k: float, inertia: float, elapsed: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(q, qdot) of I q'' = H(t - a) - b q' from rest, k = b / I > 0, at ``elapsed`` = max(t - a, 0) [s]."""
    kt = k * elapsed
    return _ramp(kt) / (k * k * inertia), -np.expm1(-kt) / (k * inertia)


def _damped_sinusoid(k: float, inertia: float, amplitude: float, frequency_hz: float, phase: float,
                     t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(q, qdot) of I q'' = A sin(w t + phi) - b q' from rest: the steady state plus the transient that cancels its
    start, v = v_p(t) - v_p(0) exp(-k t), v_p = A / I (k sin(w t + phi) - w cos(w t + phi)) / (k^2 + w^2)."""
    w = 2.0 * np.pi * frequency_hz
    scale = amplitude / (inertia * (k * k + w * w))
    v_p0 = scale * (k * np.sin(phi := phase) - w * np.cos(phi))
    qdot = scale * (k * np.sin(w * t + phi) - w * np.cos(w * t + phi)) - v_p0 * np.exp(-k * t)
    q = scale * (-k * (np.cos(w * t + phi) - np.cos(phi)) / w - (np.sin(w * t + phi) - np.sin(phi))) \
        + v_p0 * np.expm1(-k * t) / k
    return q, qdot


def damped_drive_supported(function: TimeFunction | None) -> str:
    """"" when :func:`driven_joint` has the closed form of a damped joint driven by ``function``, else why not."""
    if isinstance(function, SmoothFunction) and len(function.polynomial) > 1 and np.any(function.polynomial[1:]):
        return "no closed form here for a damped joint driven by a polynomial in t of degree 1 or more"
    if isinstance(function, SmoothFunction) and any(s.frequency_hz == 0 for s in function.sinusoids):
        return "a sinusoid of frequency 0 is a constant: give it as the polynomial's c_0"
    return ""


def driven_joint(q0: float, qdot0: float, inertia: float, damping: float, force: float,
                 function: TimeFunction | None, times) -> tuple[np.ndarray, np.ndarray]:
    """(q, qdot) (T,) of one joint, I q'' = f + tau(t) - b q', from (q0, qdot0): the free response plus each term's
    response from rest (the equation is linear). Without damping every time function integrates exactly
    (:func:`integrals`); with damping, constants, sinusoids and holds (a step up at each sample instant and down at
    the next) do (:func:`damped_drive_supported`)."""
    t = np.asarray(times, dtype=float)
    if damping == 0:
        q, qdot = q0 + qdot0 * t + force * t * t / (2 * inertia), qdot0 + force * t / inertia
        if function is not None:
            first, second = integrals(function, t)
            q, qdot = q + second[:, 0] / inertia, qdot + first[:, 0] / inertia
        return q, qdot
    k = damping / inertia
    q, qdot = q0 - qdot0 * np.expm1(-k * t) / k, qdot0 * np.exp(-k * t)
    steps = [(force, 0.0)]  # (height, instant) of each step input
    if isinstance(function, HeldFunction):
        instants = function.phase_s + function.period_s * np.arange(len(function.samples))
        previous = 0.0
        for instant, value in zip(instants, function.samples[:, 0]):
            steps.append((value - previous, instant))
            previous = value
    elif isinstance(function, SmoothFunction):
        steps.append((float(function.polynomial[0, 0]) if len(function.polynomial) else 0.0, 0.0))
        for term in function.sinusoids:
            dq, dv = _damped_sinusoid(k, inertia, float(term.amplitude[0]), term.frequency_hz, term.phase_rad, t)
            q, qdot = q + dq, qdot + dv
    for height, instant in steps:
        if height:
            dq, dv = _damped_step(k, inertia, np.maximum(t - instant, 0.0))
            q, qdot = q + height * dq, qdot + height * dv
    return q, qdot
