"""A dynamics case's run measured as its engine yields it, piece by piece (``Simulation.stream``): the extents
(:mod:`comparisons.measure.extents`), the errors against the reference's samples at the same times and the
sampled series accumulate, and each piece is dropped once read, so memory stays flat in the number of steps. A
whole trajectory is read as one piece, with the same results.

The reference's pieces need not be cut where the engine's are: :class:`AlignedPieces` cuts them to match.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from simparity.comparisons.measure.extents import ErrorExtents, ReferenceExtents, RunExtents
from simparity.comparisons.measure.series import DynamicsSeries
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory, joined

SAMPLE_BYTES = 13 * 8
"""[bytes] One body's sample: position 3, quaternion 4, velocity 3, angular velocity 3 float64."""

PIECE_BYTES = 8 * 2**20
"""[bytes] The samples the runner asks an engine for at once: small next to a worker's ~200 MiB of libraries and
models (the engine's piece, the reference's and their temporaries are a few times this), large enough that a piece
is thousands of samples (80,659 of one body), so the per-piece overhead is nothing next to the steps."""

TIME_GRID_TOLERANCE = 1e-3
"""How far [steps] a trajectory's sample time may be from k * dt: a clock kept as t += dt drifts at most
~n^2 eps steps (1e-4 at the 10^6 steps a scene may have); a sample a thousandth of a step off is on another
grid, and every error measured against the reference's samples would be wrong."""


def samples_per_piece(scene: DynamicsScene) -> int:
    """How many samples of ``scene``'s bodies make :data:`PIECE_BYTES` (at least 1)."""
    return max(1, PIECE_BYTES // (len(scene.bodies) * SAMPLE_BYTES))


def piece_problem(scene: DynamicsScene, piece: object, start: int, n_steps: int, dt: float) -> str:
    """What is wrong with ``piece`` as the samples ``start``, ``start + 1``, ... of ``n_steps`` steps of ``dt`` of
    ``scene`` ("" when nothing): a Trajectory of every body, at times k * dt (within :data:`TIME_GRID_TOLERANCE`
    steps), not past the run's last sample."""
    if not isinstance(piece, Trajectory):
        return (f"the engine gave a value of type {type(piece).__name__} (allowed: a "
                "simparity.core.trajectory.Trajectory)")
    times = np.asarray(piece.times)
    if start + len(times) > n_steps + 1:
        return (f"it has more than {n_steps + 1} samples (expected {n_steps + 1}: the initial state and {n_steps} "
                "steps)")
    if piece.n_bodies != len(scene.bodies):
        return f"it has {piece.n_bodies} bodies (the scene has {len(scene.bodies)})"
    with np.errstate(all="ignore"):
        off = np.abs(times - np.arange(start, start + len(times)) * dt) / dt
    bad = np.flatnonzero(~(off <= TIME_GRID_TOLERANCE))
    if bad.size:
        k = int(bad[0])
        return (f"sample {start + k} is at t = {float(times[k]):.9g} s (expected {(start + k) * dt:.9g} s, k * dt "
                f"within {TIME_GRID_TOLERANCE:g} steps)")
    return ""


class AlignedPieces:
    """A run's pieces (the reference's), re-cut to the lengths asked for (the engine's pieces')."""

    def __init__(self, pieces: Iterator[Trajectory]) -> None:
        self._pieces = pieces
        self._held: list[Trajectory] = []
        self._count = 0

    def take(self, count: int) -> Trajectory:
        """The next ``count`` samples. Raises ValueError when the run has fewer left."""
        while self._count < count:
            piece = next(self._pieces, None)
            if piece is None:
                raise ValueError(f"the reference ended {count - self._count} samples early")
            self._held.append(piece)
            self._count += len(piece.times)
        whole = joined(self._held)
        self._count -= count
        self._held = [whole.sliced(slice(count, None))] if self._count else []
        return whole.sliced(slice(None, count))


class CaseReading:
    """What a dynamics case's rows read of its run and, when ``compared``, of its reference's run at the same
    times, accumulated piece by piece (:meth:`add`).

    Attributes
    ----------
    run : RunExtents or None
        The engine's run (None before the first piece).
    reference : ReferenceExtents or None
        The reference's run.
    errors : ErrorExtents or None
        The run's errors against the reference.
    reference_finite : bool
        Every reference value so far finite.
    samples : int
        Samples read so far.
    series : DynamicsSeries
    """

    def __init__(self, scene: DynamicsScene, n_steps: int, compared: bool) -> None:
        self._scene = scene
        self.run: RunExtents | None = None
        self.reference: ReferenceExtents | None = None
        self.errors: ErrorExtents | None = None
        self.reference_finite = True
        self.samples = 0
        self.series = DynamicsSeries(scene, n_steps + 1, compared)

    def add(self, piece: Trajectory, ref: Trajectory | None) -> None:
        """The run's next ``piece`` and the reference's samples ``ref`` at its times (None: not compared). Once
        either has a value that is not finite, nothing more of it is read: the run is diverged, or the reference
        is (its comparison is dropped)."""
        scene = self._scene
        self.samples += len(piece.times)
        if self.run is not None and not self.run.finite:
            return
        extents = RunExtents.of(scene, piece, self.run)
        self.run = extents if self.run is None else self.run.merged(extents)
        if not extents.finite:
            return
        if ref is not None and self.reference_finite:
            self.reference_finite = ref.is_finite()
            if self.reference_finite:
                reference = ReferenceExtents.of(scene, ref, self.reference)
                self.reference = reference if self.reference is None else self.reference.merged(reference)
                errors = ErrorExtents.of(piece, ref)
                self.errors = errors if self.errors is None else self.errors.merged(errors)
        self.series.add(piece, ref if self.reference_finite else None, self.run)

    def stop_comparing(self) -> None:
        """Drop the comparison with the reference (it failed or diverged): the run is measured alone."""
        self.reference, self.errors = None, None
        self.series.stop_comparing()
