"""The bookkeeping of a batch of IK targets: best configurations, stall counts, solved and stopped targets."""

import numpy as np

from simparity.core.ik.batch_progress import BatchProgress
from simparity.core.model.ik_result import IKReason

STALL_RATIO = 0.1


def test_a_batch_keeps_each_targets_best_and_lets_solved_and_stopped_ones_go():
    progress = BatchProgress.start(np.zeros((4, 2)), gap_crossings=1)
    idx = progress.unsolved()
    assert idx.tolist() == [0, 1, 2, 3]
    progress.observe(idx, np.ones((4, 2)), np.array([1.0, 2.0, 3.0, 4.0]), np.array([False, True, False, False]),
                     STALL_RATIO)
    assert progress.unsolved().tolist() == [0, 2, 3] and progress.reason[1] == IKReason.SOLVED
    assert np.array_equal(progress.best_q, np.ones((4, 2))) and progress.since_best.tolist() == [0, 0, 0, 0]

    idx = progress.unsolved()  # worse for 0, a little better for 2 (not a tenth), better for 3
    progress.observe(idx, np.full((3, 2), 2.0), np.array([1.5, 2.9, 1.0]), np.zeros(3, bool), STALL_RATIO)
    assert progress.best_q[:, 0].tolist() == [1.0, 1.0, 2.0, 2.0]
    assert progress.best_merit.tolist() == [1.0, 2.0, 2.9, 1.0] and progress.since_best.tolist() == [1, 0, 1, 0]
    assert progress.stalled(idx, window=1).tolist() == [0, 1]

    progress.stop(idx[:1], IKReason.LIMIT_BLOCKED)
    step, escape = np.array([False, False, True]), np.array([False, True, False])
    assert progress.may_cross(idx).tolist() == [True, True, True]
    progress.advance(idx, step, np.full((1, 2), 3.0), escape, np.full((1, 2), -3.0))
    assert progress.unsolved().tolist() == [2, 3] and progress.reason[0] == IKReason.LIMIT_BLOCKED
    assert progress.q[2].tolist() == [-3.0, -3.0] and progress.q[3].tolist() == [3.0, 3.0]
    assert progress.crossings_left.tolist() == [1, 1, 0, 1] and progress.since_best[2] == 0
    assert progress.iterations.tolist() == [0, 0, 1, 1] and progress.reason[3] == IKReason.ITERATION_CAP
