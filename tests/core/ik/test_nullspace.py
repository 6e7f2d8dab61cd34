"""The lecture's null-space control expression: it does not move the end effector and descends H."""

from __future__ import annotations

import os

import numpy as np
import pybullet_data
import pytest

from simparity.core.ik.jacobian_solvers import IKOptions, solve_ik
from simparity.core.ik.nullspace import limit_penalty_gradient, nullspace_term, penalty, penalty_gradient
from simparity.core.kinematics import jacobian_world, joint_frames
from simparity.core.rotations import so3_log
from simparity.core.urdf import chain_from_urdf

IIWA = chain_from_urdf(os.path.join(pybullet_data.getDataPath(), "kuka_iiwa/model.urdf"))

# J (J+ J - I) z = 0 holds exactly; with |J| ~ 2 and |z| ~ 1 float64 leaves ~1e-15.
NULLSPACE_TOLERANCE = 1e-12
# Central differences of H with step 1e-6 have truncation ~1e-12 and rounding ~1e-10.
GRADIENT_TOLERANCE = 1e-7
# The IK success tolerances of the control-loop test [m] and [rad].
POSITION_TOLERANCE = 1e-6
ORIENTATION_TOLERANCE = 1e-6
# The slide's J^T (J J^T)^-1 form solves with J J^T, whose condition number kappa (up to
# ~2e8 at these configurations) amplifies rounding: the two forms may differ by
# kappa * eps * |z| per configuration (measured: at most a tenth of that).
LECTURE_FORM_ROUNDING = 1.0
N_CONFIGURATIONS = 200


def _random_q(rng, n: int) -> np.ndarray:
    return rng.uniform(IIWA.lower, IIWA.upper, size=(n, IIWA.n_joints))


@pytest.mark.parametrize("rows", [3, 6], ids=["position", "pose"])
def test_nullspace_term_does_not_move_the_end_effector(rows):
    """J (J+ J - I) z = 0 to 1e-12 at seeded configurations of the redundant iiwa, singular ones included."""
    rng = np.random.default_rng(31)
    q = np.concatenate([_random_q(rng, N_CONFIGURATIONS), np.zeros((1, 7))])  # q = 0 is singular
    jac = jacobian_world(IIWA, q)[:, :rows]
    z = rng.normal(size=q.shape)
    term = nullspace_term(jac, z)
    np.testing.assert_allclose(np.einsum("bmn,bn->bm", jac, term), 0.0, rtol=0, atol=NULLSPACE_TOLERANCE)
    # ... and it is a descent direction of H whenever z has a null-space part.
    assert np.all(np.einsum("bn,bn->b", term, z) < 0)


def test_nullspace_term_matches_the_lecture_formula():
    """(J+ J - I) z equals the slide's J^T (J J^T)^-1 J z - z for a full-row-rank J."""
    rng = np.random.default_rng(32)
    jac = jacobian_world(IIWA, _random_q(rng, N_CONFIGURATIONS))
    z = rng.normal(size=(N_CONFIGURATIONS, 7))
    jt = np.swapaxes(jac, 1, 2)
    jz = np.einsum("bmn,bn->bm", jac, z)
    expected = np.einsum("bnm,bm->bn", jt, np.linalg.solve(jac @ jt, jz[..., None])[..., 0]) - z
    bound = LECTURE_FORM_ROUNDING * np.linalg.cond(jac @ jt) * np.finfo(float).eps * np.linalg.norm(z, axis=1)
    assert np.all(np.abs(nullspace_term(jac, z) - expected).max(axis=1) <= bound)


@pytest.mark.parametrize("exponent", [1.0, 2.0, 2.5, 3.0, 4.0])
def test_penalty_is_a_penalty_with_its_gradient(exponent):
    """H = sum alpha |q - q_c|^Psi is >= 0, 0 only at q_c, and penalty_gradient is its derivative."""
    rng = np.random.default_rng(33)
    q = rng.uniform(-2, 2, size=(N_CONFIGURATIONS, 7))
    center = rng.uniform(-1, 1, size=7)
    gain = rng.uniform(0.1, 2.0, size=7)
    h = penalty(q, center, gain, exponent)
    assert np.all(h > 0) and penalty(center[None], center, gain, exponent)[0] == 0
    if exponent == 2.0:
        np.testing.assert_allclose(h, np.sum(gain * (q - center) ** 2, axis=1), rtol=1e-14)
    step = 1e-6
    numeric = np.stack([(penalty(q + step * e, center, gain, exponent) - penalty(q - step * e, center, gain, exponent))
                        / (2 * step) for e in np.eye(7)], axis=1)
    np.testing.assert_allclose(penalty_gradient(q, center, gain, exponent), numeric, rtol=0, atol=GRADIENT_TOLERANCE)


