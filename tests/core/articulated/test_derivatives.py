"""Core's analytic derivatives (core/articulated/derivatives.py, issue #44): the planar arm's closed-form partials by
hand, central differences of core's own RNEA to their truncation, ∂q̈/∂τ M = I, and a batch is its states one by one.
Against the complex-step truth on every built-in arm: the gate's rows (rnea_derivative_error_max)."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.comparisons.scenes import library
from simparity.core.articulated.model import build
from tests.helpers import SPONG_GRAVITY, spong_chain, spong_partials

ROUNDING = 1e-13
"""Sums of O(n^2) products of order-1 numbers evaluated two ways (measured <= 1e-15 on the arm)."""
FD_STEP, FD_AGREEMENT = 1e-5, 1e-7
"""Central differences at 1e-5 rad: truncation and rounding both ~1e-11 relative; 1e-7 is far below a wrong term."""


def test_the_planar_arm_s_partials_by_hand():
    model = build(spong_chain(), "recursive", np.array([0.0, -SPONG_GRAVITY, 0.0]))
    rng = np.random.default_rng(45)
    q, qd, tau = (rng.uniform(-2, 2, (6, 2)) for _ in range(3))
    found = model.derivatives(q, qd, tau)
    by_q, by_qd = spong_partials(q, qd, model.forward_dynamics(q, qd, tau))
    assert np.max(np.abs(found.dtau_dq - by_q)) <= ROUNDING * np.max(np.abs(by_q))
    assert np.max(np.abs(found.dtau_dqdot - by_qd)) <= ROUNDING * np.max(np.abs(by_qd))


@pytest.mark.parametrize("name", ["crafted-arm-dynamics", "armature-arm-dynamics", "oblique-arm-dynamics"])
def test_central_differences_of_core_s_own_dynamics(name):
    """Revolute, prismatic and continuous joints, armature and damping: the partials are the slopes of core's RNEA and
    ABA themselves."""
    scene = library.load([name])[0]
    model = build(scene.chain, "recursive", scene.gravity_world)
    q, qd, _, tau = (x[:4] for x in scene.states())
    found = model.derivatives(q, qd, tau)
    qdd = model.forward_dynamics(q, qd, tau)
    for which, (name_tau, name_qdd) in enumerate((("dtau_dq", "dqddot_dq"), ("dtau_dqdot", "dqddot_dqdot"))):
        slopes_tau, slopes_qdd = [], []
        for e in np.eye(scene.chain.n_joints):
            plus, minus = [q, qd], [q, qd]
            plus[which], minus[which] = plus[which] + FD_STEP * e, minus[which] - FD_STEP * e
            slopes_tau.append((model.inverse_dynamics(*plus, qdd) - model.inverse_dynamics(*minus, qdd)) / (2 * FD_STEP))
            slopes_qdd.append((model.forward_dynamics(*plus, tau) - model.forward_dynamics(*minus, tau)) / (2 * FD_STEP))
        for slopes, field in ((slopes_tau, name_tau), (slopes_qdd, name_qdd)):
            reference = np.stack(slopes, axis=-1)
            assert np.max(np.abs(getattr(found, field) - reference)) <= FD_AGREEMENT * np.max(np.abs(reference)), field
    mass = model.mass_matrix(q)
    assert np.max(np.abs(found.dqddot_dtau @ mass - np.eye(scene.chain.n_joints))) <= ROUNDING * np.linalg.cond(mass, 1).max()
    alone = model.derivatives(q[:1], qd[:1], tau[:1])
    assert np.allclose(alone.dtau_dq[0], found.dtau_dq[0], rtol=0, atol=ROUNDING * np.max(np.abs(found.dtau_dq)))
