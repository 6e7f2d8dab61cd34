"""When a body first reaches a plane within a step: the contact search of the backup method.

Two searches over n bodies with per-body horizons, each on a free flight ``flight(t, state, duration)``
(with ``.bodies``, ``.wrench`` and ``.take(idx)``, :class:`core.contact.backup._Flight`):

- :func:`exact_contact`: the entering root of E(s) = E0 + (u.N) s + (a.N) s^2 / 2
  (:func:`core.contact.particle.entry_time`), exact for a body whose contact points move with its COM under a
  constant force (a point, a sphere, a body that does not turn);
- :func:`root_contact`: a bracketed root finder on f(s) = min over points of E + delta
  (:data:`ROOT_OFFSET_RTOL` of the body's size) along the flight. The bracket ends at the end of the horizon
  if a point is inside
  there, else at the minimum of the points' cubic Hermite interpolants of E (from E and u.N at both ends)
  if a flight confirms it: this catches a corner that dips in and out within one step. Each iterate is
  the first root of the Hermite cubic of the point inside at the upper end, or the bracket's middle when
  an end has been kept twice in a row.
"""

from __future__ import annotations

import numpy as np

from simparity.core.contact.particle import entry_time
from simparity.core.contact.bodies import Bodies, take_state
from simparity.core.dynamics.rigid_body import State, velocities

ROOT_OFFSET_RTOL = 1e-11
"""delta, relative to the body's size: the root finder looks for the first instant a point is delta inside a
plane (to within delta / 2), so that a point that has just bounced (E = 0, moving out) is not found again at
once; the body is pushed back out after the response. 1e-12 m for a decimetre body, ~1e5 ulp of positions of
order 1 m; relative to the size, so that the scene's length unit does not change where the root is found
(an absolute delta moved core's back-up trajectories by 1e-8 m when the scene was rescaled)."""

ROOT_TIME_TOLERANCE = 1e-13
"""Relative to the sub-step: a narrower bracket is taken as converged (~500 ulp)."""

MAX_ROOT_ITERATIONS = 100
"""Root-finder iterations at most; from a step-wide bracket down to delta it takes 2-6 (measured on 1000
tumbling boxes)."""

HERMITE_SAMPLES = 16
"""Interior instants at which each point's Hermite interpolant of E is checked for a dip within the step."""

CUBIC_BISECTIONS = 60
"""Bisections of a Hermite cubic's root within one of its sample intervals: 2^-60 of it is below roundoff."""


def distances(bodies: Bodies, state: State, resting: np.ndarray):
    """Levers (n, P, V, 3) [m], distances E (n, P, V) [m] (+inf on the plane a body rests on), u.N (n, P, V)."""
    rotation = state.rotation_world
    lever, distance = bodies.model.points(state.position_world, rotation)
    own = np.arange(distance.shape[1])[None, :] == resting[:, None]
    v, omega = velocities(state, bodies.props, rotation)
    return lever, np.where(own[:, :, None], np.inf, distance), bodies.model.normal_speeds(v, omega, lever)


ROUNDING_SPEED_RTOL = 1e-12
"""A normal speed within this fraction of the body's speed (plus what the step's acceleration adds) is rounding:
a body placed on a tilted plane starts at E ~ -1e-17 m with u . N ~ +1e-16 m/s, and must count as touching now
(it is pushed in by gravity), not as leaving the plane for a whole step of free fall."""


def exact_contact(flight, t: float, state: State, distance: np.ndarray, horizon: np.ndarray) -> np.ndarray:
    """First contact of bodies whose points move on parabolas: time (n,) [s], inf if none within the horizon."""
    rotation = state.rotation_world
    v, omega = velocities(state, flight.bodies.props, rotation)
    force, _ = flight.wrench(t, state.position_world, rotation, v, omega)
    normals = flight.bodies.model.normals
    u, a = v @ normals.T, (force / flight.bodies.props.mass[:, None]) @ normals.T
    e0 = distance.min(axis=2)
    candidate = np.isfinite(e0)
    e0 = np.where(candidate, e0, 1.0)
    hit, s = entry_time(e0, u, a / 2.0, horizon[:, None])
    speed_rounding = ROUNDING_SPEED_RTOL * (np.linalg.norm(v, axis=1)[:, None] + np.abs(a) * horizon[:, None])
    now = (e0 <= 0.0) & ((u < 0.0) | ((u <= speed_rounding) & (a < 0.0)))
    return np.where(candidate & now, 0.0, np.where(candidate & hit, s, np.inf)).min(axis=1)


def _hermite(g0, rate0, g1, rate1, span):
    """Cubic Hermite interpolants of E + delta on [0, span] at :data:`HERMITE_SAMPLES` interior instants.

    g0, rate0, g1, rate1 (n, M) [m], [m/s]; span (n,) [s]. Returns the fractions theta (samples,) and the
    values (n, M, samples) [m].
    """
    theta = np.arange(1, HERMITE_SAMPLES + 1) / (HERMITE_SAMPLES + 1.0)
    basis = (2 * theta**3 - 3 * theta**2 + 1, theta**3 - 2 * theta**2 + theta, -2 * theta**3 + 3 * theta**2,
             theta**3 - theta**2)
    h = span[:, None]
    return theta, sum(b * e[..., None] for b, e in zip(basis, (g0, h * rate0, g1, h * rate1)))


