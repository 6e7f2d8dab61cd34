"""A physical pendulum striking a plane with a rigid contact (restitution e), in closed form between impacts.

The scene is a one-joint pendulum (:mod:`references.analytic.joint_motion`: no damping, no torque) with one contact
sphere on its link (or its end effector, or the base) and a rigid ``[contact]``. The sphere's centre is a point of
the link, so by Rodrigues' formula its gap to the plane (N . x + d, less the radius) is

    gap(q) = A cos q + B sin q + C

with x the centre at q = 0 from the joint's origin p0: A = N . (x - n (n . x)), B = N . (n x x),
C = N . (p0 + n (n . x)) + d - r (n the joint axis). Between impacts the pendulum follows its closed form (Jacobi
elliptic functions); an impact is the first instant after a piece's start at which the gap closes to 0 while
decreasing, found on the closed form: its sign scanned every :data:`SCAN_FRACTION` of a period, the crossing
refined by Brent's method to rounding (:data:`IMPACT_XTOL`). A one-joint chain's sphere moves along the plane's
normal only through q, so the impulse of any rigid contact maps q' to -e q' (its normal velocity is
gap'(q) q'): no mass matrix, no Jacobian of anyone's. A rebound slower than the scene's ``rest_speed`` is plastic
(q' = 0); the pendulum then rests on the plane for good where gravity presses the sphere into it (the gap's
acceleration from rest, gap'(q) q'', is negative), and swings on from rest where gravity lifts it.

Nothing here is core's: the impact instants come from the closed form, not from any scheme's steps.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipk

from simparity.core.model.engine import Support
from simparity.core.model.scenes.chain_contact import frame_index
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.references.analytic.joint_motion import OneJoint, Pendulum, modulus_squared, pendulum_motion

SCAN_FRACTION = 1.0 / 512
"""[1] The gap's sign is scanned every this fraction of the pendulum's period (of one turn, rotating): a sphere
that dips into the plane and out again between two scans (a graze deeper than ~(2 pi / 512)^2 / 2 ~ 8e-5 of the
sphere's swing is not missed) is the one thing the scan can miss."""
IMPACT_XTOL = 1e-15
"""[s] Brent's absolute tolerance on an impact instant (its relative one is 4 eps): the instant to rounding."""
MAX_IMPACTS = 10_000
"""Impacts one run may have; a rest speed at least rounding's above zero ends every bounce sequence long before."""


def supports(scene: JointMotionScene) -> Support:
    """Whether the pendulum-and-plane closed form covers the scene's contact (called for a supported pendulum)."""
    contact = scene.contact
    assert contact is not None
    if not contact.rigid:
        return Support.no("no closed form for a soft contact: its penetration follows each engine's own stiffness")
    if len(contact.spheres) != 1:
        return Support.no(f"no closed form for {len(contact.spheres)} contact spheres (the closed form strikes one)")
    return Support.yes()


@dataclass(frozen=True)
class StrikingPendulum:
    """The pendulum and its plane: gap(q) = A cos q + B sin q + C [m] (module docstring)."""

    pendulum: Pendulum
    cos_coefficient: float
    sin_coefficient: float
    constant: float
    restitution: float
    rest_speed: float

    def gap(self, q: np.ndarray) -> np.ndarray:
        """[m] the sphere's gap at joint values q [rad]."""
        return self.cos_coefficient * np.cos(q) + self.sin_coefficient * np.sin(q) + self.constant

    def gap_slope(self, q: float) -> float:
        """d gap / dq [m/rad] at q."""
        return float(-self.cos_coefficient * np.sin(q) + self.sin_coefficient * np.cos(q))


def striking_pendulum(scene: JointMotionScene, joint: OneJoint, pendulum: Pendulum) -> StrikingPendulum:
    """The scene's pendulum with its one sphere's gap coefficients (a supported scene, :func:`supports`)."""
    contact = scene.contact
    assert contact is not None and contact.restitution is not None  # supports() says so
    sphere = contact.spheres[0]
    chain = scene.chain
    place = frame_index(sphere.frame, tuple(j.name for j in chain.joints), chain.end_effector_name, chain.base_link)
    normal, rotation = contact.plane.normal_world, chain.joints[0].origin_rotation
    if place < 0:  # on the base: a world point that never moves
        offset, swing = sphere.centre_xyz - joint.origin, np.zeros(3)
    else:
        in_link = sphere.centre_xyz if place == 0 else chain.end_effector_xyz + chain.end_effector_rotation @ sphere.centre_xyz
        offset = rotation @ in_link
        swing = offset - (joint.axis @ offset) * joint.axis
    fixed = offset - swing  # the part along the axis (all of it on the base)
    return StrikingPendulum(pendulum, float(normal @ swing), float(normal @ np.cross(joint.axis, swing)),
                            float(normal @ (joint.origin + fixed)) + contact.plane.offset - sphere.radius,
                            contact.restitution, contact.rest_speed)


def _period(theta0: float, thetadot0: float, omega0: float) -> float:
    """[s] the free pendulum's period from (theta0, theta0'): of a swing, or of one turn."""
    m, m1 = modulus_squared(np.array([theta0]), np.array([thetadot0]), omega0)
    if m1[0] > 0:
        return float(4 * ellipk(m[0]) / omega0)
    return float(2 * ellipk(1 / m[0]) / (np.sqrt(m[0]) * omega0))


def _crossing(gap_at, start: float, step: float, horizon: float) -> float | None:
    """The first time in (start, horizon] at which ``gap_at`` goes from >= 0 to < 0 (a scan every ``step``, refined
    near ``start`` where the gap starts at 0 and Brent's method at the crossing); None when it does not."""
    times = np.arange(start, horizon + step, step)
    gaps = gap_at(times)
    inside = np.flatnonzero(gaps[1:] < 0)
    if inside.size == 0:
        return None
    k = int(inside[0]) + 1
    lower = times[k - 1]
    if gaps[k - 1] <= 0:  # the piece starts on the plane moving off: find where it is off it within the first step
        fine = np.linspace(lower, times[k], 65)[1:]
        above = np.flatnonzero(gap_at(fine) > 0)
        if above.size == 0:
            return lower
        lower = fine[int(above[0])]
        if lower >= times[k]:
            return None
    return float(brentq(lambda t: float(gap_at(np.array([t]))[0]), lower, times[k], xtol=IMPACT_XTOL))


def striking_motion(model: StrikingPendulum, q0: float, qdot0: float,
                    times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(q, q') at ``times`` (T,) [s] from (q0, q0') at t = 0: closed-form pieces between impacts (module docstring)."""
    psi, omega0 = model.pendulum.psi, model.pendulum.omega0
    q, qdot = np.empty(len(times)), np.empty(len(times))
    start, state, resting = 0.0, (q0, qdot0), False
    horizon = float(times[-1])
    for _ in range(MAX_IMPACTS):
        piece = times >= start
        if resting:
            q[piece], qdot[piece] = state[0], 0.0
            return q, qdot
        theta0, rate0 = state[0] - psi, state[1]

        def motion(t: np.ndarray, theta0=theta0, rate0=rate0, start=start) -> tuple[np.ndarray, np.ndarray]:
            theta, rate = pendulum_motion(np.array([theta0]), np.array([rate0]), omega0, np.asarray(t) - start)
            return theta[:, 0] + psi, rate[:, 0]
        step = SCAN_FRACTION * _period(theta0, rate0, omega0)
        impact = _crossing(lambda t: model.gap(motion(t)[0]), start, step, horizon)
        end = times <= horizon if impact is None else times < impact
        q[piece & end], qdot[piece & end] = motion(times[piece & end])
        if impact is None:
            return q, qdot
        (q_hit,), (rate_hit,) = motion(np.array([impact]))
        slope = model.gap_slope(q_hit)
        rebound = -model.restitution * rate_hit
        if abs(slope * rebound) < model.rest_speed:
            gravity_rate = -omega0**2 * np.sin(q_hit - psi)  # q'' from rest at the impact
            resting, rebound = bool(slope * gravity_rate < 0), 0.0
        start, state = impact, (q_hit, rebound)
    raise ValueError(f"more than {MAX_IMPACTS} impacts before {horizon:g} s")
