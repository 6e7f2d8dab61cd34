"""Sampled series: bounded, extremes kept, values from hand-made trajectories, stored and read back."""

import dataclasses
import math

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.measure.rows import Case
from simparity.comparisons.execute.in_process import run_in_process as run_scene
from simparity.comparisons.measure.series import dynamics_series, envelope
from simparity.comparisons.pipeline.run_info import describe_run
from simparity.reports.store import RunWriter
from simparity.core.model.results import SERIES_POINTS
from simparity.core.model.scenes.bodies import Forces, RigidBody
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.trajectory import Trajectory
from simparity.reports.store import read_series
from tests.helpers import builtin, smoke
from tests.references.test_engine_kinematics import DOUBLE_TOL


def test_envelope_is_bounded_and_keeps_the_extremes(rng=np.random.default_rng(3)):
    """Of 10,001 noisy samples, at most SERIES_POINTS remain, with the first, the last and the largest
    magnitude (a spike planted mid-run) at their own times."""
    times = np.linspace(0.0, 10.0, 10_001)
    values = rng.normal(size=times.size)
    values[4321] = -50.0
    t, v = envelope(times, values)
    assert len(t) <= SERIES_POINTS and t[0] == 0.0 and t[-1] == 10.0
    assert v.min() == -50.0 and t[np.argmin(v)] == times[4321]
    assert np.all(np.diff(t) > 0)
    short_t, short_v = envelope(times[:7], values[:7])
    assert np.array_equal(short_v, values[:7])


def _free_body_scene() -> DynamicsScene:
    body = RigidBody("b", 2.0, np.eye(3), np.zeros(3), np.array([1.0, 0, 0, 0]), np.zeros(3), np.zeros(3))
    return DynamicsScene("free", "a free body", "analytic", (body,), Forces(), 1.0, (0.5,))


def _trajectory(speeds, positions) -> Trajectory:
    n = len(speeds)
    v = np.zeros((n, 1, 3)); v[:, 0, 0] = speeds
    x = np.zeros((n, 1, 3)); x[:, 0, 0] = positions
    q = np.tile([1.0, 0, 0, 0], (n, 1, 1))
    return Trajectory(np.arange(n) * 0.5, x, q, v, np.zeros((n, 1, 3)))


def test_dynamics_series_from_a_hand_made_trajectory():
    """Speeds 1, 2, 1 m/s of a 2 kg body: E = 1, 4, 1 J, so (E - E(0)) / E(0) = 0, 3, 0; the position
    error against a reference 0.25 m behind at the middle sample is 0, 0.25, 0."""
    scene = _free_body_scene()
    case = Case("free", "core", "rk4", 0.5, "analytic:exact")
    traj = _trajectory([1, 2, 1], [0, 1, 2])
    records = dynamics_series(case, scene, traj, _trajectory([1, 2, 1], [0, 0.75, 2]))
    by_quantity = {r.quantity: r for r in records}
    assert np.allclose(by_quantity["energy_change"].value, [0, 3, 0])
    assert np.allclose(by_quantity["position_error"].value, [0, 0.25, 0])
    assert np.array_equal(by_quantity["position_error"].x, [0.0, 0.5, 1.0]) and by_quantity["position_error"].unit == "m"
    assert "angular_momentum_change" not in by_quantity   # nothing spins: no |L| to drift


@pytest.mark.slow
def test_runner_series_round_trip_through_the_store(tmp_path):
    """Every ok case of a real scene gets its series; written with the rows and read back by pandas."""
    # Trimmed (smoke: the two coarsest dts over 1 s): every integrator of both engines still runs, and the
    # finer dt's 200 steps are more than SERIES_POINTS, so the bound below still needs the thinning to hold
    # (the full scene, 10 s down to 2.5 ms with its tight reference, was one of the suite's costliest tests).
    scene = smoke(builtin("dzhanibekov"))
    assert scene.duration / min(scene.dts) > SERIES_POINTS
    engines = [make_engine("core"), make_engine("mujoco")]
    series = []
    rows = run_scene(scene, engines, make_engine, repeats=0, series=series)
    writer = RunWriter(tmp_path, describe_run(engines, "test", [scene]))
    writer.append(rows, series[: len(series) // 2])
    writer.append([], series[len(series) // 2:])   # a second gzip member reads as the same file
    table = read_series(tmp_path)
    assert len(table) == sum(len(r.x) for r in series)
    ok_cases = {(r.engine, r.integrator, r.dt) for r in rows if r.status == "ok" and not math.isnan(r.dt)}
    energy = table[table["quantity"] == "energy_change"]
    assert set(zip(energy["engine"], energy["integrator"], energy["dt"])) == ok_cases
    assert energy.groupby(["engine", "integrator", "dt"]).size().max() <= SERIES_POINTS


IK_SERIES_ITERATIONS = 30
"""max_iterations of the IK scene whose series are tested: the distributions and the FK matrix are of whatever the
solvers reached, and the stalled solves (the hard targets, the transpose method) were most of the test at the scene's
200. Measured: the same 7 residual distributions of 101 points from its 500 targets, the same FK matrix."""


@pytest.mark.slow
def test_ik_series_hold_distributions_and_the_fk_matrix():
    scene = dataclasses.replace(builtin("lecture-2link-ik"), max_iterations=IK_SERIES_ITERATIONS)
    engines = [make_engine("core"), make_engine("mujoco")]
    series = []
    run_scene(scene, engines, make_engine, repeats=0, series=series)
    residuals = [r for r in series if r.quantity == "position_residual"]
    assert residuals and all(r.x[0] == 0.0 and r.x[-1] == 1.0 and np.all(np.diff(r.value) >= 0) for r in residuals)
    matrix = {(r.engine, r.integrator): r.value[0] for r in series if r.quantity == "fk_disagreement_max"}
    assert set(matrix) == {("core", "mujoco"), ("mujoco", "core")}
    assert matrix[("core", "mujoco")] == matrix[("mujoco", "core")] <= DOUBLE_TOL   # two double-precision FKs
