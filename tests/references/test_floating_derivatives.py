"""Floating-base derivatives of core, Pinocchio and MuJoCo against the complex-step truth (issue #44), each engine's
own coordinates converted to the project's (references/common/floating_base.py project_partials): Solo-12's leg and
Go1's (joint damping), random orientations. Through the gate, a planted conversion mistake in a copy of Pinocchio's
adapter is caught naming it: tests/comparisons/gate/test_derivative_gate.py."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.core.model.derivatives import PARTIALS
from simparity.references.derivatives.complex_step import derivatives, tree_from_chain
from tests.helpers import floating_states, solo12_leg
from tests.references.test_complex_step import GRAVITY, _go1_leg

ANALYTIC = 1e-11
"""The shipped bound on analytic derivatives (rnea_ and aba_derivative_error_max): measured <= 1.5e-13 here."""
FORWARD_DIFFERENCES = 1e-5
"""MuJoCo's mjd_inverseFD at eps 1e-6 (forward): truncation eps / 2 |d2 tau| ~ 5e-7 of the partial's scale."""


@pytest.fixture(scope="module", params=["solo12", "go1"])
def floating(request):
    chain = solo12_leg() if request.param == "solo12" else _go1_leg()
    q, qd, _, tau = floating_states(chain, 6, 11)
    return chain, (q, qd, tau), derivatives(tree_from_chain(chain, GRAVITY), q, qd, tau)


def _relative(found: np.ndarray, truth: np.ndarray) -> float:
    return float(np.max(np.abs(found - truth)) / np.max(np.abs(truth)))


@pytest.mark.parametrize("engine", ["core", "pinocchio"])
def test_analytic_floating_base_derivatives_match_the_truth(floating, engine):
    chain, states, truth = floating
    found = make_engine(engine).build_joint_dynamics(chain, "recursive", GRAVITY).derivatives(*states)
    assert found.differences is None
    for name in PARTIALS:
        assert _relative(getattr(found, name), getattr(truth, name)) <= ANALYTIC, name


def test_mujoco_s_floating_base_differences_match_the_truth_to_their_truncation(floating):
    chain, states, truth = floating
    found = make_engine("mujoco").build_joint_dynamics(chain, "recursive", GRAVITY).derivatives(*states)
    assert found.differences is not None and not found.differences.centred
    for name in ("dtau_dq", "dtau_dqdot"):
        assert _relative(getattr(found, name), getattr(truth, name)) <= FORWARD_DIFFERENCES, name
