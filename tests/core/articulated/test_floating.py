"""Core's floating-base dynamics (core/articulated/floating.py) against core's fixed-base algorithms and against its
own ABA/CRBA/RNEA: the joints' block of a floating M is the fixed-base M at any base pose, a still base gives the fixed
base's joint forces under gravity turned into its axes, ABA solves CRBA's M with RNEA's h, and a batch is its states
one by one. Against the other engines and truths by hand: tests/references/test_floating_base_conventions.py."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from simparity.core.articulated.model import build
from tests.helpers import floating_states, solo12_leg

ROUNDING = 1e-13
"""Relative agreement of two evaluations of sums of a few dozen double products of numbers of order 1."""

GRAVITY = np.array([0.3, -0.2, -9.81])


@pytest.fixture(scope="module")
def solo():
    return solo12_leg()


def test_core_s_floating_joint_block_is_its_fixed_base_m_and_its_still_base_rnea_the_fixed_one(solo):
    """Core against itself across the two algorithms' paths: the joints' block of a floating M is the fixed-base M at
    any base pose; with the base still (zero velocity and acceleration) the joints' forces are the fixed base's under
    gravity turned into the base's axes."""
    floating = build(solo, "recursive", GRAVITY)
    q, v, a, _ = floating_states(solo, 4, seed=4)
    fixed_chain = replace(solo, floating_base=False, base_inertia=None)
    mass = floating.mass_matrix(q)
    assert np.allclose(mass[:, 6:, 6:], build(fixed_chain, "recursive", None).mass_matrix(q[:, 7:]), rtol=0,
                       atol=ROUNDING * np.max(np.abs(mass[:, 6:, 6:])))
    v[:, :6] = 0.0
    a[:, :6] = 0.0
    tau = floating.inverse_dynamics(q, v, a)
    for row, joints, rates, accelerations, expected in zip(q, q[:, 7:], v[:, 6:], a[:, 6:], tau[:, 6:]):
        turn = Rotation.from_quat(row[3:7], scalar_first=True).as_matrix()
        fixed = build(fixed_chain, "recursive", turn.T @ GRAVITY)
        assert np.allclose(fixed.inverse_dynamics(joints, rates, accelerations)[0], expected, rtol=0,
                           atol=ROUNDING * np.max(np.abs(expected)))


def test_aba_solves_crba_s_m_with_rnea_s_h_and_a_batch_is_its_states_one_by_one(solo):
    model = build(solo, "recursive", GRAVITY)
    q, v, _, tau = floating_states(solo, 6, seed=5)
    mass, bias = model.mass_matrix(q), model.bias_forces(q, v)
    solved = np.linalg.solve(mass, (tau - bias)[:, :, None])[:, :, 0]
    assert np.max(np.abs(np.einsum("bij,bj->bi", mass, model.forward_dynamics(q, v, tau) - solved))) <= ROUNDING * (
        np.max(np.abs(tau)) + np.max(np.abs(bias)))
    for k in range(len(q)):
        assert np.allclose(model.mass_matrix(q[k:k + 1])[0], mass[k], rtol=0, atol=ROUNDING * np.max(np.abs(mass)))
        alone, together = model.forward_dynamics(q[k:k + 1], v[k:k + 1], tau[k:k + 1])[0], model.forward_dynamics(q, v, tau)[k]
        assert np.allclose(alone, together, rtol=ROUNDING, atol=0)


def test_core_refuses_the_jacobian_sum_on_a_floating_base_in_words(solo):
    from simparity.core.inhouse import InHouseEngine

    support = InHouseEngine().supports_joint_dynamics(solo, "jacobian_sum")
    assert not support.ok and "fixed-base" in support.reason and "recursive" in support.reason
