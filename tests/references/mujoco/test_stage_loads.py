"""MuJoCo under loads that change with time (issue #42): its control callback runs at every RK4 stage with d.time at
the stage's time, the adapter installs it for its run only, and so MuJoCo's RK4 keeps order 4 under a sinusoid
where a force set once per step (qfrc_applied before mj_step) makes it first order."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from simparity.references.analytic.engine import AnalyticEngine
from simparity.references.mujoco.adapter import MujocoEngine
from simparity.references.mujoco.stage_loads import StepClock, stage_callback
from tests.helpers import builtin

SLIDER = """<mujoco><option integrator="RK4" gravity="0 0 0" timestep="0.1"/>
<worldbody><body><joint type="slide" axis="1 0 0"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body>
</worldbody></mujoco>"""

RK4_RATIO = (14.0, 18.0)
"""Halving dt divides a fourth-order error by 2^4 = 16; the next term of the error moves it by a few per cent."""


def test_the_callback_runs_at_each_rk4_stage_with_the_stage_s_time_and_is_removed_after():
    model = mujoco.MjModel.from_xml_string(SLIDER)
    data = mujoco.MjData(model)
    times: list[float] = []
    with stage_callback(lambda m, d: times.append(d.time)):
        for _ in range(2):
            mujoco.mj_step(model, data)
    np.testing.assert_allclose(times, [0.0, 0.05, 0.05, 0.1, 0.1, 0.15, 0.15, 0.2], rtol=0, atol=1e-15)
    assert mujoco.get_mjcb_control() is None


def test_the_callback_is_removed_when_the_run_raises():
    with pytest.raises(RuntimeError, match="boom"):
        with stage_callback(lambda m, d: None):
            raise RuntimeError("boom")
    assert mujoco.get_mjcb_control() is None


def _error(scene, integrator: str, dt: float) -> float:
    n = scene.n_steps(dt)
    run = MujocoEngine().build_dynamics(scene, integrator, dt).run(n)
    exact = AnalyticEngine().build_dynamics(scene, "exact", dt).run(n)
    return float(np.abs(run.position_world - exact.position_world).max())


def test_mujoco_rk4_keeps_its_order_under_a_sinusoidal_force():
    scene = builtin("forced-particle")
    coarse, fine = _error(scene, "rk4", 0.02), _error(scene, "rk4", 0.01)
    assert RK4_RATIO[0] < coarse / fine < RK4_RATIO[1], coarse / fine
    assert mujoco.get_mjcb_control() is None


def test_a_stage_s_time_is_the_step_s_own_start_plus_mujoco_s_offset_not_its_drifting_clock():
    """MuJoCo's d.time sums dt step by step: after 40,000 steps of 2.5 ms it is off k dt by ~1e-11 s, more than a
    hold's tolerance near a sample instant (a held-out run saw the wrong sample applied from t = 50.85 s)."""
    dt, steps = 0.0025, 40_000
    drifted = 0.0
    for _ in range(steps):
        drifted += dt
    assert abs(drifted - steps * dt) > 1e-12
    clock = StepClock()
    clock.start(steps, dt, drifted)
    assert clock.stage_time(drifted) == steps * dt
    assert clock.stage_time(drifted + 0.5 * dt) == pytest.approx(steps * dt + 0.5 * dt, rel=0, abs=1e-13)
