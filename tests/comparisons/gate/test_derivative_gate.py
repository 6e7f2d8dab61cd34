"""Issue #44's planted bugs in a user's derivatives, through the gate: a copy of Pinocchio's adapter whose ∂τ/∂q is
transposed, or whose ∂τ/∂q̇ misses its Coriolis (velocity) terms, turns the check red naming it on a 3-D arm; a
faithful copy passes beside the built-in engines. A user's finite differences are held to the scheme they claim: a
forward difference claimed centred, or a step 100 times the one declared, is caught; centred differences that say
so pass (not held to analytic rounding). On a floating base, a copy whose conversion to the project's convention
forgets the free flyer's w_b x v_b, or turns only its linear part, is caught on Solo-12."""

from __future__ import annotations

import pytest

from tests.helpers import PLANTED_ENGINE_FACTORY, assert_caught, run_planted

PLANTED = PLANTED_ENGINE_FACTORY + '''
from dataclasses import replace

import numpy as np

from simparity.core.model.derivatives import FiniteDifferences
from simparity.references.pinocchio.adapter import PinocchioEngine
from simparity.references.pinocchio import floating as pinocchio_floating
from simparity.references.pinocchio.floating import PinocchioFloatingDynamics
from simparity.references.pinocchio.joint_dynamics import PinocchioJointDynamics


class Faithful(PinocchioJointDynamics):
    pass


class Transposed(PinocchioJointDynamics):
    def derivatives(self, q, qdot, tau):
        found = super().derivatives(q, qdot, tau)
        return replace(found, dtau_dq=np.swapaxes(found.dtau_dq, -1, -2))


class NoCoriolis(PinocchioJointDynamics):
    def derivatives(self, q, qdot, tau):
        found = super().derivatives(q, qdot, tau)
        return replace(found, dtau_dqdot=np.broadcast_to(np.diag(self.damping), found.dtau_dqdot.shape).copy())


class Differenced(PinocchioJointDynamics):
    """RNEA partials by the user's own differences of Pinocchio's inverse dynamics (ABA's analytic): ``CENTRED``
    says what is computed, ``CLAIM_CENTRED`` and ``CLAIM_STEP`` what is declared."""

    CENTRED = CLAIM_CENTRED = True
    STEP = CLAIM_STEP = 1e-5

    def _difference(self, state, which):
        count, n = state[0].shape
        out = np.empty((count, n, n))
        for j in range(n):
            up, down = [x.copy() for x in state], [x.copy() for x in state]
            up[which][:, j] += self.STEP
            down[which][:, j] -= self.STEP if self.CENTRED else 0.0
            out[:, :, j] = (self.inverse_dynamics(*up) - self.inverse_dynamics(*down)) / (
                (2.0 if self.CENTRED else 1.0) * self.STEP)
        return out

    def derivatives(self, q, qdot, tau):
        found = super().derivatives(q, qdot, tau)
        state = (q, qdot, self.forward_dynamics(q, qdot, tau))
        steps = np.full(len(q), self.CLAIM_STEP)
        return replace(found, dtau_dq=self._difference(state, 0), dtau_dqdot=self._difference(state, 1),
                       differences=FiniteDifferences(self.CLAIM_CENTRED, steps, steps))


class OneSided(Differenced):
    CENTRED = False


class WrongStep(Differenced):
    STEP = 1e-3


class _Converted(PinocchioFloatingDynamics):
    """Pinocchio's floating-base derivatives converted with ``FLAGS`` (linear, angular, offset) instead of the
    adapter's (True, True, True)."""

    FLAGS = (True, True, True)

    def derivatives(self, q, qdot, tau):
        original = pinocchio_floating.project_partials
        pinocchio_floating.project_partials = lambda *args: original(*args[:7], *self.FLAGS)
        try:
            return super().derivatives(q, qdot, tau)
        finally:
            pinocchio_floating.project_partials = original


class FloatingFaithful(_Converted):
    pass


class NoOffset(_Converted):
    FLAGS = (True, True, False)


class AngularUnturned(_Converted):
    FLAGS = (True, False, True)


class OneState(PinocchioJointDynamics):
    def derivatives(self, q, qdot, tau):
        return super().derivatives(q[:1], qdot[:1], tau[:1])


FaithfulEngine = _engine(PinocchioEngine, Faithful, "pinocchio-copy")
OneStateEngine = _engine(PinocchioEngine, OneState, "pinocchio-one-state")
FloatingFaithfulEngine = _engine(PinocchioEngine, FloatingFaithful, "pinocchio-floating-copy")
NoOffsetEngine = _engine(PinocchioEngine, NoOffset, "pinocchio-no-offset")
AngularUnturnedEngine = _engine(PinocchioEngine, AngularUnturned, "pinocchio-angular-unturned")
DifferencedEngine = _engine(PinocchioEngine, Differenced, "pinocchio-centred")
OneSidedEngine = _engine(PinocchioEngine, OneSided, "pinocchio-one-sided")
WrongStepEngine = _engine(PinocchioEngine, WrongStep, "pinocchio-wrong-step")
TransposedEngine = _engine(PinocchioEngine, Transposed, "pinocchio-transposed")
NoCoriolisEngine = _engine(PinocchioEngine, NoCoriolis, "pinocchio-no-coriolis")
'''


