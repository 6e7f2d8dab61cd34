"""Orders and verdicts that cannot pass for the wrong reason (issue #38, section 2): an order fit is ok only
within theory's band or below it (where the gate's lower bound judges it), never above; a run whose energy left
its bound is diverged whether or not its error also saturated; a contact run that gains energy at most impacts is
diverged, by one energy budget per impact."""

import math

import numpy as np
import pytest
import pandas as pd

from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.in_process import run_in_process as run_scene
from simparity.comparisons.gate.check import check_table
from simparity.comparisons.gate.tolerances import load_tolerances
from simparity.comparisons.measure.joint_motion_metrics import JOINT_MOTION_ORDERS
from simparity.comparisons.measure.metrics import observed_order
from simparity.comparisons.measure.rows import Case
from simparity.core.model.files import tomllib
from simparity.core.model.results import COLUMNS, OK

COARSE = np.array([0.0125, 0.025, 0.05, 0.1])
"""[s] A ladder of coarse steps, the finest first."""


def _order_rows(scheme: str, theory: int, slope: float) -> list:
    """The joint-motion order rows of a ladder whose errors fall exactly as dt^slope."""
    fit = observed_order(COARSE, 1e-3 * (COARSE / COARSE[-1]) ** slope, theory=theory)
    case = Case("user-pendulum", "core", scheme, math.nan, "analytic:closed_form", scheme)
    return case.rows(JOINT_MOTION_ORDERS, OK, "against analytic:closed_form",
                     {metric: fit for metric in JOINT_MOTION_ORDERS})


def _check(rows):
    return check_table(pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS)), load_tolerances(),
                       cross_checked=False)


def test_an_order_far_above_theory_is_typed_not_ok_and_the_shipped_gate_does_not_count_it_as_an_order():
    """RK4 at 5.1 and the midpoint rule at 2.89 (a large-amplitude pendulum at coarse steps) are outside their
    asymptotic range: n/a flagged superconvergent, the fitted order and the local slopes in the detail; the shipped
    gate holds no such row as a measured order (it neither passes it as ok nor counts its series as measured)."""
    for scheme, theory, slope in (("rk4", 4, 5.1), ("midpoint", 2, 2.89)):
        rows = _order_rows(scheme, theory, slope)
        assert {(r.status, r.flag) for r in rows} == {("n/a", "superconvergent")}, scheme
        assert all(f"{slope:.3g} > theory {theory}" in r.detail and "local slopes" in r.detail for r in rows)
        result = _check(rows)
        assert result.passed and not result.series, scheme


def test_an_order_is_ok_inside_theorys_band_and_below_it_fails_the_shipped_gate():
    """Bounded on both sides: within 0.5 of theory an order is a plain ok that the gate passes; more than 0.5 under
    it, ok and flagged below-theory, which the shipped lower bound fails."""
    inside = _order_rows("rk4", 4, 4.3)
    assert {(r.status, r.flag) for r in inside} == {(OK, "")}
    assert _check(inside).passed
    below = _order_rows("rk4", 4, 3.0)
    assert {(r.status, r.flag) for r in below} == {(OK, "below-theory")}
    assert {v.metric for v in _check(below).violations} == set(JOINT_MOTION_ORDERS)


def test_a_contact_that_gains_energy_at_most_impacts_is_diverged_with_the_count_and_one_budget_reads_them():
    """A ball whose first impact is nearly plastic (0.2), then rebounds 20 % faster than it hits at two impacts of
    every three (energy kept 1.44 at 6 of 11, never 3 in a row): each gain is small beside the first drop's energy
    (under 4 % of the largest kinetic energy), but the contact pumps energy in at most impacts: diverged, with the
    count; energy_gain_max reads the same impacts against the same budget as energy_kept (0.44 = 1.44 - 1)."""
    from simparity.comparisons.measure.contact_metrics import contact_blow_up, contact_metrics, read_contact
    from tests.comparisons.measure.test_contact_metrics import G, H, _gaining_bounces, _scene, _trajectory

    ratios = [0.2] + [1.2, 1.2, 0.8] * 3
    end, speed = math.sqrt(2 * H / G), math.sqrt(2 * G * H)
    for ratio in ratios:  # the end of the flight after the last listed impact
        speed *= ratio
        end += 2 * speed / G
    times = np.arange(0, end + 0.01, 0.001)
    scene = _scene(0.5)
    run = _trajectory(times, *_gaining_bounces(times, ratios))
    reading = read_contact(scene, run)
    assert "gained energy at 6 of its 11 impacts" in contact_blow_up(scene, reading)
    values = contact_metrics(scene, run, None, reading)
    assert values["energy_kept_median"].value == pytest.approx(1.44, rel=1e-6)
    assert values["energy_gain_max"].value == pytest.approx(values["energy_kept_max"].value - 1, rel=1e-6)


def _hanging_rod(q0: float, dts: list[float]):
    """A 1 m, 1 kg rod hinged at one end about z and hanging at q = 0 (gravity along its rest direction, +x),
    released at rest ``q0`` rad from hanging, stepped 3 s by explicit Euler against Jacobi's closed form."""
    from simparity.comparisons.scenes.loading.scene_file import parse_scenes

    text = f"""
[scene]
name = "hanging-rod"
description = "a rod released {q0} rad from hanging"
kind = "joint_motion"
reference = "analytic"
[chain]
end_effector = "tip"
end_effector_xyz = [1.0, 0.0, 0.0]
[[chain.joint]]
name = "hinge"
type = "revolute"
axis = [0.0, 0.0, 1.0]
mass = 1.0
com_xyz = [0.5, 0.0, 0.0]
inertia = [[1.6666666666666667e-05, 0.0, 0.0], [0.0, 0.08334166666666667, 0.0], [0.0, 0.0, 0.08334166666666667]]
[world]
gravity_world = [9.81, 0.0, 0.0]
[initial]
q = [{q0}]
qdot = [0.0]
[simulation]
duration = 3.0
dt = {dts}
integrators = ["explicit_euler"]
"""
    [scene] = parse_scenes(tomllib.loads(text))
    return scene


def test_explicit_euler_at_one_step_is_diverged_whether_the_gain_blows_the_swing_up_or_carries_it_over_the_top():
    """Explicit Euler at 0.02 s gains energy on a swinging rod at every amplitude: released 0.3 rad from hanging its
    kinetic energy passes twice the budget; released 2.5 rad from hanging the gain carries it over the top (its
    potential climbs 0.11 of the budget above the most the exact motion reaches) and its angle error saturates. Both
    are diverged, not one diverged and the other n/a saturated; at 0.005 s neither is (their angle errors are
    measured)."""
    verdicts = {}
    for q0 in (0.3, 2.5):
        rows = run_scene(_hanging_rod(q0, [0.005, 0.02]), [make_engine("core")], make_engine, repeats=0)
        angle = {r.dt: r for r in rows if r.engine == "core" and r.metric == "joint_angle_error_max"}
        verdicts[q0] = {dt: row.status for dt, row in angle.items()}
        assert "energy" in angle[0.02].detail
    assert verdicts == {0.3: {0.005: OK, 0.02: "diverged"}, 2.5: {0.005: OK, 0.02: "diverged"}}
