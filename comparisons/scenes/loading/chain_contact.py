"""A joint-motion scene's contact: its ``[[plane]]`` (one) and ``[contact]`` with the chain's ``[[contact.sphere]]``."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from simparity.comparisons.scenes.loading.contact import START_INSIDE_TOLERANCE
from simparity.comparisons.scenes.loading.reader import TableReader
from simparity.core.articulated.chain_contact import ChainContactForces
from simparity.core.model.ranges import RANGES, safe_norm
from simparity.core.model.scenes.chain import Chain
from simparity.core.model.scenes.chain_contact import ChainContact, ContactSphere
from simparity.core.model.scenes.contact import Plane

_PLANE = ("name", "coefficients")
_CONTACT = ("penalty_stiffness", "penalty_damping", "restitution", "rest_speed", "rest_after", "stands", "friction",
            "friction_speed", "sphere")
_SPHERE = ("frame", "centre_xyz", "radius")


def _plane(top: TableReader) -> Plane:
    """The scene's one [[plane]]: ``coefficients`` [a, b, c, d] of a x + b y + c z + d = 0, free side a x + ... > 0."""
    planes = top.array_of_tables("plane", _PLANE, "max_bodies")
    if len(planes) != 1:
        raise top.fail("plane", f"{len(planes)} planes", "one [[plane]]: a robot meets one ground plane (part 1)")
    p = planes[0]
    abcd = p.vector("coefficients", 4)
    length = safe_norm(abcd[:3])
    if not (length > 0 and np.isfinite(length)):
        raise p.fail("coefficients", "the normal (a, b, c) is all zeros", "[a, b, c, d] with (a, b, c) != 0")
    scaled = abcd / np.max(np.abs(abcd[:3]))  # the same plane, its normal's largest entry 1: no overflow
    offset = scaled[3] / float(np.linalg.norm(scaled[:3])) * p.scale
    if not RANGES["position_world"].allows(abs(offset)):
        raise p.fail("coefficients", f"the plane lies {abs(offset):.3g} m from the origin",
                     RANGES["position_world"].text())
    return Plane(scaled[:3], scaled[3] * p.scale, p.name("name", "ground"))


def _frames(chain: Chain) -> tuple[str, ...]:
    names = tuple(j.name for j in chain.joints) + (chain.end_effector_name,)
    return names + ((chain.base_link,) if chain.base_link is not None else ())


def read_chain_contact(top: TableReader, chain: Chain, q0: np.ndarray, duration: float) -> ChainContact | None:
    """The chain's contact spheres against the scene's plane, or None when the file has no [[plane]]; each sphere must
    start on the plane's free side (within :data:`START_INSIDE_TOLERANCE`) at ``q0`` (nq,); ``rest_after`` inside the
    scene's ``duration`` [s]."""
    if not top.has("plane"):
        if top.has("contact"):
            raise top.fail("contact", "contact settings without a [[plane]]", "a [[plane]] for the spheres to touch")
        return None
    if chain.mjcf_path is not None:
        raise top.fail("plane", "contact for a chain read from an MJCF file",
                       "a URDF chain or [[chain.joint]] entries: an MJCF importer would weigh the contact spheres")
    plane = _plane(top)
    c = top.subtable("contact", _CONTACT)
    spheres = []
    for s in c.array_of_tables("sphere", _SPHERE, "max_bodies"):
        frame = s.string("frame", choices=_frames(chain))
        spheres.append(ContactSphere(frame, s.vector("centre_xyz", 3, [0.0] * 3, length=1),
                                     s.number("radius", positive=True, length=1)))
    if not spheres:
        raise c.fail("sphere", "no contact sphere", "[[contact.sphere]] entries: frame, centre_xyz, radius")
    rest_after = c.number("rest_after", positive=True) if c.has("rest_after") else None
    if rest_after is not None and not rest_after < duration:
        raise c.fail("rest_after", f"{rest_after:g} s is not before the end of the run ({duration:g} s)",
                     "a time [s] inside the scene's duration, from which its robot is at rest")
    contact = (_rigid(c, plane, tuple(spheres), rest_after) if c.has("restitution") else
               _soft(c, chain, plane, tuple(spheres), rest_after))
    if c.has("stands"):
        if not chain.floating_base:
            raise c.fail("stands", "a fixed base", "stands on a floating base (a fixed base's mount carries an unknown "
                                                   "share of the weight: its rest checks are the joints')")
        contact = replace(contact, stands=c.boolean("stands", False))
    _check_start_outside(top, chain, contact, q0)
    return contact


