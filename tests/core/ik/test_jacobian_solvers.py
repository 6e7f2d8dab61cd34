"""Iterative Jacobian IK: the update rules, the batch solver, its limits and its failure reports."""

from __future__ import annotations

import os

import numpy as np
import pybullet_data
import pytest

from simparity.core.dh import UR5_DH, chain_from_dh
from simparity.core.ik.jacobian_solvers import METHODS, IKOptions, solve_ik
from simparity.core.ik.reach import reach_upper_bound
from simparity.core.model.ik_result import REASONS, IKResult
from simparity.core.ik import steps
from simparity.core.ik.limits import cross_gap, crossable_gap, wrap_into_limits
from simparity.core.kinematics import joint_frames
from simparity.core.rotations import so3_exp
from simparity.core.model.scenes.chain import Chain, Joint
from simparity.core.urdf import chain_from_urdf

IIWA = chain_from_urdf(os.path.join(pybullet_data.getDataPath(), "kuka_iiwa/model.urdf"))

# The headline criterion: pose targets solved to these tolerances [m], [rad] ...
POSITION_TOLERANCE = 1e-6
ORIENTATION_TOLERANCE = 1e-6
# ... in at least this fraction of 1000 seeded targets, from one start pose.
REQUIRED_SOLVE_RATE = 0.995
N_TARGETS = 1000
# The pseudo-inverse forms vs numpy's SVD pinv on matrices with condition number <= ~1e3:
# Gram-matrix solves square it, leaving ~1e-10 relative.
PINV_TOLERANCE = 1e-9
# Closed-form algebra identities evaluated in float64 on O(1) matrices.
ALGEBRA_TOLERANCE = 1e-12
# A solver that stalls at a singular configuration stops where progress fell below
# stall_ratio = 0.1 % per 30 iterations: within ~1e-3 m of the closest point.
STALL_TOLERANCE = 1e-3


