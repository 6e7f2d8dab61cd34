"""Core's evaluation of loads that change with time (issue #42): a hold as seen from inside a step, a smooth
function's value, and the orders the schemes keep when each stage evaluates the load at its own time."""

from __future__ import annotations

import numpy as np

from simparity.comparisons.engines.registry import make_engine
from simparity.core.dynamics.time_loads import held_value, smooth_value, value_in_step
from simparity.core.model.scenes.time_functions import HeldFunction, Sinusoid, SmoothFunction
from tests.helpers import builtin

HOLD = HeldFunction(np.array([[1.0], [2.0], [3.0]]), period_s=0.1, phase_s=0.05)
"""Instants 0.05, 0.15, 0.25 s: 0 before the first, then 1, 2 and 3 from the last on."""


def test_a_hold_is_zero_before_its_first_instant_and_holds_its_last_sample():
    for t, expected in ((0.0, 0.0), (0.049, 0.0), (0.05, 1.0), (0.149, 1.0), (0.15, 2.0), (0.25, 3.0), (9.0, 3.0)):
        assert held_value(HOLD, t, t)[0] == expected, t


def test_a_stage_at_a_step_s_end_sees_the_value_the_step_began_in():
    """The step [0.05, 0.15] ends on an instant: its last stage (c = 1) takes the value just before 0.15, 1, not the
    next sample; the next step's first stage (c = 0) at 0.15 takes 2. Steps and instants round differently: 0.15
    reached as 3 x 0.05 is 0.15000000000000002."""
    end = 3 * 0.05
    assert end != 0.15
    assert value_in_step(HOLD, end, 0.05)[0] == 1.0
    assert value_in_step(HOLD, end, end)[0] == 2.0
    assert value_in_step(HOLD, 0.1, 0.05)[0] == 1.0  # a midpoint stage inside the interval
    assert value_in_step(HOLD, 0.2, 0.13)[0] == 2.0  # a stage past an instant inside its step (a straddle)


def test_a_batch_of_stage_times_is_evaluated_per_body():
    times, starts = np.array([0.15, 0.15, 0.0]), np.array([0.05, 0.15, 0.0])
    np.testing.assert_array_equal(value_in_step(HOLD, times, starts)[:, 0], [1.0, 2.0, 0.0])


def test_a_smooth_function_is_its_polynomial_plus_its_sinusoids():
    function = SmoothFunction(np.array([[1.0, 0.0], [0.5, -2.0], [0.0, 3.0]]),
                              (Sinusoid(np.array([0.2, 0.0]), 2.0, 0.3),))
    t = 0.37
    expected = np.array([1.0 + 0.5 * t + 0.2 * np.sin(4 * np.pi * t + 0.3), -2.0 * t + 3.0 * t * t])
    np.testing.assert_allclose(smooth_value(function, t), expected, rtol=1e-15, atol=1e-16)
    np.testing.assert_allclose(smooth_value(function, np.array([t, 0.0])), [expected, [1.0 + 0.2 * np.sin(0.3), 0.0]], rtol=1e-15,
                               atol=1e-16)


RK4_RATIO = (14.0, 18.0)
"""Halving dt divides a fourth-order error by 2^4 = 16; the next term of the error moves it by a few per cent."""


def _rk4_ratio(name: str, coarse: float) -> float:
    scene, errors = builtin(name), []
    for dt in (coarse, coarse / 2):
        n = scene.n_steps(dt)
        if scene.kind == "dynamics":
            run = make_engine("core").build_dynamics(scene, "rk4", dt).run(n).position_world
            exact = make_engine("analytic").build_dynamics(scene, "exact", dt).run(n).position_world
        else:
            run = make_engine("core").build_joint_motion(scene, "rk4", dt).run(n).q
            exact = make_engine("analytic").build_joint_motion(scene, "closed_form", dt).run(n).q
        errors.append(float(np.abs(run - exact).max()))
    return errors[0] / errors[1]


def test_core_rk4_keeps_order_4_under_a_smooth_load_on_a_body_and_on_a_joint():
    """Each stage evaluates the load at its own time t + c dt (a stage at the step's start would be first order)."""
    assert RK4_RATIO[0] < _rk4_ratio("forced-particle", 0.02) < RK4_RATIO[1]
    assert RK4_RATIO[0] < _rk4_ratio("driven-damped-joint", 0.02) < RK4_RATIO[1]