def _run(tmp_path, monkeypatch, capsys, plugin: str) -> tuple[int, list[str], str]:
    return run_planted(tmp_path, monkeypatch, capsys, "planted_derivatives", PLANTED, "oblique-arm-dynamics", plugin)


@pytest.mark.slow
@pytest.mark.parametrize("plugin, name", [("TransposedEngine", "pinocchio-transposed"),
                                          ("NoCoriolisEngine", "pinocchio-no-coriolis")])
def test_a_planted_derivative_bug_is_caught_naming_the_engine(tmp_path, monkeypatch, capsys, plugin, name):
    assert_caught(_run(tmp_path, monkeypatch, capsys, plugin), name, "rnea_derivative_error_max")


@pytest.mark.slow
@pytest.mark.parametrize("plugin", ["FaithfulEngine", "DifferencedEngine"])
def test_a_faithful_copy_of_the_derivatives_passes(tmp_path, monkeypatch, capsys, plugin):
    code, violations, out = _run(tmp_path, monkeypatch, capsys, plugin)
    assert code == 0 and not violations, out[-2000:]


@pytest.mark.slow
@pytest.mark.parametrize("plugin, name", [("OneSidedEngine", "pinocchio-one-sided"),
                                          ("WrongStepEngine", "pinocchio-wrong-step")])
def test_differences_that_are_not_what_they_claim_are_caught(tmp_path, monkeypatch, capsys, plugin, name):
    assert_caught(_run(tmp_path, monkeypatch, capsys, plugin), name, "derivative_step_excess")


@pytest.mark.slow
def test_derivatives_of_the_wrong_shape_fail_their_case_in_one_line(tmp_path, monkeypatch, capsys):
    """A plugin answering for one state when asked for B: its case fails saying what shape was expected, the other
    engines' rows are kept, and the run ends with the check's verdict, no traceback."""
    code, violations, out = _run(tmp_path, monkeypatch, capsys, "OneStateEngine")
    assert code == 1 and "Traceback" not in out
    assert {line.split()[2] for line in violations} == {"pinocchio-one-state"}, violations
    results = (tmp_path / "run" / "results.csv").read_text(encoding="utf-8")
    assert "derivatives: dtau_dq has shape (1, 3, 3), expected (20, 3, 3)" in results


@pytest.mark.slow
@pytest.mark.parametrize("plugin, name", [("NoOffsetEngine", "pinocchio-no-offset"),
                                          ("AngularUnturnedEngine", "pinocchio-angular-unturned")])
def test_a_planted_floating_base_conversion_bug_is_caught_naming_the_engine(tmp_path, monkeypatch, capsys, plugin,
                                                                             name):
    assert_caught(run_planted(tmp_path, monkeypatch, capsys, "planted_derivatives", PLANTED,
                              "solo12-floating-dynamics", plugin), name, "rnea_derivative_error_max")


@pytest.mark.slow
def test_a_faithful_copy_of_the_floating_base_derivatives_passes(tmp_path, monkeypatch, capsys):
    code, violations, out = run_planted(tmp_path, monkeypatch, capsys, "planted_derivatives", PLANTED,
                                        "solo12-floating-dynamics", "FloatingFaithfulEngine")
    assert code == 0 and not violations, out[-2000:]
