"""Finite differences of inverse dynamics as users take them (issue #44): the layout of a differenced partial, its
truncation against the closed-form Taylor remainder, and the step sweep's V with its bottom where truncation meets
rounding (√ε forward, ε^(1/3) centred), all on functions whose derivatives are known by hand."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.comparisons.measure.finite_differences import SWEEP_STEPS, difference_partial, step_sweep

COEFFICIENTS = np.array([3.0, -2.0, 0.5])
"""[N m] The amplitudes of the test function tau_i = c_i sin(q_i) + (A q)_i + qdot_i^2."""
LINEAR = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 2.0], [-1.0, 0.0, 0.0]])
"""[N m / rad] A non-symmetric coupling: a transposed partial is told from the right one."""
TAYLOR_RELATIVE = 1e-3
"""The leading Taylor term predicts a difference's error to O(h) of itself: at h = 1e-4 (forward) and 1e-3
(centred), relative 1e-4 and 1e-6, and its rounding is 1e-12 and 1e-13 of it; 1e-3 leaves room for both."""


def _tau(q, qdot, qddot):
    return COEFFICIENTS * np.sin(q) + q @ LINEAR.T + qdot**2 + 0.0 * qddot


def _states(seed: int, count: int = 5):
    rng = np.random.default_rng(seed)
    return rng.uniform(-2, 2, (count, 3)), rng.uniform(-3, 3, (count, 3)), rng.uniform(-1, 1, (count, 3))


def _exact_dq(q):
    return np.einsum("bi,ij->bij", COEFFICIENTS * np.cos(q), np.eye(3)) + LINEAR


def test_a_differenced_partial_has_column_j_along_variable_j():
    q, qd, qdd = _states(1)
    found = difference_partial(_tau, q, qd, qdd, "q", np.full(len(q), 1e-6), centred=True)
    assert np.max(np.abs(found - _exact_dq(q))) < 1e-8  # centred at 1e-6: ~1e-12 truncation, ~1e-10 rounding
    assert np.max(np.abs(np.swapaxes(found, -1, -2) - _exact_dq(q))) > 1.0  # LINEAR is not symmetric


@pytest.mark.parametrize("centred, step", [(False, 1e-4), (True, 1e-3)])
def test_the_truncation_is_the_leading_taylor_term(centred, step):
    """Forward: D - T = h f''/2 = -h c sin(q) / 2 on the diagonal; centred: h^2 f'''/6 = -h^2 c cos(q) / 6."""
    q, qd, qdd = _states(2)
    error = difference_partial(_tau, q, qd, qdd, "q", np.full(len(q), step), centred) - _exact_dq(q)
    taylor = (-step * COEFFICIENTS * np.sin(q) / 2) if not centred else (-step**2 * COEFFICIENTS * np.cos(q) / 6)
    diagonal = np.diagonal(error, axis1=-2, axis2=-1)
    assert np.allclose(diagonal, taylor, rtol=TAYLOR_RELATIVE, atol=0.0)
    assert np.max(np.abs(error - np.einsum("bi,ij->bij", diagonal, np.eye(3)))) < 1e-9  # off-diagonal: linear, exact


def test_steps_are_per_state_and_along_qdot_a_forward_difference_of_a_square_errs_by_the_step():
    """d(qdot^2)/dqdot by (f(x + h) - f(x)) / h = 2 qdot + h exactly: each state's own h shows."""
    q, qd, qdd = _states(3)
    steps = np.array([1e-3, 2e-3, 4e-3, 1e-2, 5e-2])
    found = difference_partial(_tau, q, qd, qdd, "qdot", steps, centred=False)
    expected = np.einsum("bi,ij->bij", 2 * qd + steps[:, None], np.eye(3))
    assert np.allclose(found, expected, rtol=0, atol=1e-10)
    centred = difference_partial(_tau, q, qd, qdd, "qdot", steps, centred=True)
    assert np.allclose(centred, np.einsum("bi,ij->bij", 2 * qd, np.eye(3)), rtol=0, atol=1e-10)


def test_the_sweep_finds_the_bottom_of_the_v_where_truncation_meets_rounding():
    """Forward: error ~ h/2 + eps/h, least near sqrt(eps) ~ 1e-8 at ~1e-8; centred: ~ h^2/6 + eps/h, least near
    eps^(1/3) ~ 6e-6 at ~1e-11. Both ends of the V rise (the sweep spans it)."""
    q, qd, qdd = _states(4)
    found = step_sweep(_tau, q, qd, qdd, _exact_dq(q), floor=1.0)
    np.testing.assert_array_equal(found.steps, SWEEP_STEPS)
    step, error = found.best(centred=False)
    assert 1e-9 <= step <= 1e-7 and 1e-10 < error < 1e-7
    step, error = found.best(centred=True)
    assert 1e-6 <= step <= 1e-4 and 1e-13 < error < 1e-9
    for errors in (found.forward, found.central):
        assert errors[0] > 100 * np.min(errors) and errors[-1] > 100 * np.min(errors)


def test_a_sweep_of_an_engine_that_returns_nan_has_no_best_step():
    q, qd, qdd = _states(5)
    found = step_sweep(lambda *x: np.full_like(x[0], np.nan), q, qd, qdd, _exact_dq(q), floor=1.0)
    assert np.all(np.isnan(found.forward)) and np.isnan(found.best(centred=True)[0])
