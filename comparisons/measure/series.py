"""Sampled series of a case, stored with the run (``series.csv.gz``) so reports draw them without
running anything: drift and error against time for dynamics, residual distributions and the
engines' FK agreement for IK. What each quantity holds: :data:`core.results.SERIES_QUANTITIES`.
"""

from __future__ import annotations

import numpy as np

from simparity.comparisons.measure.extents import RunExtents, angular_momenta, energies
from simparity.comparisons.measure.metrics import dynamics_metrics, energy_scale
from simparity.comparisons.measure.rows import Case
from simparity.core.model.metric_catalogue import ANGULAR_MOMENTUM_DRIFT_MAX, ENERGY_DRIFT_MAX
from simparity.core.model.results import SERIES_POINTS, SeriesRecord
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory
from simparity.references.common.conventions import quat_wxyz_angle


def envelope(times: np.ndarray, values: np.ndarray, points: int = SERIES_POINTS) -> tuple[np.ndarray, np.ndarray]:
    """(times, values) of at most ``points`` samples: of each run of consecutive samples, the one of
    largest magnitude, at its own time; the first and last samples are always kept.

    times, values : (T,) -> (K,), K <= points. Maxima of |values| are kept exactly, so a figure or a
    flag read from the series sees the run's extremes, and an oscillation shows its envelope.
    """
    n = len(values)
    if n <= points:
        return np.asarray(times, dtype=float), np.asarray(values, dtype=float)
    inner = np.array_split(np.arange(1, n - 1), points - 2)
    picks = [0] + [chunk[np.argmax(np.abs(values[chunk]))] for chunk in inner if chunk.size] + [n - 1]
    return np.asarray(times)[picks], np.asarray(values)[picks]


def _record(case: Case, quantity: str, unit: str, x: np.ndarray, value: np.ndarray) -> SeriesRecord:
    return SeriesRecord(case.scene, case.engine, case.integrator, case.dt, quantity, unit, x, value)


