"""Starts for IK restarts chosen near the target: the nearest poses of a seeded pool of random configurations.

A uniform random start lands in the basin of a solution only by chance; a start whose end-effector pose is
already near the target is more often in one, and closer (the lookup-table seed of sampling-based IK).
:func:`nearest_pose_starts` draws a pool of configurations within the limits
(:func:`core.model.scenes.chain.sample_configurations`), computes their end-effector poses in one batched FK pass,
and gives each target the ``starts`` pool configurations whose poses are nearest to it.

Poses are compared as the solver weighs its error (1 m of position counts as much as 1 rad of rotation,
:mod:`core.ik.jacobian_solvers`): a pose is embedded as its position [m] and its rotation matrix's entries / sqrt(2)
(the chordal distance |R1 - R2|_F / sqrt(2) = 2 sin(theta / 2), ~theta for small angles), and the nearest
embeddings found by a k-d tree.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from simparity.core.kinematics import packed_frames
from simparity.core.model.scenes.chain import Chain, sample_configurations

POOL_PER_START = 2
"""Pool configurations drawn per start asked for. Measured on the first restart round of the bench's 10,000 TRAC-IK
targets (4 starts per target, a run stopped at its first solution): uniform starts solved 73.1 % of the SO-100's
2,143 targets in 66,152 row-iterations, 95.3 % of the Panda's 953 in 34,559, 94.1 % of the UR5's 1,501 in 52,625;
nearest poses of 2 per start solved 96.5 % in 34,893, 97.4 % in 21,789 and 94.0 % in 32,471; 1 per start solved 94.0 %
of the SO-100's, and 4 per start no more than 2 at twice the FK and k-d tree time."""
POOL_MIN, POOL_MAX = 1024, 16384
"""Bounds of the pool [configurations]: a few failed targets still get a pool dense enough to be near them, and a
pool stays a small part of a restart round's cost (16,384 poses: one FK pass and a k-d tree, ~0.1 of the SO-100's
first restart round)."""


def nearest_pose_starts(chain: Chain, target_position: np.ndarray, target_rotation: np.ndarray | None,
                        starts: int, rng: np.random.Generator) -> np.ndarray:
    """(B * starts, n) starts, target by target: for each of the B targets, the ``starts`` configurations of a
    pool drawn from ``rng`` whose end-effector poses are nearest to it (nearest first).

    Parameters
    ----------
    chain : Chain
    target_position : (B, 3) ndarray
        [m], world frame.
    target_rotation : (B, 3, 3) ndarray or None
        End-effector orientation targets; None: positions only are compared.
    starts : int
        Starts per target, >= 1.
    rng : numpy.random.Generator
        The pool's draws.
    """
    count = len(target_position) * starts
    size = int(np.clip(POOL_PER_START * count, max(POOL_MIN, starts), POOL_MAX))
    pool = sample_configurations(chain, size, rng)
    frames = packed_frames(chain, pool)
    pool_rotation = None if target_rotation is None else frames.end_rotation.transpose(2, 0, 1)
    tree = cKDTree(_embed(frames.positions[-1].T, pool_rotation))
    _, nearest = tree.query(_embed(target_position, target_rotation), k=starts)
    return pool[np.asarray(nearest).reshape(count)]


def _embed(position: np.ndarray, rotation: np.ndarray | None) -> np.ndarray:
    """(B, 3) or (B, 12): the position, then the rotation's entries / sqrt(2) (module docstring)."""
    if rotation is None:
        return position
    return np.concatenate([position, rotation.reshape(len(rotation), 9) / np.sqrt(2)], axis=1)
