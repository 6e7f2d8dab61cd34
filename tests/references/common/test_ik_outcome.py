"""The engines' IK verdict (references/common/ik_outcome.py): hand-made residuals and joint values."""

import numpy as np

from simparity.core.model.ik_problem import IKTolerances
from simparity.core.model.ik_result import LIMIT_TOLERANCE
from simparity.core.model.scenes.chain import Chain, Joint
from simparity.references.common.ik_outcome import ik_outcome

# A planar 2-link arm, links 1.0 m and 0.8 m: reach 1.8 m from the first joint.
ELBOW_LOWER, ELBOW_UPPER = 0.2, 2.0
CHAIN = Chain(
    name="arm",
    joints=(Joint("shoulder", "revolute", (0.0, 0.0, 1.0), (0.0, 0.0, 0.0), np.eye(3), -np.pi, np.pi),
            Joint("elbow", "revolute", (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), np.eye(3), ELBOW_LOWER, ELBOW_UPPER)),
    end_effector_name="tip", end_effector_xyz=(0.8, 0.0, 0.0), end_effector_rotation=np.eye(3),
)
TOLERANCES = IKTolerances(position_tolerance=1e-6, orientation_tolerance=1e-6)


def _judge(q, position_residual, target):
    q = np.atleast_2d(np.asarray(q, float))
    return ik_outcome(CHAIN, q, np.full(len(q), 5), np.asarray(position_residual, float), np.zeros(len(q)),
                      np.atleast_2d(np.asarray(target, float)), TOLERANCES)


def test_a_reached_target_outside_the_limits_is_not_solved():
    # elbow at 2.45 rad: 0.45 rad past its upper limit; the residual is within tolerance
    result = _judge([[0.0, 2.45]], [1e-9], [[0.5, 0.5, 0.0]])
    assert not result.success[0]
    assert result.reason[0] == "outside_limits"
    assert abs(result.limit_violation[0] - 0.45) < 1e-12


def test_rounding_at_a_limit_still_counts_as_inside():
    result = _judge([[0.0, ELBOW_UPPER + 0.5 * LIMIT_TOLERANCE]], [1e-9], [[0.5, 0.5, 0.0]])
    assert result.success[0] and result.reason[0] == ""


def test_beyond_the_reach_bound_is_reported_unreachable():
    # 2.0 m from the first joint, the reach is 1.8 m
    result = _judge([[0.0, 0.5]], [0.2], [[2.0, 0.0, 0.0]])
    assert not result.success[0] and result.reason[0] == "unreachable"


def test_a_reachable_miss_is_an_iteration_cap():
    result = _judge([[0.0, 0.5]], [1e-3], [[1.0, 0.5, 0.0]])
    assert not result.success[0] and result.reason[0] == "iteration_cap"
