"""PyBullet calculateInverseKinematics adapter: settings, conventions and honest failure reports."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.core.ik.jacobian_solvers import IKOptions
from tests.helpers import IIWA, REVOLUTE7, build_ik, reachable_targets, reached_rate

OPTIONS = IKOptions()  # 1e-6 m, 1e-6 rad, 200 iterations
N_TARGETS = 100
TUNED = "calculateInverseKinematics-tuned"


# Measured solve rates (100 targets, start q = 0): iiwa pose 0.99, iiwa position 1.00,
# 7R pose 0.89, 7R position 1.00.
@pytest.mark.parametrize("chain, pose, required", [
    (IIWA, True, 0.95), (IIWA, False, 0.97), (REVOLUTE7, True, 0.8), (REVOLUTE7, False, 0.97)])
def test_tuned_solves_reachable_targets(chain, pose, required):
    """The tuned solver reaches the stated share of reachable targets (pose ones: the quaternion order is right)."""
    p, r = reachable_targets(chain, N_TARGETS, seed=0)
    result = build_ik("pybullet", chain, TUNED, OPTIONS).solve(p, r if pose else None, np.zeros(chain.n_joints))
    assert reached_rate(result) >= required
    assert np.all(result.position_residual[result.success] <= OPTIONS.position_tolerance)
    assert np.all(result.iterations == -1)
    assert not np.any(result.reason == "unreachable")


def test_defaults_stop_early():
    """PyBullet as users call it (20 iterations, 1e-4 m) reaches almost no target to 1e-6, the tuned one nearly all."""
    p, r = reachable_targets(IIWA, N_TARGETS, seed=1)
    default = build_ik("pybullet", IIWA, "calculateInverseKinematics", OPTIONS).solve(p, r, np.zeros(7))
    tuned = build_ik("pybullet", IIWA, TUNED, OPTIONS).solve(p, r, np.zeros(7))
    # Measured: 0.00 and 1.00; default median position residual 6.7e-2 m.
    assert default.solve_rate <= 0.05
    assert reached_rate(tuned) >= 0.95
    assert np.median(default.position_residual) > 1e-3
    assert set(default.reason.tolist()) == {"iteration_cap"}






def test_every_target_starts_from_q_start():
    """Joints are reset before each target: a batch gives what each target gives alone, in any order."""
    p, r = reachable_targets(IIWA, 10, seed=4)
    model = build_ik("pybullet", IIWA, "calculateInverseKinematics", OPTIONS)  # 20 iterations: the result depends on the start
    q_start = np.full(7, 0.3)
    batch = model.solve(p, r, q_start)
    for k in reversed(range(len(p))):
        alone = model.solve(p[k:k + 1], r[k:k + 1], q_start)
        np.testing.assert_array_equal(alone.q[0], batch.q[k])
    other_start = model.solve(p, r, np.zeros(7))
    assert np.abs(other_start.q - batch.q).max() > 1e-3


def test_limit_violation_reported_not_clamped():
    """Solutions outside the limits come back as they are, with the amount in limit_violation."""
    p, r = reachable_targets(IIWA, N_TARGETS, seed=5)
    result = build_ik("pybullet", IIWA, TUNED, OPTIONS).solve(p, r, np.zeros(7))
    outside = np.maximum(np.maximum(IIWA.lower - result.q, result.q - IIWA.upper), 0.0).max(axis=1)
    np.testing.assert_array_equal(result.limit_violation, outside)
    # Measured: 13 of 100 solutions leave the limits.
    assert np.sum(result.limit_violation > 0) >= 5


@pytest.mark.slow
def test_nullspace_variant_respects_limits_more_but_stops_short():
    """Limits and rest pose keep more solutions inside the limits; the damped projector leaves ~mm residuals."""
    p, r = reachable_targets(IIWA, N_TARGETS, seed=6)
    q_start = np.random.default_rng(7).uniform(IIWA.lower, IIWA.upper)
    tuned = build_ik("pybullet", IIWA, TUNED, OPTIONS).solve(p, r, q_start)
    nullspace = build_ik("pybullet", IIWA, "calculateInverseKinematics-tuned-nullspace", OPTIONS).solve(p, r, q_start)
    # Measured: 68 vs 56 solutions outside the limits; median residual 8.8e-3 m, none solved.
    assert np.sum(nullspace.limit_violation > 0) < np.sum(tuned.limit_violation > 0)
    assert np.median(nullspace.position_residual) > 1e-4
    assert nullspace.solve_rate <= 0.05
