"""Restart starts near the target in pose (core/ik/pose_seeds.py) and a target's starts stopped at its first solution
(solve_ik's starts_per_target)."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.core.ik.jacobian_solvers import IKOptions, solve_ik
from simparity.core.ik.pose_seeds import nearest_pose_starts
from simparity.core.ik.restarts import Restarts
from simparity.core.kinematics import packed_frames
from simparity.core.model.scenes.chain import sample_configurations
from simparity.core.rotations import so3_log
from tests.helpers import builtin

TARGETS = 200
NEARER = 0.5
"""The nearest poses' median position error is below half the uniform draws' (a pool of 1,024 or more poses covers
the workspace far more densely than one draw per target)."""


@pytest.fixture(scope="module")
def arm():
    chain = builtin("bench-panda-ik").chain
    q = sample_configurations(chain, TARGETS, 7)
    frames = packed_frames(chain, q)
    return chain, frames.positions[-1].T, frames.end_rotation.transpose(2, 0, 1)


def _pose_errors(chain, q, position, rotation):
    frames = packed_frames(chain, q)
    angle = np.linalg.norm(so3_log(rotation @ frames.end_rotation.transpose(2, 1, 0)), axis=1)
    return np.linalg.norm(frames.positions[-1].T - position, axis=1), angle


def test_nearest_starts_are_within_the_limits_deterministic_and_nearer_than_uniform_draws(arm):
    chain, position, rotation = arm
    starts = nearest_pose_starts(chain, position, rotation, 3, np.random.default_rng(1))
    assert starts.shape == (TARGETS * 3, chain.n_joints)
    assert np.all((starts >= chain.lower) & (starts <= chain.upper))
    np.testing.assert_array_equal(starts, nearest_pose_starts(chain, position, rotation, 3, np.random.default_rng(1)))
    first = starts[::3]  # each target's nearest
    near_position, near_angle = _pose_errors(chain, first, position, rotation)
    uniform_position, uniform_angle = _pose_errors(chain, sample_configurations(chain, TARGETS, 2), position, rotation)
    assert np.median(near_position) < NEARER * np.median(uniform_position)
    assert np.median(near_angle) < NEARER * np.median(uniform_angle)


def test_position_targets_compare_positions_only(arm):
    chain, position, _ = arm
    starts = nearest_pose_starts(chain, position, None, 2, np.random.default_rng(3))
    near, _ = _pose_errors(chain, starts[::2], position, np.broadcast_to(np.eye(3), (TARGETS, 3, 3)))
    second, _ = _pose_errors(chain, starts[1::2], position, np.broadcast_to(np.eye(3), (TARGETS, 3, 3)))
    assert np.all(near <= second)  # nearest first


def test_a_run_of_starts_stops_at_its_first_solution(arm):
    """Each target from its own configuration (solved at once) and from a far one: as one run of 2, the far start
    stops when its sibling is solved; as separate targets it iterates on."""
    chain, position, rotation = arm
    exact = sample_configurations(chain, TARGETS, 7)  # the configurations the targets were made from
    far = sample_configurations(chain, TARGETS, 8)
    rows = np.repeat(np.arange(TARGETS), 2)
    q0 = np.stack([exact, far], axis=1).reshape(-1, chain.n_joints)
    options = Restarts().attempt_options(IKOptions())  # short attempts, as restarts make them
    runs = solve_ik(chain, position[rows], rotation[rows], q0, "damped_least_squares", options, starts_per_target=2)
    alone = solve_ik(chain, position[rows], rotation[rows], q0, "damped_least_squares", options)
    assert np.all(runs.success[::2]) and np.all(runs.iterations[1::2] == 0)
    assert np.all(runs.reason[1::2][~runs.success[1::2]] == "iteration_cap")
    assert np.sum(alone.iterations[1::2]) > 0
    with pytest.raises(ValueError, match="starts_per_target"):
        solve_ik(chain, position[:3], rotation[:3], exact[:3], "damped_least_squares", options, starts_per_target=2)
