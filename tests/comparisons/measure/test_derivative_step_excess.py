"""derivative_step_excess (issue #44): differenced partials held to the truncation of the scheme they declare, on
hand-made partials: a scheme as good as its claim reads 1, one 1000x worse reads 1000, and where the claimed scheme
is exact the rounding allowance (DIFFERENCE_ROUNDING eps |tau| / h) is what an engine is held to."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.comparisons.measure.derivative_metrics import DIFFERENCE_ROUNDING, derivative_errors, step_excess
from simparity.core.model.metric_catalogue import RNEA_DERIVATIVE_ERROR_MAX
from simparity.core.model.derivatives import DynamicsDerivatives, FiniteDifferences

EPS = np.finfo(float).eps


def _partials(dq, dqd, differences=None) -> DynamicsDerivatives:
    return DynamicsDerivatives(dq, dqd, forward_missing="none here", differences=differences)


def _truth(rng):
    return _partials(rng.normal(size=(3, 2, 2)), rng.normal(size=(3, 2, 2)))


def test_analytic_partials_have_no_step_excess():
    truth = _truth(np.random.default_rng(0))
    found = step_excess(truth, truth, {}, np.ones(3))
    assert found.unmeasurable.startswith("analytic")


@pytest.mark.parametrize("factor", [1.0, 1000.0])
def test_the_excess_is_the_ratio_to_the_claimed_schemes_error(factor):
    rng = np.random.default_rng(1)
    truth = _truth(rng)
    claimed_error = 1e-6 * rng.normal(size=(2, 3, 2, 2))
    expected = {"dtau_dq": truth.dtau_dq + claimed_error[0], "dtau_dqdot": truth.dtau_dqdot + claimed_error[1]}
    differences = FiniteDifferences(False, np.full(3, 1e-6), np.full(3, 1e-6))
    own = _partials(truth.dtau_dq + factor * claimed_error[0], truth.dtau_dqdot + factor * claimed_error[1],
                    differences)
    found = step_excess(own, truth, expected, np.ones(3))
    assert found.value == pytest.approx(factor, rel=1e-9)
    assert "forward_differences" in found.note


def test_where_the_claimed_scheme_is_exact_rounding_is_allowed():
    """The claimed scheme's own error 0 (a linear function): an engine is held to DIFFERENCE_ROUNDING eps |tau| / h,
    per state with its own step and force."""
    rng = np.random.default_rng(2)
    truth = _truth(rng)
    steps, forces = np.array([1e-4, 1e-6, 1e-8]), np.array([10.0, 1.0, 0.1])
    allowance = DIFFERENCE_ROUNDING * EPS * forces / steps
    own = _partials(truth.dtau_dq + 0.5 * allowance[:, None, None], truth.dtau_dqdot,
                    FiniteDifferences(True, steps, steps))
    found = step_excess(own, truth, {"dtau_dq": truth.dtau_dq, "dtau_dqdot": truth.dtau_dqdot}, forces)
    assert found.value == pytest.approx(0.5, rel=1e-9)


@pytest.mark.parametrize("steps", [np.array([1e-6, -1e-6, 1e-6]), np.array([1e-6, np.nan, 1e-6]), np.ones((3, 1))])
def test_steps_must_be_positive_finite_and_one_per_state(steps):
    with pytest.raises(ValueError, match="step_q"):
        FiniteDifferences(False, steps, np.ones(3))


def test_as_many_steps_as_states():
    truth = _truth(np.random.default_rng(3))
    with pytest.raises(ValueError, match="2 difference steps for 3 states"):
        _partials(truth.dtau_dq, truth.dtau_dqdot, FiniteDifferences(True, np.ones(2), np.ones(2)))


def test_no_allowance_at_all_is_no_excuse():
    """A claimed scheme exact at every state and no rounding allowance (a force scale of 0): any error of the engine is
    an excess, never a ratio of 0 (found by a held-out review: 0 / 0 read as 0)."""
    rng = np.random.default_rng(4)
    truth = _truth(rng)
    own = _partials(truth.dtau_dq + 1.0, truth.dtau_dqdot, FiniteDifferences(False, np.full(3, 1e-6), np.full(3, 1e-6)))
    found = step_excess(own, truth, {"dtau_dq": truth.dtau_dq, "dtau_dqdot": truth.dtau_dqdot}, np.zeros(3))
    assert found.value > 1e100


def test_a_partial_zero_in_truth_and_floor_is_judged_against_one():
    """∂τ/∂q̇ of a chain at rest without damping is 0: an engine's non-zero entries there are errors (relative to 1),
    not a partial skipped (found by a held-out review)."""
    rng = np.random.default_rng(5)
    truth = _truth(rng)
    zero = _partials(truth.dtau_dq, np.zeros_like(truth.dtau_dqdot))
    wrong = _partials(truth.dtau_dq, np.full_like(truth.dtau_dqdot, 5.0))
    floors = {name: 0.0 for name in ("dtau_dq", "dtau_dqdot", "dqddot_dq", "dqddot_dqdot", "dqddot_dtau")}
    found = derivative_errors(wrong, zero, np.tile(np.eye(2), (3, 1, 1)), floors)
    assert found[RNEA_DERIVATIVE_ERROR_MAX].value == pytest.approx(5.0)
