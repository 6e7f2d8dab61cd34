"""Finite differences of inverse dynamics as users take them (issue #44): the partials ∂τ/∂q and ∂τ/∂q̇ of any
engine's batched inverse dynamics by forward or centred differences, and their error against a truth across step
sizes (the V of truncation falling with the step and rounding rising as ε |τ| / h).

A judge's tool: it calls the function it is given (an engine's own inverse dynamics, or the truth's own RNEA in real
arithmetic to learn what a declared scheme's truncation is at its step) and imports nothing but NumPy.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

InverseDynamics = Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]
"""τ = f(q, q̇, q̈), each (K, n) [SI], batched over K states (a floating base: q (K, 7 + n), the others (K, 6 + n))."""
Retraction = Callable[[np.ndarray, np.ndarray], np.ndarray]
"""q ⊕ δ: configurations (K, nq) moved by tangent steps (K, nv)."""

SWEEP_STEPS = 10.0 ** np.arange(-1.0, -13.01, -0.5)
"""[rad or m] The steps of the sweep, half a decade apart from 1e-1 to 1e-13: past both ends of the V of any scheme
in float64 (forward differences are best near sqrt(ε) ~ 1e-8, centred near ε^(1/3) ~ 6e-6)."""
SWEEP_STATES = 4
"""States of a scene the sweep differences at (its first ones): the V's shape is the same at every state, and four
keep the sweep at ~2 x 25 x 4 n evaluations of an engine's inverse dynamics."""
_WITH_RESPECT_TO = {"q": 0, "qdot": 1}


def additive(q: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """q + δ: the retraction of a fixed base's joint values."""
    return q + delta


def floating_retraction(q: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """q ⊕ δ of floating-base configurations (K, 7 + n) by tangent steps (K, 6 + n) in the project's chart: the base
    moved by δp and turned by exp([δθ]x) in world axes (its quat_wxyz multiplied on the left), the joints added."""
    turn = delta[:, 3:6]
    angle = np.sqrt(np.sum(turn**2, axis=1))
    half = 0.5 * angle
    scale = np.where(angle > 0, np.sin(half) / np.where(angle > 0, angle, 1.0), 0.5)
    w1, v1 = np.cos(half), scale[:, None] * turn
    w2, v2 = q[:, 3], q[:, 4:7]
    quat = np.concatenate([(w1 * w2 - np.sum(v1 * v2, axis=1))[:, None],
                           w1[:, None] * v2 + w2[:, None] * v1 + np.cross(v1, v2)], axis=1)
    return np.concatenate([q[:, :3] + delta[:, :3], quat, q[:, 7:] + delta[:, 6:]], axis=1)


def difference_partial(inverse_dynamics: InverseDynamics, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray,
                       wrt: str, step: np.ndarray, centred: bool, retract: Retraction = additive) -> np.ndarray:
    """∂τ/∂``wrt`` ("q" or "qdot") at B states (q (B, nq), the others (B, nv)), (B, nv, nv) with column j the
    difference along tangent (or velocity) entry j, at step ``step`` (B,) per state: (f(x ⊕ h e_j) - f(x)) / h, or
    (f(x ⊕ h e_j) - f(x ⊕ -h e_j)) / 2h when ``centred``; q moved by ``retract`` (:func:`floating_retraction` for a
    floating base). Dividing by h (not by the representable difference) is what users write."""
    count, n = qdot.shape
    h = np.broadcast_to(np.asarray(step, dtype=float), (count,))
    offsets = (h[:, None, None] * np.eye(n)).reshape(count * n, n)
    base = [np.repeat(x, n, axis=0) for x in (q, qdot, qddot)]
    which = _WITH_RESPECT_TO[wrt]

    def at(sign: float) -> np.ndarray:
        moved = list(base)
        moved[which] = retract(base[0], sign * offsets) if which == 0 else base[which] + sign * offsets
        return np.asarray(inverse_dynamics(*moved), dtype=float)

    if centred:
        rise, run = at(1.0) - at(-1.0), 2.0 * np.repeat(h, n)
    else:
        rise, run = at(1.0) - np.repeat(np.asarray(inverse_dynamics(q, qdot, qddot), dtype=float), n, axis=0), \
            np.repeat(h, n)
    return (rise / run[:, None]).reshape(count, n, n).transpose(0, 2, 1)


@dataclass(frozen=True)
class StepSweep:
    """The relative error of ∂τ/∂q by differences of an engine's inverse dynamics, at every step of ``steps``.

    Attributes
    ----------
    steps : (K,) ndarray
        [rad or m] The steps, largest first.
    forward, central : (K,) ndarray
        max |D - T| over the floored max |T| (1) at each step; NaN where the engine returned non-finite values.
    """

    steps: np.ndarray
    forward: np.ndarray
    central: np.ndarray

    def best(self, centred: bool) -> tuple[float, float]:
        """(the step of the smallest error, that error) of the centred or forward differences; (NaN, NaN) when no
        step gave a finite error."""
        errors = self.central if centred else self.forward
        if not np.any(np.isfinite(errors)):
            return float("nan"), float("nan")
        k = int(np.nanargmin(errors))
        return float(self.steps[k]), float(errors[k])


def step_sweep(inverse_dynamics: InverseDynamics, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray,
               truth_dtau_dq: np.ndarray, floor: float, steps: np.ndarray = SWEEP_STEPS,
               retract: Retraction = additive) -> StepSweep:
    """Both schemes' errors of ∂τ/∂q at every step, against ``truth_dtau_dq`` (B, nv, nv) at the same B states (q
    moved by ``retract``), relative to its largest entry floored at ``floor`` [N m / rad or N / m] (the chain's force
    floor)."""
    scale = max(float(np.max(np.abs(truth_dtau_dq))), floor)
    errors = {}
    for centred in (False, True):
        errors[centred] = np.array([
            float(np.max(np.abs(difference_partial(inverse_dynamics, q, qdot, qddot, "q", np.full(len(q), h), centred,
                                                   retract) - truth_dtau_dq))) / scale for h in steps])
    errors = {k: np.where(np.isfinite(v), v, np.nan) for k, v in errors.items()}
    return StepSweep(np.asarray(steps, dtype=float), errors[False], errors[True])


def difference_map(function: Callable[[np.ndarray, np.ndarray], np.ndarray], x: np.ndarray, step: np.ndarray,
                   centred: bool) -> np.ndarray:
    """∂f/∂x of a batched map f(points (K, m), owner (K,)) -> (K, p), ``owner`` the index of the point of ``x`` each
    row was moved from, at B points x (B, m): (B, p, m), column j by forward (or centred) differences along entry j
    at each point's step (B,)."""
    count, m = x.shape
    offsets = (np.asarray(step, dtype=float)[:, None, None] * np.eye(m)).reshape(count * m, m)
    owner = np.repeat(np.arange(count), m)
    base = x[owner]
    up = np.asarray(function(base + offsets, owner), dtype=float)
    down = (np.asarray(function(base - offsets, owner), dtype=float) if centred
            else np.asarray(function(x, np.arange(count)), dtype=float)[owner])
    run = np.repeat(np.asarray(step, dtype=float), m) * (2.0 if centred else 1.0)
    return ((up - down) / run[:, None]).reshape(count, m, -1).transpose(0, 2, 1)
