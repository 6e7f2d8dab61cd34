"""Orders and verdicts that cannot pass for the wrong reason (issue #38, section 2): an order fit is ok only
within theory's band or below it (where the gate's lower bound judges it), never above; a run whose energy left
its bound is diverged whether or not its error also saturated; a contact run that gains energy at most impacts is
diverged, by one energy budget per impact."""

import math

import numpy as np
import pandas as pd

from simparity.comparisons.gate.check import check_table
from simparity.comparisons.gate.tolerances import load_tolerances
from simparity.comparisons.measure.joint_motion_metrics import JOINT_MOTION_ORDERS
from simparity.comparisons.measure.metrics import observed_order
from simparity.comparisons.measure.rows import Case
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