class StreamedEnvelope:
    """:func:`envelope` of a quantity of ``columns`` columns (bodies) over ``n_samples`` samples, taken as its
    samples arrive in consecutive pieces: per run of consecutive samples (the runs :func:`envelope` cuts) and
    column, the first sample of largest magnitude, its time and signed value. A fixed size whatever the samples.
    """

    def __init__(self, n_samples: int, columns: int, points: int = SERIES_POINTS) -> None:
        if n_samples <= points:
            self._edges = np.arange(n_samples + 1)
        else:
            # np.array_split's parts of the inner samples 1 .. n - 2: the first (n - 2) % (points - 2) one longer.
            size, longer = divmod(n_samples - 2, points - 2)
            sizes = [size + 1] * longer + [size] * (points - 2 - longer)
            self._edges = np.concatenate([[0], 1 + np.cumsum([0] + sizes), [n_samples]])
        runs = len(self._edges) - 1
        self._magnitude = np.full((runs, columns), -np.inf)
        self._time = np.zeros((runs, columns))
        self._value = np.zeros((runs, columns))

    def add(self, start: int, times: np.ndarray, values: np.ndarray) -> None:
        """The samples ``start``, ``start + 1``, ... at ``times`` (k,) [s], ``values`` (k, columns)."""
        values = np.asarray(values, dtype=float)
        k = len(values)
        if k == 0:
            return
        runs = np.searchsorted(self._edges, np.arange(start, start + k), side="right") - 1
        cuts = np.concatenate([[0], np.flatnonzero(np.diff(runs)) + 1])
        magnitude = np.abs(values)
        top = np.maximum.reduceat(magnitude, cuts, axis=0)
        owner = np.repeat(np.arange(len(cuts)), np.diff(np.append(cuts, k)))
        first = np.minimum.reduceat(np.where(magnitude == top[owner], np.arange(k)[:, None], k), cuts, axis=0)
        at = runs[cuts]
        better = (first < k) & (top > self._magnitude[at])  # strict: of equal magnitudes the earlier sample stays
        row = np.minimum(first, k - 1)
        column = np.arange(values.shape[1])
        self._magnitude[at] = np.where(better, top, self._magnitude[at])
        self._time[at] = np.where(better, np.asarray(times, dtype=float)[row], self._time[at])
        self._value[at] = np.where(better, values[row, column], self._value[at])

    def series(self) -> tuple[np.ndarray, np.ndarray]:
        """(times, values), each (K,), of a one-column quantity: :func:`envelope`'s."""
        return self._time[:, 0], self._value[:, 0]

    def worst(self, scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(times, values), each (K,): per run of samples, the column whose value / ``scale`` (columns,) is largest
        in magnitude, over the columns with a non-zero scale, signed: :func:`envelope` of the worst column's
        relative value per sample (the same maxima; of equal magnitudes it may keep another sample)."""
        measurable = scale > 0
        relative = self._value[:, measurable] / scale[measurable]
        pick = np.argmax(np.abs(relative), axis=1)[:, None]
        return (np.take_along_axis(self._time[:, measurable], pick, axis=1)[:, 0],
                np.take_along_axis(relative, pick, axis=1)[:, 0])


class DynamicsSeries:
    """The sampled series of a dynamics case (:func:`dynamics_series`), taken as the run's pieces arrive: drift of
    what the scene conserves and, against a reference, the position and orientation errors, against time."""

    def __init__(self, scene: DynamicsScene, n_samples: int, compared: bool) -> None:
        wanted = dynamics_metrics(scene)
        bodies = len(scene.bodies)
        self._scene, self._compared = scene, compared
        self._energy = StreamedEnvelope(n_samples, bodies) if ENERGY_DRIFT_MAX in wanted else None
        self._momentum = StreamedEnvelope(n_samples, bodies) if ANGULAR_MOMENTUM_DRIFT_MAX in wanted else None
        self._position = StreamedEnvelope(n_samples, 1) if compared else None
        self._orientation = StreamedEnvelope(n_samples, 1) if compared else None
        self._next = 0

    def add(self, piece: Trajectory, ref: Trajectory | None, run: RunExtents) -> None:
        """The next ``piece`` of the run (its reference's samples ``ref`` when compared); ``run``: the run's extents
        so far (its first sample's energy and momentum)."""
        times, start = np.asarray(piece.times, dtype=float), self._next
        self._next += len(times)
        if self._energy is not None and run.energy is not None:
            self._energy.add(start, times, energies(self._scene, piece)[0] - run.energy.energy0)
        if self._momentum is not None and run.momentum is not None:
            change = angular_momenta(self._scene, piece) - run.momentum.momentum0
            self._momentum.add(start, times, np.linalg.norm(change, axis=-1))
        if self._position is not None and self._orientation is not None and ref is not None:
            distance = np.linalg.norm(piece.position_world - ref.position_world, axis=-1)
            self._position.add(start, times, distance.max(axis=1)[:, None])
            self._orientation.add(start, times, quat_wxyz_angle(piece.quat_wxyz, ref.quat_wxyz).max(axis=1)[:, None])

    def stop_comparing(self) -> None:
        """No error series: the reference failed or diverged."""
        self._compared = False

    def records(self, case: Case, run: RunExtents, heights: np.ndarray | None = None,
                times: np.ndarray | None = None) -> list[SeriesRecord]:
        """The series of the whole run (``run``: its extents); with contact, ``heights`` (T,) [m] at ``times``
        (T,) [s]: the first body's lowest point above its nearest plane."""
        out: list[tuple[str, str, tuple[np.ndarray, np.ndarray]]] = []
        if heights is not None and times is not None:
            out.append(("support_height", "m", envelope(times, heights)))
        if self._energy is not None and run.energy is not None:
            scale = energy_scale(self._scene, run.energy)
            if (scale > 0).any():
                out.append(("energy_change", "1", self._energy.worst(scale)))
        if self._momentum is not None and run.momentum is not None and (run.momentum.size0 > 0).any():
            out.append(("angular_momentum_change", "1", self._momentum.worst(run.momentum.size0)))
        if self._compared and self._position is not None and self._orientation is not None:
            out.append(("position_error", "m", self._position.series()))
            out.append(("orientation_error", "rad", self._orientation.series()))
        return [_record(case, quantity, unit, *picked) for quantity, unit, picked in out]


def dynamics_series(case: Case, scene: DynamicsScene, traj: Trajectory, ref: Trajectory | None,
                    heights: np.ndarray | None = None) -> list[SeriesRecord]:
    """Drift of what the scene conserves, error against ``ref`` (when there is one) and, in a contact scene,
    ``heights`` (T,): the first body's lowest point above its nearest plane [m], of the whole trajectory
    ``traj``, against time (:class:`DynamicsSeries` of one piece)."""
    series = DynamicsSeries(scene, len(traj.times), ref is not None)
    run = RunExtents.of(scene, traj)
    series.add(traj, ref, run)
    return series.records(case, run, heights, np.asarray(traj.times, dtype=float))


def quantiles(case: Case, quantity: str, unit: str, values: np.ndarray) -> SeriesRecord:
    """The distribution of ``values`` (N,) as :data:`SERIES_POINTS` quantiles (x: cumulative fraction)."""
    fractions = np.linspace(0.0, 1.0, SERIES_POINTS)
    return _record(case, quantity, unit, fractions, np.quantile(np.asarray(values, dtype=float), fractions))


def disagreement_matrix(case: Case, ends: dict[str, np.ndarray]) -> list[SeriesRecord]:
    """Largest distance [m] between every two judges' end-effector positions ({engine: (N, 3)})."""
    return [_record(Case(case.scene, a, b, case.dt, case.reference), "fk_disagreement_max", "m", np.zeros(1),
                    np.array([np.linalg.norm(ends[a] - ends[b], axis=-1).max(initial=0.0)]))
            for a in ends for b in ends if a != b]