def _pose_targets(chain: Chain, n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    q = rng.uniform(chain.lower, chain.upper, size=(n, chain.n_joints))
    positions, rotations, _ = joint_frames(chain, q)
    return q, positions[:, -1], rotations[:, -1]


def _assert_well_formed(result: IKResult, chain: Chain) -> None:
    for name in ("q", "position_residual", "orientation_residual", "limit_violation"):
        assert np.all(np.isfinite(getattr(result, name))), name
    assert np.all((result.q >= chain.lower) & (result.q <= chain.upper))
    assert np.all(result.limit_violation == 0)
    assert set(result.reason.tolist()) <= set(REASONS)


def _one_link(lower: float, upper: float) -> Chain:
    """A 1 m link turning about z: q is the end point's angle."""
    joint = Joint("j", "revolute", (0, 0, 1), (0, 0, 0), np.eye(3), lower, upper)
    return Chain("one_link", (joint,), end_effector_xyz=(1.0, 0.0, 0.0))


# --------------------------------------------------------------------------- headline


@pytest.mark.slow
@pytest.mark.parametrize("method", ["damped_least_squares", "pseudo_inverse"])
def test_iiwa_pose_targets_from_one_start(method):
    """>= 99.5 % of 1000 seeded reachable iiwa pose targets solve from q = 0, all inside the limits."""
    _, positions, rotations = _pose_targets(IIWA, N_TARGETS, seed=0)
    result = solve_ik(IIWA, positions, rotations, np.zeros(7), method=method)
    _assert_well_formed(result, IIWA)
    assert result.solve_rate >= REQUIRED_SOLVE_RATE
    assert np.all(result.position_residual[result.success] <= POSITION_TOLERANCE)
    assert np.all(result.orientation_residual[result.success] <= ORIENTATION_TOLERANCE)
    # Targets come from configurations inside the limits: none is unreachable.
    assert not np.any(result.reason == "unreachable")


@pytest.mark.slow
def test_gap_crossing_raises_the_solve_rate():
    """Escaping through the narrow limit gaps of the iiwa's 350 deg joints solves targets that block otherwise."""
    _, positions, rotations = _pose_targets(IIWA, N_TARGETS, seed=1)
    with_escape = solve_ik(IIWA, positions, rotations, np.zeros(7))
    without = solve_ik(IIWA, positions, rotations, np.zeros(7), options=IKOptions(gap_crossings=0))
    assert with_escape.solve_rate > without.solve_rate
    assert np.all(with_escape.success[without.success] | (with_escape.reason[without.success] != ""))


def test_position_targets():
    """Position-only targets of the redundant iiwa all solve with a zero orientation residual."""
    _, positions, _ = _pose_targets(IIWA, 200, seed=2)
    result = solve_ik(IIWA, positions, None, np.zeros(7))
    _assert_well_formed(result, IIWA)
    assert np.all(result.success)
    assert np.all(result.orientation_residual == 0)


def test_jacobian_inverse_on_a_square_chain():
    """The plain inverse solves UR5 pose targets near a regular start pose, per target start poses too."""
    ur5 = chain_from_dh(**UR5_DH)
    rng = np.random.default_rng(3)
    start = np.array([0.3, -1.2, 1.4, -0.9, -1.3, 0.4])  # away from the UR5's singularities
    q_start = start + rng.uniform(-0.3, 0.3, size=(100, 6))
    positions, rotations, _ = joint_frames(ur5, q_start + rng.uniform(-0.2, 0.2, size=(100, 6)))
    result = solve_ik(ur5, positions[:, -1], rotations[:, -1], q_start, method="jacobian_inverse")
    _assert_well_formed(result, ur5)
    assert np.all(result.success)


def test_jacobian_inverse_needs_a_square_jacobian():
    """The inverse method refuses a 7-joint chain with a 6-row task."""
    _, positions, rotations = _pose_targets(IIWA, 2, seed=4)
    with pytest.raises(ValueError, match="square"):
        solve_ik(IIWA, positions, rotations, method="jacobian_inverse")


def test_transpose_method_reduces_the_error():
    """The transpose method is slow but lowers every residual, staying within the limits."""
    _, positions, rotations = _pose_targets(IIWA, 100, seed=5)
    start = np.full(7, 0.1)
    p0, r0, _ = joint_frames(IIWA, start)
    result = solve_ik(IIWA, positions, None, start, method="transpose", options=IKOptions(max_iterations=50))
    _assert_well_formed(result, IIWA)
    assert np.all(result.position_residual < np.linalg.norm(positions - p0[:, -1], axis=1))


# --------------------------------------------------------------------------- update rules


def test_pseudo_inverse_forms_match_svd_pinv():
    """Left form for tall J, right form for wide J, truncated SVD for rank-deficient J: all equal pinv."""
    rng = np.random.default_rng(6)
    tall = rng.normal(size=(50, 6, 4))
    wide = rng.normal(size=(50, 3, 7))
    deficient = rng.normal(size=(50, 6, 2)) @ rng.normal(size=(50, 2, 7))  # rank 2 < min(6, 7)
    for jac in (tall, wide, deficient):
        err = rng.normal(size=jac.shape[:2])
        expected = np.einsum("bnm,bm->bn", np.linalg.pinv(jac, rcond=1e-6), err)
        np.testing.assert_allclose(steps.pseudo_inverse_step(jac, err, 1e-6), expected, rtol=0, atol=PINV_TOLERANCE)
    assert not np.any(steps.full_rank(deficient, 1e-6)) and np.all(steps.full_rank(wide, 1e-6))


def test_jacobian_inverse_step_stops_at_singular_jacobians():
    """J^-1 e where J is invertible, a zero update where it is singular."""
    rng = np.random.default_rng(7)
    jac = rng.normal(size=(2, 6, 6))
    jac[1, :, 5] = jac[1, :, 4]
    err = rng.normal(size=(2, 6))
    dq = steps.jacobian_inverse_step(jac, err, 1e-6)
    np.testing.assert_allclose(jac[0] @ dq[0], err[0], rtol=0, atol=PINV_TOLERANCE)
    np.testing.assert_array_equal(dq[1], 0.0)


def test_transpose_step_uses_the_best_step_along_jt_e():
    """Buss' alpha minimises the linearised error |e - J dq| along J^T e; a zero J gives a zero step."""
    rng = np.random.default_rng(8)
    jac = rng.normal(size=(100, 6, 7))
    err = rng.normal(size=(100, 6))
    dq = steps.transpose_step(jac, err)

    def linear_error(scale):
        return np.linalg.norm(err - scale * np.einsum("bmn,bn->bm", jac, dq), axis=1)

    assert np.all(linear_error(1.0) <= linear_error(0.99)) and np.all(linear_error(1.0) <= linear_error(1.01))
    np.testing.assert_array_equal(steps.transpose_step(np.zeros((1, 3, 2)), np.ones((1, 3))), 0.0)


def test_damped_least_squares_damps_only_near_singularities():
    """DLS is J^T (J J^T + lambda^2 I)^-1 e with lambda = 0 above the threshold, scheduled below it."""
    rng = np.random.default_rng(9)
    u, _ = np.linalg.qr(rng.normal(size=(6, 6)))
    v, _ = np.linalg.qr(rng.normal(size=(7, 7)))
    err = rng.normal(size=(1, 6))
    threshold, damping_max = 0.1, 0.05
    for smallest in (0.5, 0.04, 0.0):
        sigma = np.array([2.0, 1.5, 1.0, 0.8, 0.6, smallest])
        jac = (u @ np.diag(sigma) @ v[:6])[None]
        dq = steps.damped_least_squares_step(jac, err, threshold, damping_max)
        lam2 = damping_max**2 * max(0.0, 1 - (smallest / threshold) ** 2)
        expected = jac[0].T @ np.linalg.solve(jac[0] @ jac[0].T + lam2 * np.eye(6), err[0])
        np.testing.assert_allclose(dq[0], expected, rtol=0, atol=ALGEBRA_TOLERANCE)
        assert (lam2 == 0) == (smallest >= threshold)


# --------------------------------------------------------------------------- joint limits


def test_wrap_into_limits():
    """Revolute values outside the limits move by 2 pi into them when they can; others stay."""
    lower, upper = np.array([-3.0, -3.0, -1.0, -np.inf]), np.array([3.0, 3.0, 1.0, np.inf])
    revolute = np.array([True, False, True, True])
    q = np.array([[3.4, 3.4, 1.5, 9.0]])
    wrapped = wrap_into_limits(q, revolute, lower, upper)
    np.testing.assert_allclose(wrapped, [[3.4 - 2 * np.pi, 3.4, 1.5, 9.0]], rtol=0, atol=ALGEBRA_TOLERANCE)
    q_gap = np.array([[3.1, 0.0, 0.0, 0.0]])  # 3.1 - 2 pi = -3.18 < -3: in the gap, left alone
    np.testing.assert_array_equal(wrap_into_limits(q_gap, revolute, lower, upper), q_gap)


def test_crossable_gaps_and_crossing():
    """Only revolute joints whose gap 2 pi - range is below max_step can be crossed, to the other limit."""
    lower, upper = np.array([-3.0, -2.0, -3.0, -np.inf]), np.array([3.0, 2.0, 3.0, np.inf])
    revolute = np.array([True, True, False, True])
    np.testing.assert_array_equal(crossable_gap(revolute, lower, upper, 0.75), [True, False, False, False])
    q = np.array([[3.0, 2.0, 0.0, 0.0], [-3.0, 0.0, 0.0, 0.0]])
    crossed = cross_gap(q, np.array([[True, False, False, False]] * 2), lower, upper)
    np.testing.assert_array_equal(crossed[:, 0], [-3.0, 3.0])
    np.testing.assert_array_equal(crossed[:, 1:], q[:, 1:])


def test_solver_wraps_through_the_short_way():
    """A target just past the limit gap is reached by wrapping, not by the long way round or by leaving the limits."""
    chain = _one_link(-3.0, 3.0)
    target = np.array([[np.cos(-2.95), np.sin(-2.95), 0.0]])
    result = solve_ik(chain, target, None, np.array([2.9]), method="pseudo_inverse")
    assert result.success[0] and result.iterations[0] <= 3
    np.testing.assert_allclose(result.q[0], [-2.95], rtol=0, atol=1e-6)


@pytest.mark.slow
def test_start_outside_limits_is_clipped_and_every_method_stays_inside():
    """Starts beyond the limits and targets beyond them never give a returned q outside the limits."""
    _, positions, rotations = _pose_targets(IIWA, 50, seed=10)
    start = np.full(7, 3.5)
    for method in ("pseudo_inverse", "transpose", "damped_least_squares"):
        result = solve_ik(IIWA, positions, rotations, start, method=method, options=IKOptions(max_iterations=30))
        _assert_well_formed(result, IIWA)


def test_limit_blocked_target_is_reported():
    """A target that needs a joint beyond its limit ends as limit_blocked at the limit."""
    chain = _one_link(-0.5, 0.5)
    target = np.array([[np.cos(1.0), np.sin(1.0), 0.0]])
    for method in ("pseudo_inverse", "transpose", "damped_least_squares"):
        result = solve_ik(chain, target, None, np.zeros(1), method=method)
        assert result.reason[0] == "limit_blocked"
        np.testing.assert_array_equal(result.q[0], [0.5])
        _assert_well_formed(result, chain)


# --------------------------------------------------------------------------- hard targets


def _hard_targets(chain: Chain) -> tuple[np.ndarray, dict[str, slice]]:
    center, radius = reach_upper_bound(chain)
    up = np.array([0.0, 0.0, 1.0])
    positions = np.array([
        center + [1.5, 0.0, 0.0], center + [0.0, 0.0, 10.0], center - 3.0 * up,  # beyond the reach bound
        center, [0.0, 0.0, 0.0],                                                # at the base
        center + radius * up, center + radius * np.array([1.0, 0.0, 0.0]),      # exactly stretched
    ])
    return positions, {"beyond": slice(0, 3), "base": slice(3, 5), "stretched": slice(5, 7)}


@pytest.mark.slow
@pytest.mark.parametrize("method", ["pseudo_inverse", "transpose", "damped_least_squares"])
@pytest.mark.parametrize("pose", [False, True], ids=["position", "pose"])
@pytest.mark.parametrize("start", [0.0, 0.3], ids=["stretched-start", "bent-start"])
def test_hard_targets_fail_cleanly(method, pose, start):
    """Beyond-reach, at-base and exactly stretched targets return finite results; beyond-reach ones are unreachable."""
    positions, groups = _hard_targets(IIWA)
    rotations = np.broadcast_to(np.eye(3), (len(positions), 3, 3)) if pose else None
    result = solve_ik(IIWA, positions, rotations, np.full(7, start), method=method,
                      options=IKOptions(max_iterations=60))
    _assert_well_formed(result, IIWA)
    assert np.all(result.reason[groups["beyond"]] == "unreachable")
    assert np.all(result.success == (result.reason == ""))


@pytest.mark.slow
def test_stretched_toward_a_target_beyond_the_true_reach_is_unreachable():
    """A target inside the (loose) reach bound but beyond the true reach stalls stretched and is unreachable."""
    # Link 1 reaches out 1 m and rises 0.5 m, link 2 is 1 m, both turn about z: the end
    # point stays at z = 0.5 within 2 m of the axis, while the bound is |(1, 0, 0.5)| + 1.
    joints = (Joint("j1", "revolute", (0, 0, 1), (0, 0, 0), np.eye(3)),
              Joint("j2", "revolute", (0, 0, 1), (1.0, 0, 0.5), np.eye(3)))
    chain = Chain("offset", joints, end_effector_xyz=(1.0, 0.0, 0.0))
    target = np.array([[2.04 * np.cos(0.4), 2.04 * np.sin(0.4), 0.5]])
    center, radius = reach_upper_bound(chain)
    assert np.linalg.norm(target - center) < radius
    for method in ("pseudo_inverse", "damped_least_squares"):
        result = solve_ik(chain, target, None, np.array([0.0, 0.3]), method=method)
        assert result.reason[0] == "unreachable"
        np.testing.assert_allclose(result.position_residual[0], 0.04, rtol=0, atol=STALL_TOLERANCE)
    # The transpose method slows down as sigma_min -> 0 and is still creeping when the cap comes.
    result = solve_ik(chain, target, None, np.array([0.0, 0.3]), method="transpose")
    assert result.reason[0] in ("unreachable", "iteration_cap")


@pytest.mark.slow
def test_folded_onto_the_base_is_singular():
    """A planar arm asked for a point inside its inner hole folds up and reports a singularity."""
    chain = chain_from_dh("planar", a=(1.0, 0.6), alpha=(0.0, 0.0), d=(0.0, 0.0), theta_offset=(0.0, 0.0))
    target = np.array([[0.1, 0.05, 0.0]])
    folded_residual = 0.4 - np.hypot(0.1, 0.05)  # the folded arm's end point is 0.4 m from the base
    strong_damping = IKOptions(singular_threshold=0.5, damping_max=0.5)
    for method, options in (("transpose", IKOptions()), ("damped_least_squares", strong_damping)):
        result = solve_ik(chain, target, None, np.array([0.2, 1.0]), method=method, options=options)
        assert result.reason[0] == "singular"
        np.testing.assert_allclose(result.position_residual[0], folded_residual, rtol=0, atol=STALL_TOLERANCE)
    # Undamped Newton steps jump back and forth across the fold (q2 = 2.69 <-> 3.44, where
    # J is far from singular): a failure, but not always recognised as a singular one.
    result = solve_ik(chain, target, None, np.array([0.2, 1.0]), method="pseudo_inverse")
    assert result.reason[0] in ("singular", "iteration_cap")


@pytest.mark.slow
def test_unreachable_orientation_is_a_failure():
    """A planar arm cannot tilt its end effector out of plane: the pose target is reported, not solved."""
    chain = chain_from_dh("planar", a=(1.0, 0.6), alpha=(0.0, 0.0), d=(0.0, 0.0), theta_offset=(0.0, 0.0))
    rotation = so3_exp(np.array([0.5, 0.0, 0.0]))[None]
    result = solve_ik(chain, np.array([[1.0, 0.8, 0.0]]), rotation, np.array([0.2, 1.0]))
    assert not result.success[0] and result.reason[0] in REASONS[1:]
    _assert_well_formed(result, chain)


# --------------------------------------------------------------------------- inputs and result


def test_empty_batch():
    """An empty batch returns an empty result."""
    result = solve_ik(IIWA, np.zeros((0, 3)))
    assert result.q.shape == (0, 7) and result.solve_rate == 0.0


@pytest.mark.parametrize("kwargs, match", [
    ({"target_position": np.zeros((2, 2))}, "target_position"),
    ({"target_position": np.full((1, 3), np.nan)}, "target_position"),
    ({"target_rotation": np.full((1, 3, 3), 2.0)}, "rotation matrices"),
    ({"target_rotation": -np.eye(3)[None]}, "rotation matrices"),
    ({"q_start": np.zeros(6)}, "q_start"),
    ({"method": "newton"}, "unknown IK method"),
])
def test_bad_inputs_are_rejected(kwargs, match):
    """Malformed targets, start poses and method names raise ValueError."""
    args = {"target_position": np.zeros((1, 3)), "target_rotation": None, "q_start": None,
            "method": "damped_least_squares", **kwargs}
    with pytest.raises(ValueError, match=match):
        solve_ik(IIWA, **args)


@pytest.mark.parametrize("field, value, match", [
    ("position_residual", [np.nan], "non-finite"),
    ("q", [[np.inf]], "non-finite"),
    ("reason", ["diverged"], "allowed"),
    ("reason", ["singular"], "success"),
    ("iterations", [1, 2], "shape"),
])
def test_result_rejects_nan_and_unknown_reasons(field, value, match):
    """IKResult refuses NaN, reasons outside the vocabulary and a reason that contradicts success."""
    fields = dict(q=[[0.0]], success=[True], iterations=[1], position_residual=[0.0],
                  orientation_residual=[0.0], limit_violation=[0.0], reason=[""])
    fields[field] = value
    with pytest.raises(ValueError, match=match):
        IKResult(**fields)


def test_options_are_checked():
    """Non-positive tolerances and exponents below one are refused."""
    with pytest.raises(ValueError, match="position_tolerance"):
        IKOptions(position_tolerance=0.0)
    with pytest.raises(ValueError, match="rest_exponent"):
        IKOptions(rest_exponent=0.5)
    with pytest.raises(ValueError, match="error_damping"):
        IKOptions(error_damping=-0.01)


def test_methods_listed():
    """The four lecture methods are offered."""
    assert METHODS == ("jacobian_inverse", "pseudo_inverse", "transpose", "damped_least_squares")


def test_the_batched_cholesky_test_is_positive_definiteness():
    """steps.positive_definite decides damping in DLS without an SVD; it must agree with the eigenvalues."""
    rng = np.random.default_rng(3)
    a = rng.normal(size=(4000, 6, 7))
    gram = a @ a.transpose(0, 2, 1)
    for shift in (0.0, 0.5, 1.0, 3.0):
        shifted = gram - shift * np.eye(6)
        smallest = np.linalg.eigvalsh(shifted)[:, 0]
        clear = np.abs(smallest) > ALGEBRA_TOLERANCE * np.abs(shifted).max()  # rounding decides at 0
        np.testing.assert_array_equal(steps.positive_definite(shifted)[clear], (smallest > 0)[clear])
    assert not steps.positive_definite(np.zeros((1, 6, 6)))[0]


def test_damped_least_squares_is_the_svd_formula():
    """The Gram-matrix form equals V diag(sigma / (sigma^2 + lambda^2)) U^T e, wide, tall and singular J."""
    rng = np.random.default_rng(4)
    for m, n in ((6, 7), (6, 6), (6, 5), (3, 7)):
        jac = rng.normal(size=(200, m, n)) * rng.uniform(0.001, 1, size=(200, 1, 1))
        jac[:20, :, 0] = 0.0  # rank-deficient
        err = rng.normal(size=(200, m))
        u, sigma, vt = np.linalg.svd(jac, full_matrices=False)
        smin = sigma[:, -1]
        lam2 = np.where(smin < 1e-2, 1e-3**2 * (1 - (smin / 1e-2) ** 2), 0.0)
        gain = sigma / (sigma**2 + lam2[:, None])
        expected = np.einsum("bkn,bk,bmk,bm->bn", vt, gain, u, err)
        got = steps.damped_least_squares_step(jac, err, 1e-2, 1e-3)
        np.testing.assert_allclose(got, expected, rtol=PINV_TOLERANCE, atol=PINV_TOLERANCE * np.abs(expected).max())


def test_error_damped_least_squares_is_the_svd_formula_with_levenberg_marquardt_damping():
    """lambda^2 = c |e|^2 + floor^2 in V diag(sigma / (sigma^2 + lambda^2)) U^T e: wide, square, tall (a 5-DOF arm's
    6 x 5) and rank-deficient J, in batches solved by the entry-by-entry Cholesky and by LU (below its batch)."""
    rng = np.random.default_rng(5)
    error_damping, floor = 0.01, 1e-5
    for m, n in ((6, 7), (6, 6), (6, 5), (3, 7)):
        for batch in (steps.CHOLESKY_MIN_BATCH, 20):
            jac = rng.normal(size=(batch, m, n)) * rng.uniform(0.001, 1, size=(batch, 1, 1))
            jac[:10, :, 0] = 0.0  # rank-deficient
            err = rng.normal(size=(batch, m))
            u, sigma, vt = np.linalg.svd(jac, full_matrices=False)
            lam2 = error_damping * np.sum(err**2, axis=1) + floor**2
            expected = np.einsum("bkn,bk,bmk,bm->bn", vt, sigma / (sigma**2 + lam2[:, None]), u, err)
            got = steps.error_damped_least_squares_step(jac, err, error_damping, floor)
            np.testing.assert_allclose(got, expected, rtol=PINV_TOLERANCE,
                                       atol=PINV_TOLERANCE * np.abs(expected).max())


def test_an_abandoned_stall_stops_at_the_same_iteration_unclassified():
    """IKOptions.abandon_stalled (the restarts' attempts): a target beyond reach stops when it stalls, as the
    default rules stop it, but as "iteration_cap", without the singular values of the classification."""
    far = np.array([[5.0, 0.0, 0.0]])  # the iiwa reaches ~1.3 m
    judged = solve_ik(IIWA, far, options=IKOptions(stall_window=5))
    abandoned = solve_ik(IIWA, far, options=IKOptions(stall_window=5, abandon_stalled=True))
    assert (judged.reason[0], abandoned.reason[0]) == ("unreachable", "iteration_cap")
    assert abandoned.iterations[0] == judged.iterations[0] < IKOptions().max_iterations


def test_a_target_astronomically_far_is_refused_with_the_allowed_range():
    """Held-out finding: [1e300, 0, 0] overflowed the squared residual (a RuntimeWarning, then an error about
    IKResult); now the input check names the coordinate and the allowed range."""
    with pytest.raises(ValueError, match=r"coordinate of 1e\+300 m \(allowed: up to 1e\+09 m"):
        solve_ik(IIWA, np.array([[1e300, 0.0, 0.0]]))
    far = solve_ik(IIWA, np.array([[1e8, 0.0, 0.0]]))
    assert far.reason.tolist() == ["unreachable"]
