"""The bookkeeping of a batch of IK targets iterated at once (:func:`core.ik.jacobian_solvers.solve_ik`).

Every array is indexed by target over the whole batch; an iteration works on the still-unsolved targets, whose
batch indices :meth:`BatchProgress.unsolved` gives, and hands its results back through those indices. A target
leaves the iteration solved, stopped with a reason (:class:`core.model.ik_result.IKReason`) or at the cap.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from simparity.core.model.ik_result import IKReason


@dataclass
class BatchProgress:
    """Where each of B targets of an n-joint chain stands.

    Attributes
    ----------
    q : (B, n) ndarray
        The current iterate [rad or m].
    best_q : (B, n) ndarray
        The configuration of the smallest error met (or the solving one).
    best_merit : (B,) ndarray
        That smallest error |e| (inf before the first).
    since_best : (B,) int ndarray
        Iterations since |e| last fell by the stall ratio.
    iterations : (B,) int ndarray
        Joint updates applied (steps and gap escapes).
    crossings_left : (B,) int ndarray
        Escapes through a narrow limit gap still allowed.
    reason : (B,) object ndarray of IKReason
        Why the target stopped; :attr:`IKReason.ITERATION_CAP` until it does.
    active : (B,) bool ndarray
        Still iterated.
    """

    q: np.ndarray
    best_q: np.ndarray
    best_merit: np.ndarray
    since_best: np.ndarray
    iterations: np.ndarray
    crossings_left: np.ndarray
    reason: np.ndarray
    active: np.ndarray

    @classmethod
    def start(cls, q: np.ndarray, gap_crossings: int) -> BatchProgress:
        """Every target active at ``q`` (B, n), no error met yet, ``gap_crossings`` escapes each."""
        batch = q.shape[0]
        return cls(q=q, best_q=q.copy(), best_merit=np.full(batch, np.inf), since_best=np.zeros(batch, int),
                   iterations=np.zeros(batch, int), crossings_left=np.full(batch, gap_crossings),
                   reason=np.full(batch, IKReason.ITERATION_CAP, dtype=object), active=np.ones(batch, bool))

    def unsolved(self) -> np.ndarray:
        """(k,) the batch indices of the targets still iterated."""
        return np.flatnonzero(self.active)

    def observe(self, idx: np.ndarray, q: np.ndarray, merit: np.ndarray, solved: np.ndarray,
                stall_ratio: float) -> None:
        """Record the errors ``merit`` (k,) at the iterates ``q`` (k, n) of targets ``idx`` (k,): a smaller error
        or a solution becomes the best configuration, progress by more than ``stall_ratio`` restarts the stall
        count, and the ``solved`` (k,) targets leave the iteration as solved."""
        better = merit < self.best_merit[idx]
        self.since_best[idx] = np.where(merit < self.best_merit[idx] * (1 - stall_ratio), 0, self.since_best[idx] + 1)
        keep = better | solved
        self.best_q[idx[keep]] = q[keep]
        self.best_merit[idx[better]] = merit[better]
        self.reason[idx[solved]] = IKReason.SOLVED
        self.active[idx[solved]] = False

    def retire_runs(self, solved: np.ndarray, run: int) -> None:
        """End the iteration of every target in a run of ``run`` consecutive targets (one target from ``run``
        starts) that holds one of the just ``solved`` (k,) batch indices; the others keep their reason, best
        configuration and count."""
        first = np.unique(solved // run) * run
        self.active[(first[:, None] + np.arange(run)).ravel()] = False

    def stalled(self, idx: np.ndarray, window: int) -> np.ndarray:
        """(m,) positions within ``idx`` of the targets without progress for ``window`` iterations."""
        return np.flatnonzero(self.since_best[idx] >= window)

    def may_cross(self, idx: np.ndarray) -> np.ndarray:
        """(k,) bool: the targets ``idx`` have a gap escape left."""
        return self.crossings_left[idx] > 0

    def stop(self, idx: np.ndarray, reasons: np.ndarray | IKReason) -> None:
        """Record why the targets ``idx`` stop (they leave the iteration in :meth:`advance`)."""
        self.reason[idx] = reasons

    def advance(self, idx: np.ndarray, step: np.ndarray, stepped: np.ndarray, escape: np.ndarray,
                escaped: np.ndarray) -> None:
        """Move the targets ``idx[step]`` to ``stepped`` and ``idx[escape]`` through their limit gap to
        ``escaped`` (an escape spends a crossing and restarts the stall count), count the update, and end the
        iteration of every other target of ``idx``. ``step`` and ``escape`` (k,) bool, disjoint."""
        self.q[idx[step]] = stepped
        self.q[idx[escape]] = escaped
        self.crossings_left[idx[escape]] -= 1
        self.since_best[idx[escape]] = 0
        self.iterations[idx[step | escape]] += 1
        self.active[idx[~(step | escape)]] = False
