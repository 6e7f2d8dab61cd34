"""Pinocchio's static balance with point forces (``references/pinocchio/statics.py``), the truth of
``rest_equilibrium_error``: without forces it is Pinocchio's gravity vector, and the forces enter as -sum_s J_s^T f_s,
against the virtual power of the forces on the spheres' centres differenced by core's FK (a second, independent
geometry), on a floating base (world-axes wrench about its origin) and on a fixed one (a sphere on the end effector)."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.comparisons.api import load_scene
from simparity.core.articulated.chain_contact import ChainContactForces
from simparity.core.articulated.stepping import configuration_rate, normalised
from simparity.references.pinocchio.joint_dynamics import PinocchioJointDynamics
from simparity.references.pinocchio.floating import PinocchioFloatingDynamics
from simparity.references.pinocchio.statics import PinocchioStatics

FD_STEP = 1e-6
"""Central differences of the centres along a velocity: truncation ~ step^2, rounding ~ eps / step ~ 1e-10."""
AGREEMENT = 1e-8
"""Relative agreement of the balance's force part with the forces' virtual power (both errors above)."""
ROUNDING = 1e-12
"""Two evaluations of one recursion at one state: rounding."""



def _centres(chain, contact, q: np.ndarray) -> np.ndarray:
    """(B, S, 3) the spheres' centres by core's FK at configurations q (B, nq)."""
    return ChainContactForces(chain, contact).centres_world(np.asarray(q).T)

@pytest.mark.parametrize("name, seed", [("solo12-drop-stand", 1), ("pendulum-press", 2)])
def test_the_balance_is_gravity_less_the_forces_through_the_spheres_jacobians(name, seed):
    scene = load_scene(name)
    chain, contact = scene.chain, scene.contact
    rng = np.random.default_rng(seed)
    q = np.array(scene.q0, dtype=float)
    q[:, q.shape[1] - chain.n_joints:] += rng.uniform(-0.5, 0.5, chain.n_joints)
    if chain.floating_base:
        turn = rng.normal(size=4)
        q[:, 3:7] = turn / np.linalg.norm(turn)
    forces = rng.normal(size=(1, len(contact.spheres), 3))
    statics = PinocchioStatics(chain, scene.gravity_world, contact)
    dynamics = (PinocchioFloatingDynamics if chain.floating_base else PinocchioJointDynamics)(chain,
                                                                                              scene.gravity_world)
    np.testing.assert_allclose(statics.balance(q, 0 * forces), dynamics.bias_forces(q, np.zeros((1, chain.nv))),
                               rtol=0, atol=ROUNDING * max(1.0, float(np.abs(statics.balance(q, 0 * forces)).max())))
    pushed = statics.balance(q, forces) - statics.balance(q, 0 * forces)  # -sum J^T f
    for _ in range(3):
        w = rng.uniform(-1, 1, chain.nv)

        def moved(eps):
            if chain.floating_base:
                return normalised((q + eps * configuration_rate(q.T, w[:, None]).T).T).T
            return q + eps * w
        velocities = (_centres(chain, contact, moved(FD_STEP))
                      - _centres(chain, contact, moved(-FD_STEP))) / (2 * FD_STEP)
        virtual = float(np.einsum("bsi,bsi->", forces, velocities))
        scale = float(np.abs(forces).sum() * np.abs(velocities).max())
        assert abs(-float(pushed[0] @ w) - virtual) <= AGREEMENT * scale
