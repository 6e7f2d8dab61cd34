"""Core's penalty contact of a chain's spheres (:mod:`core.articulated.chain_contact`): the generalized force is the
spheres' forces through the Jacobian of their centres (virtual power, against finite differences of the centres), each
force the lecture's spring-damper along the normal, never a pull, nothing off the plane."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.core.articulated.chain_contact import ChainContactForces
from simparity.core.articulated.stepping import configuration_rate, normalised
from simparity.core.model.scenes.chain_contact import ChainContact, ContactSphere
from simparity.core.model.scenes.contact import Plane
from tests.helpers import floating_states, random_chain, solo12_leg

STIFFNESS, DAMPING = 2e4, 30.0
FD_STEP = 1e-6
"""[rad or m, or s along the configuration's rate] Central differences of the centres: truncation ~ step^2 |x'''|
~ 1e-12 m, rounding ~ eps / step ~ 1e-10 m per unit rate."""
FD_TOLERANCE = 1e-7
"""Relative agreement of the contact's power with the virtual power of the forces on the centres' finite-difference
velocities (both errors above, over forces of order k x 1 cm)."""


def _contact(chain, normal, frames) -> ChainContact:
    spheres = tuple(ContactSphere(frame, np.array([0.05, -0.02, 0.03]), 0.02) for frame in frames)
    return ChainContact(Plane(normal, 0.0), spheres, STIFFNESS, DAMPING)


def _penetrating(forces: ChainContactForces, contact: ChainContact, q: np.ndarray) -> ChainContact:
    """The same contact with the plane moved so that every sphere is 1 cm or more inside it at q (nq, 1)."""
    centres = forces.centres_world(q)[0]
    normal = contact.plane.normal_world
    offset = -float((centres @ normal).max()) + contact.radii.max() - 0.01
    return ChainContact(Plane(normal, offset), contact.spheres, STIFFNESS, DAMPING)


def _fixed_case(seed: int):
    rng = np.random.default_rng(seed)
    chain = random_chain(rng, 5)
    frames = ("j1", "j3", chain.end_effector_name)
    return chain, frames, rng.uniform(-1, 1, (chain.nq, 1)), rng.uniform(-1, 1, (chain.nv, 1)), rng


def _power_mismatch(chain, contact, q, qdot, move) -> float:
    """|tau . qdot - sum_s F_s . v_s| / sum_s |F_s| |v_s|, v_s the centres' velocities by central differences along
    ``move(q, eps)``."""
    model = ChainContactForces(chain, contact)
    tau = model.generalized(q, qdot)[:, 0]
    forces = model.forces_world(q, qdot)[0]
    velocities = (model.centres_world(move(q, FD_STEP)) - model.centres_world(move(q, -FD_STEP)))[0] / (2 * FD_STEP)
    virtual = float(np.einsum("si,si->", forces, velocities))
    scale = float(np.sum(np.linalg.norm(forces, axis=1) * np.linalg.norm(velocities, axis=1)))
    assert scale > 0, "the case must press and move"
    return abs(float(tau @ qdot[:, 0]) - virtual) / scale


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_fixed_base_chain_takes_the_spheres_forces_through_their_jacobian(seed):
    chain, frames, q, qdot, rng = _fixed_case(seed)
    normal = rng.normal(size=3)
    model = ChainContactForces(chain, _contact(chain, normal, frames))
    contact = _penetrating(model, _contact(chain, normal, frames), q)
    assert _power_mismatch(chain, contact, q, qdot, lambda q, eps: q + eps * qdot) < FD_TOLERANCE


@pytest.mark.parametrize("seed", [4, 5])
def test_a_floating_base_takes_the_forces_and_their_moments_on_its_base(seed):
    chain = solo12_leg()
    q, v, _, _ = floating_states(chain, 1, seed)
    q, qdot = q.T, v.T
    frames = ("base_link", "FL_HFE", "FL_FOOT")
    normal = np.random.default_rng(seed).normal(size=3)
    model = ChainContactForces(chain, _contact(chain, normal, frames))
    contact = _penetrating(model, _contact(chain, normal, frames), q)

    def move(q, eps):  # along the configuration's rate, the quaternion kept unit (second order in eps)
        return normalised(q + eps * configuration_rate(q, qdot))
    assert _power_mismatch(chain, contact, q, qdot, move) < FD_TOLERANCE


def test_each_force_is_the_lecture_s_spring_damper_and_never_pulls():
    chain, frames, q, qdot, _ = _fixed_case(7)
    normal = np.array([0.0, 0.0, 1.0])
    model = ChainContactForces(chain, _contact(chain, normal, frames))
    contact = _penetrating(model, _contact(chain, normal, frames), q)
    model = ChainContactForces(chain, contact)
    centres = model.centres_world(q)[0]
    depth = -(centres[:, 2] + contact.plane.offset - contact.radii)
    eps = FD_STEP
    rates = (model.centres_world(q + eps * qdot) - model.centres_world(q - eps * qdot))[0, :, 2] / (2 * eps)
    forces = model.forces_world(q, qdot)[0]
    expected = np.maximum(STIFFNESS * depth - DAMPING * rates, 0.0)
    np.testing.assert_allclose(forces[:, 2], expected, rtol=1e-9, atol=1e-9 * STIFFNESS * 0.01)
    assert np.all(forces[:, :2] == 0.0)
    away = ChainContactForces(chain, ChainContact(Plane(normal, contact.plane.offset + 1.0), contact.spheres,
                                                  STIFFNESS, DAMPING))
    assert np.all(away.forces_world(q, qdot) == 0.0)  # a sphere off the plane feels nothing
    fast = ChainContactForces(chain, contact).forces_world(q, qdot * 1e6)
    assert np.all(fast @ normal >= 0.0)  # separating fast: the damping never pulls
