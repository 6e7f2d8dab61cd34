"""Sampled series of a case, stored with the run (``series.csv.gz``) so reports draw them without
running anything: drift and error against time for dynamics, residual distributions and the
engines' FK agreement for IK. What each quantity holds: :data:`core.results.SERIES_QUANTITIES`.
"""

from __future__ import annotations

import numpy as np

from simparity.comparisons.measure.metrics import ConservedChanges
from simparity.comparisons.measure.rows import Case
from simparity.core.model.results import SERIES_POINTS, SeriesRecord
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


def _worst(change: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """Per sample, the body whose change / scale is largest in magnitude (signed); change (T, B), scale (B,)."""
    measurable = scale > 0
    relative = change[:, measurable] / scale[measurable]
    return np.take_along_axis(relative, np.argmax(np.abs(relative), axis=1)[:, None], axis=1)[:, 0]


def dynamics_series(case: Case, traj: Trajectory, ref: Trajectory | None,
                    changes: ConservedChanges, heights: np.ndarray | None = None) -> list[SeriesRecord]:
    """Drift of what the scene conserves (``changes``: :func:`comparisons.metrics.conserved_changes` of
    ``traj``), error against ``ref`` (when there is one) and, in a contact scene, ``heights`` (T,): the first
    body's lowest point above its nearest plane [m], against time."""
    out: list[tuple[str, str, np.ndarray]] = []
    if heights is not None:
        out.append(("support_height", "m", heights))
    if changes.energy is not None and changes.energy_scale is not None and (changes.energy_scale > 0).any():
        out.append(("energy_change", "1", _worst(changes.energy, changes.energy_scale)))
    if (changes.angular_momentum is not None and changes.angular_momentum_size is not None
            and (changes.angular_momentum_size > 0).any()):
        out.append(("angular_momentum_change", "1", _worst(changes.angular_momentum, changes.angular_momentum_size)))
    if ref is not None:
        out.append(("position_error", "m", np.linalg.norm(traj.position_world - ref.position_world, axis=-1).max(axis=1)))
        out.append(("orientation_error", "rad", quat_wxyz_angle(traj.quat_wxyz, ref.quat_wxyz).max(axis=1)))
    times = np.asarray(traj.times, dtype=float)
    return [_record(case, quantity, unit, *envelope(times, values)) for quantity, unit, values in out]


def quantiles(case: Case, quantity: str, unit: str, values: np.ndarray) -> SeriesRecord:
    """The distribution of ``values`` (N,) as :data:`SERIES_POINTS` quantiles (x: cumulative fraction)."""
    fractions = np.linspace(0.0, 1.0, SERIES_POINTS)
    return _record(case, quantity, unit, fractions, np.quantile(np.asarray(values, dtype=float), fractions))


def disagreement_matrix(case: Case, ends: dict[str, np.ndarray]) -> list[SeriesRecord]:
    """Largest distance [m] between every two judges' end-effector positions ({engine: (N, 3)})."""
    return [_record(Case(case.scene, a, b, case.dt, case.reference), "fk_disagreement_max", "m", np.zeros(1),
                    np.array([np.linalg.norm(ends[a] - ends[b], axis=-1).max(initial=0.0)]))
            for a in ends for b in ends if a != b]
