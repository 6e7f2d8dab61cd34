"""Issue #42's built-in scenes of loads that change with time, each engine on them.

torque-pulse-straddle: a held torque jumps a third of the way into a step at every time step. Over that step a
Runge-Kutta scheme integrates the torque as the weights of its stages past the jump say, sum_{c_i > 1/3} b_i, where
the truth is 2/3 of the step: the angular velocity is off by |sum_{c_i > 1/3} b_i - 2/3| tau dt / I after the first
jump (an O(dt) error: first order whatever the scheme), and the second jump takes the same amount back. Derived
here from each scheme's tableau, not from a run; every engine (core, MuJoCo, PyBullet, Pinocchio) must show it.
"""

from __future__ import annotations

import numpy as np
import pytest

from simparity.comparisons.measure.held_forcing import forcing_scheme, straddled_instants, straddles
from simparity.comparisons.engines.registry import make_engine
from simparity.core.dynamics.tableau import TABLEAUX
from tests.helpers import builtin

JUMP_FRACTION = 1 / 3
"""Where in its step each jump of torque-pulse-straddle falls (its scene file)."""

TAU_OVER_I = 0.5 / 0.5
"""The pulse's 0.5 N m about a principal moment of 0.5 kg m^2 [rad/s^2]."""

EULER_WEIGHT = 0.0
"""An Euler step evaluates the torque at the step's start only: no weight past the jump."""

CASES = [("core", "rk4", TABLEAUX["rk4"]), ("core", "midpoint", TABLEAUX["midpoint"]),
         ("core", "average_velocity", TABLEAUX["average_velocity"]), ("core", "semi_implicit_euler", None),
         ("mujoco", "rk4", TABLEAUX["rk4"]), ("mujoco", "euler", None), ("pybullet", "euler", None),
         ("pinocchio", "rk4", TABLEAUX["rk4"]), ("pinocchio", "euler", None)]

AGREEMENT = 1e-9
"""Relative: the error is a sum of a few exact terms (the motion is piecewise linear in omega); PyBullet's float32
link states are not read here (the angular velocity is its double-precision base velocity)."""


def _weight_past(tableau) -> float:
    return EULER_WEIGHT if tableau is None else sum(b for b, c in zip(tableau.b, tableau.c) if c > JUMP_FRACTION)


@pytest.mark.parametrize("engine, integrator, tableau", CASES, ids=[f"{e}-{i}" for e, i, _ in CASES])
def test_a_jump_inside_a_step_costs_the_error_the_stages_weights_say(engine, integrator, tableau):
    scene = builtin("torque-pulse-straddle")
    expected = abs(_weight_past(tableau) - (1 - JUMP_FRACTION)) * TAU_OVER_I
    for dt in scene.dts[:2]:
        run = make_engine(engine).build_dynamics(scene, integrator, dt).run(scene.n_steps(dt))
        exact = make_engine("analytic").build_dynamics(scene, "exact", dt).run(scene.n_steps(dt))
        error = np.abs(run.angular_velocity_world - exact.angular_velocity_world).max()
        assert error == pytest.approx(expected * dt, rel=AGREEMENT), (dt, error / dt)


def test_the_straddle_is_named_and_the_aligned_pulse_is_not():
    straddle, aligned = builtin("torque-pulse-straddle"), builtin("torque-pulse")
    assert straddles(straddle) and all(straddled_instants(straddle, dt) == 2 for dt in straddle.dts)
    assert not straddles(aligned) and forcing_scheme("rk4", aligned) == "rk4"
    assert forcing_scheme("rk4", straddle) == "held+rk4"
    assert forcing_scheme("closed_form", straddle) == "closed_form" and forcing_scheme("", straddle) == ""