def _first_root(g0, rate0, g1, rate1, span):
    """Fraction theta in (0, 1] (n,) where the cubic Hermite interpolant of one point's E + delta first crosses
    zero going in (g0 > 0 > g1): the sign change among :data:`HERMITE_SAMPLES` nodes, then bisection of the
    cubic itself (cheap: no flight) down to roundoff."""
    c = (g0, span * rate0, 3.0 * (g1 - g0) - span * (2.0 * rate0 + rate1), 2.0 * (g0 - g1) + span * (rate0 + rate1))

    def cubic(x):
        return c[0] + x * (c[1] + x * (c[2] + x * c[3]))

    nodes = np.linspace(0.0, 1.0, HERMITE_SAMPLES + 2)
    below = cubic(nodes[:, None]) < 0.0  # (nodes, n); the last node is g1 < 0
    first = np.argmax(below, axis=0)
    lo, hi = nodes[np.maximum(first - 1, 0)], nodes[first]
    for _ in range(CUBIC_BISECTIONS):
        mid = 0.5 * (lo + hi)
        inside = cubic(mid) < 0.0
        lo, hi = np.where(inside, lo, mid), np.where(inside, mid, hi)
    return hi


def root_contact(flight, t: float, state: State, resting, distance, speed, horizon) -> np.ndarray:
    """First contact of turning bodies, by bracketing and Hermite-guided bisection: time (n,) [s], inf if none.

    Bracketed by f = min over points of E + delta (f >= 0 at the lower end, < 0 at the upper one); each
    iterate is where the cubic Hermite interpolant (E and u.N at both ends) of the point inside at the upper
    end first crosses zero, or the bracket's middle when an end has been kept twice in a row.
    """
    def g(fl, st, rest, s):
        """E + delta of every point (n, P V) [m] after flying s (n,) [s], and their rates u.N (n, P V)."""
        _, dist, spd = distances(fl.bodies, fl(t, st, s), rest)
        dist = dist.reshape(len(s), -1)
        delta_fl = ROOT_OFFSET_RTOL * fl.bodies.size[:, None]
        return np.where(np.isfinite(dist), dist + delta_fl, 1.0), spd.reshape(len(s), -1)

    n = len(horizon)
    delta = ROOT_OFFSET_RTOL * flight.bodies.size[:, None]  # (n, 1) [m]
    time = np.full(n, np.inf)
    start = distance.reshape(n, -1)
    g0, rate0 = np.where(np.isfinite(start), start + delta, 1.0), speed.reshape(n, -1)
    f0 = g0.min(axis=1)
    time[f0 <= 0.0] = 0.0
    g_end, rate_end = g(flight, state, resting, np.where(f0 > 0.0, horizon, 0.0))
    inside = (f0 > 0.0) & (g_end.min(axis=1) < 0.0)
    hi, g_hi, r_hi = np.where(inside, horizon, np.nan), g_end, rate_end
    # The Hermite cubic is >= min(g0, g1) - 4/27 span (|rate0| + |rate1|): only bodies below that bound can dip.
    bound = np.minimum(g0, g_end) - 4.0 / 27.0 * horizon[:, None] * (np.abs(rate0) + np.abs(rate_end))
    maybe = np.flatnonzero((f0 > 0.0) & ~inside & (bound.min(axis=1) < 0.0))
    dip, probe = np.zeros(n, dtype=bool), np.zeros(n)
    if len(maybe):
        theta, curve = _hermite(g0[maybe], rate0[maybe], g_end[maybe], rate_end[maybe], horizon[maybe])
        curve = curve.min(axis=1)  # (bodies, samples)
        dip[maybe] = curve.min(axis=1) < 0.0
        probe[maybe] = theta[np.argmin(curve, axis=1)] * horizon[maybe]
    if dip.any():
        probe = np.where(dip, probe, 0.0)
        g_probe, r_probe = g(flight, state, resting, probe)
        found = (dip & (g_probe.min(axis=1) < 0.0))[:, None]
        hi = np.where(found[:, 0], probe, hi)
        g_hi, r_hi = np.where(found, g_probe, g_hi), np.where(found, r_probe, r_hi)
    idx = np.flatnonzero(~np.isnan(hi))
    if not len(idx):
        return time
    fl, st, rest = flight.take(idx), take_state(state, idx), resting[idx]
    lo, g_lo, r_lo = np.zeros(len(idx)), g0[idx], rate0[idx]
    hi, g_hi, r_hi = hi[idx], g_hi[idx], r_hi[idx]
    side, kept = np.zeros(len(idx), dtype=int), np.zeros(len(idx), dtype=bool)
    width = ROOT_TIME_TOLERANCE * horizon[idx]
    half = 0.5 * delta[idx, 0]
    for _ in range(MAX_ROOT_ITERATIONS):
        work = (g_lo.min(axis=1) > half) & (g_hi.min(axis=1) < -half) & (hi - lo > width)
        if not work.any():
            break
        point = g_hi.argmin(axis=1)[:, None]
        g0_p, r0_p, g1_p, r1_p = (np.take_along_axis(a, point, axis=1)[:, 0] for a in (g_lo, r_lo, g_hi, r_hi))
        fraction = _first_root(g0_p, r0_p, g1_p, r1_p, hi - lo)
        s = np.where(kept, 0.5 * (lo + hi), lo + fraction * (hi - lo))
        s = np.where((s > lo) & (s < hi), s, 0.5 * (lo + hi))
        g_s, r_s = g(fl, st, rest, np.where(work, s, 0.0))
        right = work & (g_s.min(axis=1) < 0.0)
        left = work & ~right
        kept = (right & (side == 1)) | (left & (side == -1))
        hi, g_hi, r_hi = (np.where(right, s, hi), np.where(right[:, None], g_s, g_hi),
                          np.where(right[:, None], r_s, r_hi))
        lo, g_lo, r_lo = np.where(left, s, lo), np.where(left[:, None], g_s, g_lo), np.where(left[:, None], r_s, r_lo)
        side = np.where(right, 1, np.where(left, -1, side))
    time[idx] = np.where(g_hi.min(axis=1) >= -half, hi, lo)
    return time
