"""The complex-step truth of the dynamics' derivatives (issue #44, references/derivatives/complex_step.py): its RNEA is
the dynamics (Pinocchio's to rounding), its derivatives match central finite differences to their truncation and the
planar 2-link arm's closed-form derivatives to rounding, it is complex-safe (run with ComplexWarning as an error), and
∂τ/∂q̈ = M exactly."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.comparisons.scenes import library
from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia
from simparity.references.derivatives.complex_step import _mass_and_bias, derivatives, rnea, tree_from_chain
from simparity.references.pinocchio.joint_dynamics import PinocchioJointDynamics

ROUNDING = 1e-13
"""Two double evaluations of the same sums of O(n^2) products, relative to the largest entry (measured <= 3e-14)."""
FD_STEP = 1e-5
FD_AGREEMENT = 1e-7
"""Central differences at 1e-5 rad: truncation h^2 / 6 |d3 tau| ~ 2e-11 relative, rounding eps |tau| / h ~ 2e-11;
1e-7 is far above both and far below any wrong term."""

SCENES = ["crafted-arm-dynamics", "oblique-arm-dynamics", "armature-arm-dynamics", "panda-dynamics"]


@pytest.fixture(scope="module", params=SCENES)
def case(request):
    scene = library.load([request.param])[0]
    q, qd, qdd, tau = (x[:6] for x in scene.states())
    return scene, tree_from_chain(scene.chain, scene.gravity_world), (q, qd, qdd, tau)


def test_its_rnea_is_the_dynamics(case):
    scene, tree, (q, qd, qdd, _) = case
    pinocchio = PinocchioJointDynamics(scene.chain, scene.gravity_world).inverse_dynamics(q, qd, qdd)
    assert np.max(np.abs(rnea(tree, q, qd, qdd) - pinocchio)) <= ROUNDING * np.max(np.abs(pinocchio))


def test_its_derivatives_match_central_differences(case):
    scene, tree, (q, qd, _, tau) = case
    truth = derivatives(tree, q, qd, tau)
    mass, bias = _mass_and_bias(tree, q, qd)
    qdd = np.linalg.solve(mass, (tau - bias)[:, :, None])[:, :, 0]
    for name, moved in (("dtau_dq", 0), ("dtau_dqdot", 1)):
        columns = []
        for e in np.eye(scene.chain.n_joints):
            plus, minus = [q, qd], [q, qd]
            plus[moved], minus[moved] = plus[moved] + FD_STEP * e, minus[moved] - FD_STEP * e
            columns.append((rnea(tree, *plus, qdd) - rnea(tree, *minus, qdd)).real / (2 * FD_STEP))
        fd = np.stack(columns, axis=-1)
        reference = getattr(truth, name)
        assert np.max(np.abs(fd - reference)) <= FD_AGREEMENT * np.max(np.abs(reference)), name
    exact_mass = np.linalg.inv(truth.dqddot_dtau)
    assert np.max(np.abs(exact_mass - mass)) <= ROUNDING * np.max(np.abs(mass))  # dtau/dqddot = M


def _spong(m1=1.3, m2=0.8, l1=0.9, lc1=0.4, lc2=0.35, i1=0.07, i2=0.03, damping=(0.2, 0.1)) -> Chain:
    """Spong's planar elbow arm about z, gravity along -y: every centre of mass on its link's x axis."""
    def link(mass, lc, inertia):
        return LinkInertia(mass, np.array([lc, 0.0, 0.0]), np.diag([inertia, inertia, inertia]))

    return Chain("spong", (
        Joint("q1", "revolute", np.array([0.0, 0.0, 1.0]), np.zeros(3), np.eye(3), link=link(m1, lc1, i1),
              damping=damping[0]),
        Joint("q2", "revolute", np.array([0.0, 0.0, 1.0]), np.array([l1, 0.0, 0.0]), np.eye(3), link=link(m2, lc2, i2),
              damping=damping[1])))


def test_the_planar_arm_s_closed_form_derivatives_to_rounding():
    """tau = M(q2) qdd + C(q, qd) qd + g(q) + D qd of the elbow manipulator (Spong, Hutchinson and Vidyasagar),
    differentiated by hand."""
    m1, m2, l1, lc1, lc2, i1, i2, g0 = 1.3, 0.8, 0.9, 0.4, 0.35, 0.07, 0.03, 9.81
    chain = _spong()
    tree = tree_from_chain(chain, np.array([0.0, -g0, 0.0]))
    rng = np.random.default_rng(44)
    q, qd, tau = (rng.uniform(-2, 2, (5, 2)) for _ in range(3))
    truth = derivatives(tree, q, qd, tau)
    mass, bias = _mass_and_bias(tree, q, qd)
    qdd = np.linalg.solve(mass, (tau - bias)[:, :, None])[:, :, 0]
    b = m2 * l1 * lc2
    s2, c2 = np.sin(q[:, 1]), np.cos(q[:, 1])
    s1, s12 = np.sin(q[:, 0]), np.sin(q[:, 0] + q[:, 1])
    weight1, weight2 = (m1 * lc1 + m2 * l1) * g0, m2 * lc2 * g0
    by_q = np.stack([
        np.stack([-weight1 * s1 - weight2 * s12,
                  -2 * b * s2 * qdd[:, 0] - b * s2 * qdd[:, 1] - b * c2 * (2 * qd[:, 0] * qd[:, 1] + qd[:, 1] ** 2)
                  - weight2 * s12], -1),
        np.stack([-weight2 * s12, -b * s2 * qdd[:, 0] + b * c2 * qd[:, 0] ** 2 - weight2 * s12], -1)], 1)
    by_qd = np.stack([
        np.stack([-2 * b * s2 * qd[:, 1] + 0.2, -2 * b * s2 * (qd[:, 0] + qd[:, 1])], -1),
        np.stack([2 * b * s2 * qd[:, 0], np.full(len(q), 0.1)], -1)], 1)
    assert np.max(np.abs(truth.dtau_dq - by_q)) <= 1e-14 * np.max(np.abs(by_q))
    assert np.max(np.abs(truth.dtau_dqdot - by_qd)) <= 1e-14 * np.max(np.abs(by_qd))
    del i1, i2  # the inertias enter M, not these partials at the solved qddot


def test_it_is_complex_safe():
    """A complex input's imaginary part carries through as the derivative (no part dropped or conjugated), and the
    RNEA raises if anything casts complex to real (ComplexWarning is an error inside it)."""
    scene = library.load(["oblique-arm-dynamics"])[0]
    tree = tree_from_chain(scene.chain, scene.gravity_world)
    q, qd, qdd, _ = (x[:3] for x in scene.states())
    perturbed = rnea(tree, q + 1e-30j, qd, qdd)
    assert perturbed.dtype == complex and np.all(perturbed.imag != 0)
    real = rnea(tree, q, qd, qdd)  # the real part is the function itself, to the rounding of complex products
    assert np.max(np.abs(perturbed.real - real)) <= ROUNDING * np.max(np.abs(real))