def test_penalty_gradient_rejects_exponents_below_one():
    """Psi < 1 has an infinite gradient at q_c and is refused."""
    with pytest.raises(ValueError, match="exponent"):
        penalty_gradient(np.zeros((1, 2)), np.zeros(2), 1.0, 0.5)


def test_limit_penalty_pushes_toward_mid_range_on_limited_joints_only():
    """Liegeois' gradient is q - mid scaled by 2 gain / range^2, and 0 on unlimited joints."""
    lower, upper = np.array([-1.0, 0.0, -np.inf]), np.array([1.0, 4.0, np.inf])
    q = np.array([[0.5, 3.0, 7.0]])
    np.testing.assert_allclose(limit_penalty_gradient(q, lower, upper, 2.0), [[2 * 2 * 0.5 / 4, 2 * 2 * 1 / 16, 0.0]])


@pytest.mark.slow
def test_control_expression_pulls_joints_toward_rest_pose():
    """theta += J+ V + dt (J+ J - I) grad H: H falls every step while the pose residual stays within tolerance."""
    rng = np.random.default_rng(34)
    q = _random_q(rng, 20) * 0.8  # away from the limits
    positions, rotations, _ = joint_frames(IIWA, q)
    target_p, target_r = positions[:, -1], rotations[:, -1]
    center = _random_q(rng, 1)[0] * 0.8
    # dt keeps the null-space step <= ~2e-3 rad per iteration, so its second-order drift of
    # the end effector (~5e-7 m measured) stays below the tolerance that J+ V then removes.
    gain, exponent, dt = 1.0, 2.0, 4e-4
    h_start = penalty(q, center, gain, exponent)
    h_previous = h_start
    for _ in range(500):
        jac = jacobian_world(IIWA, q)
        p, r, _ = joint_frames(IIWA, q)
        velocity = np.concatenate([target_p - p[:, -1], so3_log(target_r @ np.swapaxes(r[:, -1], 1, 2))], axis=1)
        q = q + np.einsum("bnm,bm->bn", np.linalg.pinv(jac), velocity) + dt * nullspace_term(
            jac, penalty_gradient(q, center, gain, exponent))
        p, r, _ = joint_frames(IIWA, q)
        assert np.all(np.linalg.norm(p[:, -1] - target_p, axis=1) <= POSITION_TOLERANCE)
        angle = np.linalg.norm(so3_log(target_r @ np.swapaxes(r[:, -1], 1, 2)), axis=1)
        assert np.all(angle <= ORIENTATION_TOLERANCE)
        h = penalty(q, center, gain, exponent)
        assert np.all(h < h_previous)
        h_previous = h
    # Some rest poses lie almost square to the one-dimensional self-motion; on average H
    # falls by ~8 % over these 500 steps.
    assert h_previous.mean() < 0.95 * h_start.mean()


# Mean H with the rest-pose term over mean H without must fall below this: position
# targets leave 4 redundant joints to pull (measured ratio ~0.78), pose targets only the
# one-dimensional self-motion (~0.91).
@pytest.mark.parametrize("pose, ratio", [(False, 0.85), pytest.param(True, 0.95, marks=pytest.mark.slow)],
                         ids=["position", "pose"])
def test_rest_pose_option_gives_solutions_nearer_the_rest_pose(pose, ratio):
    """solve_ik with rest_pose solves the same targets and ends nearer theta_c on average."""
    rng = np.random.default_rng(35)
    positions, rotations, _ = joint_frames(IIWA, _random_q(rng, 100))
    target_rotation = rotations[:, -1] if pose else None
    rest, start = np.zeros(7), np.full(7, 0.2)
    plain = solve_ik(IIWA, positions[:, -1], target_rotation, start)
    pulled = solve_ik(IIWA, positions[:, -1], target_rotation, start, options=IKOptions(rest_pose=rest))
    both = plain.success & pulled.success
    assert np.count_nonzero(both) >= 95
    assert penalty(pulled.q[both], rest, 1.0).mean() < ratio * penalty(plain.q[both], rest, 1.0).mean()
