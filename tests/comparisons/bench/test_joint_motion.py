"""The joint-motion bench (:mod:`comparisons.bench.joint_motion`) at tiny sizes: its rows, its equal-accuracy check
and its BENCHMARKS.md section. No timing thresholds: speed targets live in the bench as ratios of one run."""

import math

import numpy as np
import pytest

from simparity.comparisons.bench import joint_motion as jm
from simparity.comparisons.bench.rows import BenchRow, median_time
from simparity.comparisons.scenes import library

RK4_AGREEMENT = 1e-9
"""[rad] The engines' RK4s are one scheme on the same dynamics: over a few steps they differ by rounding (~1e-15),
so anything above this is a different scheme, model or time step."""
EULER_OVER_RK4 = 1e3
"""Over 5 steps of 2 ms from rest, a first-order Euler is off by ~dt^2 qddot (1e-5 rad) and RK4 by ~1e-12 rad: at
least a thousandfold apart, unless the rows mixed up the engines' errors."""
BATCHES = [1, 4]
TINY_STEPS = 3
ERROR_STEPS = 5


@pytest.fixture(scope="module")
def rows():
    """One tiny run of the bench on two arms: 3 steps per call, the accuracy run 5 steps; Pinocchio and PyBullet timed
    up to B = 1 only, so B = 4 shows their skip."""
    patch = pytest.MonkeyPatch()
    for name, value in (("ARMS", ("ur5-falling", "panda-falling")), ("MIN_STEPS", TINY_STEPS),
                        ("MAX_STEPS", TINY_STEPS), ("ERROR_STEPS", ERROR_STEPS), ("PER_COPY_MAX_BATCH", 1),
                        ("REPEATS", 1)):
        patch.setattr(jm, name, value)
    try:
        return jm.joint_motion_rows(BATCHES, median_time, BenchRow, lambda line: None)
    finally:
        patch.undo()


def test_a_timed_row_per_arm_engine_and_batch(rows):
    timed = [r for r in rows if r.section == jm.SECTION]
    keys = [(r.workload, r.engine, r.method, r.batch) for r in timed]
    assert sorted(keys) == sorted((arm, engine, method, b) for arm in ("ur5-falling", "panda-falling")
                                  for engine, method in jm.ENGINES for b in BATCHES)
    for r in timed:
        if r.engine in jm.NOT_BATCHED and r.batch > 1:
            assert math.isnan(r.value) and r.note.startswith("n/a: not timed above B = 1") and "s per call" in r.note
        else:
            assert math.isfinite(r.value) and r.value > 0 and r.unit == jm.UNIT, r


def test_the_rk4s_agree_to_rounding_and_the_euler_does_not(rows):
    accuracy = {(r.workload, r.engine): r for r in rows if r.section == jm.ACCURACY_SECTION}
    assert len(accuracy) == 2 * len(jm.ENGINES)
    for (arm, engine), r in accuracy.items():
        assert math.isfinite(r.value) and math.isfinite(r.accuracy), r
        if r.method == "rk4":
            assert r.accuracy <= RK4_AGREEMENT, r
            # the same error against DOP853 as Pinocchio's RK4, to the same rounding
            assert abs(r.value - accuracy[arm, "pinocchio"].value) <= RK4_AGREEMENT
        else:
            # PyBullet's first-order Euler
            assert r.value > EULER_OVER_RK4 * accuracy[arm, "pinocchio"].value, r
    # every timed row carries the error its engine reached in the accuracy run
    for r in rows:
        if r.section == jm.SECTION:
            assert r.accuracy == accuracy[r.workload, r.engine].value


def test_copies_start_at_the_scene_pose_then_seeded_perturbations():
    scene = library.load(["iiwa-falling"])[0]
    first, again = jm.copies(scene, 3, 7), jm.copies(scene, 3, 7)
    np.testing.assert_array_equal(first.q0[0], scene.q0[0])
    assert np.all(first.q0[1:] != scene.q0[0]) and np.array_equal(first.q0, again.q0)
    np.testing.assert_array_equal(first.qdot0, np.repeat(scene.qdot0[:1], 3, axis=0))
    assert first.n_steps(jm.DT) == 7


def test_steps_per_call_aim_at_the_copy_steps_within_bounds():
    assert jm.steps_per_call(1) == jm.MAX_STEPS
    assert jm.steps_per_call(10_000) == max(jm.MIN_STEPS, jm.COPY_STEPS // 10_000)
    assert jm.steps_per_call(10**9) == jm.MIN_STEPS


def _row(engine, batch, value, section=jm.SECTION, method="rk4", note=""):
    return BenchRow(section, "iiwa-falling", engine, method, batch, value, jm.UNIT, 1e-7, "rad", note)


def test_markdown_shows_accuracy_times_and_ratios():
    rows = [BenchRow(jm.ACCURACY_SECTION, "iiwa-falling", "mujoco", "rk4", 2, 6.4e-7, "rad vs dop853", 3.9e-14,
                     "rad vs pinocchio rk4"),
            _row("core", 1, 8000.0), _row("core", 10_000, 10.0, note="one NumPy batch; CPU/wall 1.00"),
            _row("mujoco", 1, 40.0), _row("mujoco", 10_000, 20.0),
            _row("pinocchio", 1, 100.0), _row("pinocchio", 10_000, math.nan, note="n/a: not timed above B = 100")]
    text = "\n".join(jm.markdown_lines(rows))
    assert "| iiwa-falling | mujoco | rk4 | 6.40e-07 | 3.9e-14 |" in text
    assert "| iiwa-falling | core | rk4 | 8e+03 (125/s) | 10 (100,000/s) |" in text
    # ratios engine / core: MuJoCo 40 / 8000 and 20 / 10; best vs best 20 / 10; Pinocchio 100 / 8000, n/a, 100 / 10
    assert "| iiwa-falling | mujoco | rk4 | 0.005 | 2 | 2 |" in text
    assert "| iiwa-falling | pinocchio | rk4 | 0.0125 | n/a | 10 |" in text
    # the notes of the largest B (how each engine ran there) and of every row not measured
    assert "- iiwa-falling pinocchio B = 10,000: n/a: not timed above B = 100" in text
    assert "- iiwa-falling core B = 10,000: one NumPy batch; CPU/wall 1.00" in text
    assert jm.markdown_lines([]) == []


def test_the_profile_case_runs_core():
    title, call = jm.profile_case(2)
    assert "2 iiwa-falling copies" in title
    assert call().q.shape == (jm.PROFILE_STEPS + 1, 2, 7)
