"""Core's rigid contact of a fixed-base chain's spheres with a plane: the lecture's impulses, time backed up to the
instant of contact, carried to a chain through the contact-space inverse inertia j^T M^-1 j.

Each step of the scene's scheme is taken from its start (:mod:`core.articulated.stepping`). Where a sphere that was
off the plane ends the step inside it, time is backed up to the instant it touches (the lecture's "backing up time"):
the first root of s -> min over the spheres of gap(step of s h from the start), s in [0, 1], each trial the scheme's
own state at t + s h, found by Brent's method to :data:`TIME_RTOL` of the step; the chain is stepped there, responds,
and steps the rest of the step (several events in one step in time order, at most :data:`MAX_EVENTS_PER_STEP`). A
sphere on or inside the plane at a step's start and moving in responds at once; one leaving it (just bounced, at a
gap of rounding) is followed until it clears the plane (:data:`CLEARING`), so that its return within the same step
is found: on a chain the other joints can bring a bounced sphere straight back.

The response is Newton's impulse at the touching sphere: with N the plane's normal, j = J^T N (J the Jacobian of the
sphere's centre) and v_n = j . qdot its normal velocity (< 0: approaching),

    qdot+ = qdot - (1 + e) v_n M^-1 j / (j^T M^-1 j),

which makes its normal velocity -e v_n, leaves every motion that does not move the sphere along N alone, and takes
(1 - e^2) v_n^2 / (2 j^T M^-1 j) of kinetic energy (the contact-space mass 1 / (j^T M^-1 j) meeting an immovable
plane). A rebound slower than the scene's ``rest_speed`` is plastic (e = 0) and the sphere then rests on the plane:
every evaluation of the accelerations adds the plane's force lambda j with

    lambda = max(0, -(j . a + N . (dJ/dt qdot)) / (j^T M^-1 j))   (a the accelerations without it),

the force that keeps its normal acceleration zero while the plane pushes (the lecture's resting contact force, for
one contact; M the scheme's own, armature + dt D under implicit damping). The stages keep its normal acceleration zero,
not its gap and normal velocity at the step's end: semi-implicit Euler's drift let a pressed arm's sphere sink 1.5
radii in 2 s, and both are restored at each step's end (below). The sphere leaves the
plane where the plane would have to pull: where, at a step's last evaluation of the accelerations, lambda's unclipped
value is <= 0, time is backed up to the instant lambda falls to 0 (the first root of s -> lambda at the held step of
s h, to :data:`TIME_RTOL` of the step), the sphere released there and the rest of the step taken free (a release
found at the step's end would leave the scheme first order there: the held force switches off inside its stages). At each step's end a resting sphere is put back on the plane
(Newton steps along M^-1 j remove its gap) and its normal velocity removed (:meth:`RigidContact._held`).

One contact at a time: two spheres striking at once, or one striking while another rests, couple their impulses
through M^-1 and need a complementarity solver (PGS or similar), beyond the lecture; core raises
:class:`core.model.errors.ContactError` there (its rows n/a, saying so). More than :data:`MAX_EVENTS_PER_STEP` events
in a step is a failure of the run. A floating
base is not carried (its Jacobian and M have the base's six rows): the in-house engine declines those scenes.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from simparity.core.articulated import stepping
from simparity.core.articulated.chain_arrays import chain_arrays
from simparity.core.articulated.chain_contact import ChainContactForces
from simparity.core.articulated.recursive import Recursive
from simparity.core.dynamics.time_loads import value_in_step
from simparity.core.model.errors import ContactError, SimparityError
from simparity.core.model.scenes.joint_motion import JointMotionScene

TIME_RTOL = 1e-13
"""[1] The backed-up instant of contact is found to this fraction of the step (Brent's xtol): its error moves the
impact by |v| dt TIME_RTOL, below the rounding of a 1 m scene for dt <= 1e-2 s."""
MAX_EVENTS_PER_STEP = 100
"""Contact events one copy may have in one step; past it the run fails (a rebound faster
than ``rest_speed`` takes a finite time to come back: only a scene whose rest speed is far below what one step can
resolve gets near it)."""
FREE = -1
"""The resting sphere of a copy that rests on none."""
PROJECTIONS = 3
"""Newton steps that put a resting sphere back on the plane at a step's end: quadratic, so a gap of 1e-3 of the
sphere's reach (a fast-sliding arm's drift in one step) falls to ~1e-12 and then to rounding."""
CLEARING = (1e-12, 1e-9, 1e-6, 1e-3, 0.1, 0.5)
"""Fractions of a step tried, in turn, for the first at which a sphere leaving the plane (one just bounced, at a gap of
rounding) is above it: the lower end of the bracket of its return within the step."""


class RigidContact:
    """The rigid contact of a fixed-base scene under one scheme: its steps, impacts and resting forces, batched over
    copies (each copy's events handled in turn). States are the stepping layout: q (n, B), qdot (n, B)."""

    def __init__(self, scene: JointMotionScene, scheme: str) -> None:
        contact = scene.contact
        if contact is None or not contact.rigid or scene.chain.floating_base:
            raise ValueError("RigidContact needs a fixed-base scene with a rigid contact")
        self._scene, self._contact = scene, contact
        self._spheres = ChainContactForces(scene.chain, contact)
        self._sized = stepping.sized_stepper(scene, scheme, self._constraint)
        gravity = np.zeros(3) if scene.gravity_world is None else np.asarray(scene.gravity_world, dtype=float)
        self._dynamics = Recursive(chain_arrays(scene.chain), gravity)
        self._unforced = Recursive(chain_arrays(scene.chain), np.zeros(3))
        self.resting = np.full(scene.copies, FREE)
        """(B,) the sphere each copy rests on, :data:`FREE` for none."""
        self._unclipped = np.zeros(scene.copies)
        self._active: np.ndarray | slice = slice(None)  # the copies the constraint is evaluated for

    def gaps(self, q: np.ndarray) -> np.ndarray:
        """(B, S) [m] each sphere's distance from the plane at q (n, B) (negative: inside)."""
        return self._contact.gaps(self._spheres.centres_world(q))

    def normal_velocities(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(B, S) [m/s] each sphere's velocity along the plane's normal (negative: approaching)."""
        return np.einsum("bsn,nb->bs", self._spheres.normal_jacobians(q), qdot)

    def _response(self, q: np.ndarray, j: np.ndarray) -> np.ndarray:
        """(n, B) M^-1 j of the true M (armature included) at q (n, B) for j (n, B)."""
        return self._unforced.forward_dynamics(q, np.zeros_like(j), j)

    def _inverse_mass(self, q: np.ndarray, j: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(M^-1 j (n, B), j^T M^-1 j (B,)) of the true M at q for j (n, B)."""
        response = self._response(q, j)
        return response, np.einsum("ib,ib->b", j, response)

    def _lambda(self, q: np.ndarray, qdot: np.ndarray, a: np.ndarray, response: stepping.Response,
                resting: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(M^-1 j (n, B) of each copy's resting sphere, lambda unclipped (B,), 0 where none rests)."""
        on = resting != FREE
        sphere, copies = np.where(on, resting, 0), np.arange(q.shape[1])
        rows, biases = self._spheres.normal_kinematics(q, qdot)
        j, bias = rows[copies, sphere].T, biases[copies, sphere]
        moved = response(q, j)
        unclipped = -(np.einsum("ib,ib->b", j, a) + bias) / np.einsum("ib,ib->b", j, moved)
        return moved, np.where(on, unclipped, 0.0)

    def _constraint(self, q: np.ndarray, qdot: np.ndarray, a: np.ndarray, response: stepping.Response) -> np.ndarray:
        """The accelerations a (n, B) with each resting sphere's force lambda j added (module docstring)."""
        resting = self.resting[self._active]
        if np.all(resting == FREE):
            self._unclipped[self._active] = 0.0
            return a
        moved, unclipped = self._lambda(q, qdot, a, response, resting)
        self._unclipped[self._active] = unclipped
        return a + moved * np.maximum(unclipped, 0.0)

    def start(self, copies: int) -> None:
        """Every copy off the plane's hold: a run of ``copies`` copies begins."""
        self.resting, self._unclipped = np.full(copies, FREE), np.zeros(copies)

    def step(self, t: float, q: np.ndarray, qdot: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """One step of ``dt`` [s] from time t [s] of every copy, impacts, rests and liftoffs included."""
        self._active = slice(None)
        q_end, qdot_end = self._sized(dt)(t, q, qdot)
        held = self.resting != FREE  # resting through the step unless an event moves it
        events = np.flatnonzero(np.any(self._free_spheres() & (self.gaps(q_end) < 0), axis=1))
        held[events] = False
        for b in events:
            self._active = np.array([b])
            q_end[:, [b]], qdot_end[:, [b]] = self._events(t, q[:, [b]], qdot[:, [b]], dt, int(b))
        lifting = (self.resting != FREE) & (self._unclipped <= 0)
        for b in np.flatnonzero(lifting & held):
            self._active = np.array([b])
            q_end[:, [b]], qdot_end[:, [b]] = self._lifted(t, q[:, [b]], qdot[:, [b]], dt, int(b), q_end[:, [b]],
                                                            qdot_end[:, [b]])
        self.resting[lifting & ~held] = FREE  # came to rest in this step's events: released as found
        self._active = slice(None)
        return self._held(q_end, qdot_end)

    def _lifted(self, t: float, q: np.ndarray, qdot: np.ndarray, dt: float, b: int, q_end: np.ndarray,
                qdot_end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Copy b's step of ``dt`` from t in which its resting sphere lifts off (the plane would pull at the step's
        last evaluation): backed up to the instant its force lambda falls to 0 (the first root of s -> lambda(state of
        s dt from the start, held), to :data:`TIME_RTOL` of the step), released there, and stepped free for the rest;
        where lambda does not change sign over the step (it lifted at its start, or the held end state still presses)
        released at the step's end, as found. (q_end, qdot_end): the held step's end state."""
        def pressing(s: float) -> float:
            q_s, qdot_s = self._sized(s * dt)(t, q, qdot) if s > 0 else (q, qdot)
            return self._lambda_at(t + s * dt, q_s, qdot_s, b)
        if not (pressing(0.0) > 0 >= self._lambda_at(t + dt, q_end, qdot_end, b)):
            self.resting[b] = FREE
            return q_end, qdot_end
        s = float(brentq(pressing, 0.0, 1.0, xtol=TIME_RTOL))
        q, qdot = self._sized(s * dt)(t, q, qdot)
        self.resting[b] = FREE
        return self._events(t + s * dt, q, qdot, (1.0 - s) * dt, b)  # free for the rest, any impact in it included

    def _lambda_at(self, t: float, q: np.ndarray, qdot: np.ndarray, b: int) -> float:
        """Copy b's resting sphere's unclipped force lambda [N] at the state q, qdot (n, 1) at time t [s], under the
        scene's torque then (the true M's, as :meth:`forces_world`)."""
        a = self._dynamics.forward_dynamics(q, qdot, self._applied(np.array([t])))
        return float(self._lambda(q, qdot, a, self._response, self.resting[[b]])[1][0])

    def _applied(self, times: np.ndarray) -> np.ndarray:
        """(n, len(times)) the scene's joint torque [N m or N] at ``times`` [s]: the constant and the timed one."""
        scene = self._scene
        tau = np.repeat(scene.torque[:, None], len(times), axis=1)
        if scene.timed_torque is not None:
            tau = tau + np.stack([value_in_step(scene.timed_torque, t, t) for t in times], axis=1)
        return tau

    def _held(self, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(q, qdot) with each resting sphere put back on the plane: its gap g removed by :data:`PROJECTIONS` Newton
        steps q -= g M^-1 j / (j^T M^-1 j), then its normal velocity by the impulse along M^-1 j. The resting force keeps
        the normal acceleration zero at the scheme's stages only; without this the drift grows with time (a held-out
        three-link arm sank a full radius in 10 s under semi-implicit Euler; explicit Euler floats a pushed sphere
        above the plane)."""
        on = np.flatnonzero(self.resting != FREE)
        if on.size == 0:
            return q, qdot
        q, qdot = q.copy(), qdot.copy()
        spheres = (np.arange(on.size), self.resting[on])
        for iteration in range(PROJECTIONS + 1):
            rows = self._spheres.normal_jacobians(q[:, on])[spheres].T
            response, inverse_mass = self._inverse_mass(q[:, on], rows)
            if iteration < PROJECTIONS:
                q[:, on] -= self.gaps(q[:, on])[spheres] / inverse_mass * response
            else:
                qdot[:, on] -= np.einsum("ib,ib->b", rows, qdot[:, on]) / inverse_mass * response
        return q, qdot

    def _free_spheres(self) -> np.ndarray:
        """(B, S) the spheres that may strike: every one but the sphere a copy rests on."""
        return self.resting[self._active][:, None] != np.arange(len(self._contact.spheres))

    def _events(self, t: float, q: np.ndarray, qdot: np.ndarray, dt: float, b: int) -> tuple[np.ndarray, np.ndarray]:
        """Copy b's step of ``dt`` from t with its contact events (module docstring); q (n, 1), qdot (n, 1)."""
        remaining = dt
        for _ in range(MAX_EVENTS_PER_STEP):
            candidates = self._free_spheres()[0]
            q_end, qdot_end = self._sized(remaining)(t, q, qdot)
            if not np.any(candidates & (self.gaps(q_end)[0] < 0)):
                return q_end, qdot_end
            s, sphere = self._backed_up(t, q, qdot, remaining, candidates)
            if s > 0:
                q, qdot = self._sized(s * remaining)(t, q, qdot)
                t, remaining = t + s * remaining, remaining - s * remaining
            qdot = self._respond(q, qdot, candidates, sphere, b, at_rest=s < 0)
        raise SimparityError(f"copy {b} had more than {MAX_EVENTS_PER_STEP} contact events in one step of {dt:g} s "
                             f"at t = {t:.9g} s (allowed: a rest_speed its steps resolve)")

    def _backed_up(self, t: float, q: np.ndarray, qdot: np.ndarray, h: float,
                   candidates: np.ndarray) -> tuple[float, int]:
        """(the fraction s of the step ``h`` at which the first candidate sphere strikes, that sphere): s = 0 for one
        on or inside the plane moving in; else each sphere found inside at the step's end has its first root
        bracketed from 0 when it approaches, and from the first of :data:`CLEARING` at which it is above the plane
        when it leaves (one just bounced: its gap at rounding's level); s = -1 for a leaving sphere that never clears
        the plane before it is back (its rebound is below what the scheme resolves: it comes to rest)."""
        gaps, normal = self.gaps(q)[0], self.normal_velocities(q, qdot)[0]
        inside = np.flatnonzero(candidates & (gaps <= 0) & (normal <= 0))
        if inside.size:
            return 0.0, int(inside[np.argmin(gaps[inside])])
        trials: dict[float, np.ndarray] = {}

        def gaps_at(s: float) -> np.ndarray:
            if s not in trials:
                trials[s] = self.gaps(self._sized(s * h)(t, q, qdot)[0])[0]
            return trials[s]
        roots: list[tuple[float, int]] = []
        for k in np.flatnonzero(candidates & (gaps_at(1.0) < 0)):
            start = 0.0
            if normal[k] > 0:
                start = next((s for s in CLEARING if gaps_at(s)[k] > 0), -1.0)
                if start < 0:
                    return -1.0, int(k)
            roots.append((float(brentq(lambda s, k=k: float(gaps_at(s)[k]), start, 1.0, xtol=TIME_RTOL)), int(k)))
        return min(roots)

    def _respond(self, q: np.ndarray, qdot: np.ndarray, candidates: np.ndarray, sphere: int, b: int,
                 at_rest: bool = False) -> np.ndarray:
        """qdot after the impulse of ``sphere`` striking at (q, qdot) (module docstring); ``at_rest``: stopped and
        put at rest whatever its normal velocity (a leaving sphere back before it clears the plane)."""
        gaps, normal = self.gaps(q)[0], self.normal_velocities(q, qdot)[0]
        others = np.flatnonzero(candidates & (gaps <= 0) & (normal <= 0) & (np.arange(len(gaps)) != sphere))
        spheres = self._contact.spheres
        if others.size:
            raise ContactError(f"spheres {sphere} and {int(others[0])} (on {spheres[sphere].frame!r}, "
                               f"{spheres[int(others[0])].frame!r}) strike the plane at once: core's impulses resolve "
                               "one contact at a time (several need a complementarity solver)")
        if self.resting[b] != FREE:
            rest = int(self.resting[b])
            raise ContactError(f"sphere {sphere} (on {spheres[sphere].frame!r}) strikes the plane while sphere {rest} "
                               f"(on {spheres[rest].frame!r}) rests on it: core's impulses resolve one contact at a "
                               "time (several need a complementarity solver)")
        speed = float(normal[sphere])
        if speed > 0 and not at_rest:
            return qdot
        e = self._contact.restitution
        assert e is not None
        if at_rest or -e * speed < self._contact.rest_speed:
            e, self.resting[b] = 0.0, sphere
        j = self._spheres.normal_jacobians(q)[0, sphere][:, None]
        response, inverse_mass = self._inverse_mass(q, j)
        return qdot - (1.0 + e) * speed * response / inverse_mass

    def run(self, q0: np.ndarray, qdot0: np.ndarray, n_steps: int, dt: float
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q (n_steps + 1, B, n), qdot (n_steps + 1, B, n), the resting sphere at each sample (n_steps + 1, B)) of
        ``n_steps`` steps of ``dt`` [s] from (q0, qdot0), (B, n) each, at t = 0."""
        self.start(len(q0))
        log = np.empty((n_steps + 1, len(q0)), dtype=int)
        log[0] = FREE

        def step(t: float, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            out = self.step(t, q, qdot, dt)
            log[int(round(t / dt)) + 1] = self.resting
            return out
        q, qdot = stepping.run(step, q0, qdot0, n_steps, dt)
        return q, qdot, log

    def forces_world(self, q: np.ndarray, qdot: np.ndarray, times: np.ndarray, resting: np.ndarray) -> np.ndarray:
        """(B, S, 3) [N] the plane's force on each sphere at states q (B, n), qdot (B, n) at ``times`` (B,) [s] with
        the resting spheres ``resting`` (B,): lambda N on a resting sphere (the true M's), 0 on the others (an
        impact's impulse is no force)."""
        q_t, qdot_t = np.ascontiguousarray(q.T), np.ascontiguousarray(qdot.T)
        a = self._dynamics.forward_dynamics(q_t, qdot_t, self._applied(times))
        _, unclipped = self._lambda(q_t, qdot_t, a, self._response, resting)
        out = np.zeros((len(times), len(self._contact.spheres), 3))
        on = np.flatnonzero(resting != FREE)
        out[on, resting[on]] = np.maximum(unclipped[on], 0.0)[:, None] * self._contact.plane.normal_world
        return out