def _soft(c: TableReader, chain: Chain, plane: Plane, spheres: tuple[ContactSphere, ...],
          rest_after: float | None) -> ChainContact:
    """A soft contact: core's penalty spring k_s and damper k_d (critical on the robot's mass by default)."""
    if c.has("rest_speed"):
        raise c.fail("rest_speed", "a rest speed on a soft contact", "rest_speed with restitution (a rigid contact)")
    friction = c.number("friction", 0.0)
    if friction < 0:
        raise c.fail("friction", f"{friction:g} is negative", "a Coulomb coefficient >= 0 (0: a frictionless plane)")
    friction += 0.0  # -0.0 is 0
    if c.has("friction_speed") and friction == 0:
        raise c.fail("friction_speed", "a friction speed on a frictionless plane",
                     "friction_speed with friction > 0 (core's regularisation of it)")
    friction_speed = c.number("friction_speed", 1e-2, positive=True, length=1)  # m/s
    stiffness = c.number("penalty_stiffness", positive=True)  # N/m = kg / s^2: no length
    damping = (c.number("penalty_damping") if c.has("penalty_damping")
               else 2.0 * float(np.sqrt(stiffness * chain.mass)))  # critical on the robot's mass, N s/m = kg / s
    if damping < 0:
        raise c.fail("penalty_damping", f"{damping:g} is negative", "a number >= 0 [N s/m]")
    return ChainContact(plane, spheres, stiffness, damping, rest_after, friction=friction,
                        friction_speed=friction_speed)


def _rigid(c: TableReader, plane: Plane, spheres: tuple[ContactSphere, ...], rest_after: float | None) -> ChainContact:
    """A rigid contact: Newton's restitution e at each impact, plastic below ``rest_speed`` (m/s, default 1 mm/s)."""
    for key in ("penalty_stiffness", "penalty_damping"):
        if c.has(key):
            raise c.fail(key, "a penalty spring on a rigid contact (restitution is given)",
                         "either restitution (rigid: impulses) or penalty_stiffness (soft: springs), not both")
    if c.has("friction") and c.number("friction") != 0:
        raise c.fail("friction", "friction on a rigid contact (restitution is given)",
                     "friction on a soft contact (penalty_stiffness): a rigid contact's impacts are frictionless")
    if c.has("friction_speed"):
        raise c.fail("friction_speed", "a friction speed on a rigid contact (restitution is given)",
                     "friction_speed with friction on a soft contact (penalty_stiffness)")
    restitution = c.number("restitution")
    if not 0 <= restitution <= 1:
        raise c.fail("restitution", f"{restitution:g} is outside [0, 1]", "a number in [0, 1] (1: elastic)")
    rest_speed = c.number("rest_speed", 1e-3, positive=True, length=1)
    return ChainContact(plane, spheres, None, None, rest_after, restitution, rest_speed)


def _check_start_outside(top: TableReader, chain: Chain, contact: ChainContact, q0: np.ndarray) -> None:
    gaps = contact.gaps(ChainContactForces(chain, contact).centres_world(np.atleast_2d(q0).T))
    copy, k = np.unravel_index(int(np.argmin(gaps)), gaps.shape)
    if -gaps[copy, k] > START_INSIDE_TOLERANCE:
        raise top.fail(f"contact.sphere[{k}]", f"the sphere on {contact.spheres[k].frame!r} starts "
                       f"{-gaps[copy, k]:.3g} m inside the plane", "every sphere on the plane's free side at t = 0")
