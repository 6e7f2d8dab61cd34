"""Issue #38 section 6: how wide a catch is (tests/mutation/margin.py), read from the gate's violation lines."""

from __future__ import annotations

import math

import pytest

from tests.mutation.gate import Verdict, Violation
from tests.mutation.margin import catches, margin


@pytest.mark.parametrize("line, expected", [
    ("pendulum-large-amplitude mutant-a semi_implicit_euler dt=0.005 energy_drift_max: 0.055 1, bound <= 0.016 1 "
     "(semi-implicit Euler (order 1): energy drift = C dt^1)", 0.055 / 0.016),
    ("wind mutant-a rk4 order_position: 2.003, bound >= 3.5 (classical RK4)", 3.5 / 2.003),
    ("hard-penalty-stiff mutant-a penalty_semi_implicit_euler stability_limit: 0.43 ms, bound in [0.81, 3.2] ms "
     "(within a factor 2)", 0.81 / 0.43),
    ("x mutant-a rk4 stability_limit: 6.4 ms, bound in [0.81, 3.2] ms (within a factor 2)", 6.4 / 3.2),
    ("iiwa-ik mutant-a pseudo_inverse limit_violations: 4, bound <= 0 (clamped)", math.inf),
    ("oblique-arm-swing mutant-a: 3 metrics (joint_angle_error_max, energy_drift_max, +1 more): joint_angle_error_max "
     "0.11 rad, bound <= 0.069 rad and others (cross-check: 2 x the largest built-in)", 0.11 / 0.069),
])
def test_a_margin_is_how_many_times_over_its_bound_a_value_is(line, expected):
    assert margin(line) == pytest.approx(expected)


@pytest.mark.parametrize("line", [
    "box-edge-drop mutant-a backup dt=0.0025 position_error_max: status diverged; energy of box rose by 17.7 x its "
    "energy scale 14.5 J, bound status ok or n/a (every case must run)",
    "point-force-torque mutant-a explicit_euler dt=0.0025 orientation_error_max: saturated, bound a number like the "
    "built-in explicit_euler (cross-check)",
])
def test_a_verdict_has_no_margin(line):
    assert margin(line) is None


def test_catches_are_widest_first_and_verdicts_last():
    lines = ("s mutant-a rk4 dt=0.01 m: 2, bound <= 1 (r)", "s mutant-a rk4 dt=0.01 n: saturated, bound a number (r)",
             "s mutant-a rk4 dt=0.01 o: 30, bound <= 1 (r)")
    verdict = Verdict("mutant-a", "default", True, tuple(Violation(x) for x in lines), (), 1.0)
    assert [c.margin for c in catches(verdict)] == [30.0, 2.0, None]
