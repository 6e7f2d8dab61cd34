"""Issue #44's planted bugs in a user's step Jacobian, through the gate: a copy of core whose RK4 step Jacobian is
its explicit Euler one, whose Jacobian drops the velocity (Coriolis) terms, or whose dynamics part is 10 % off while
it claims forward differences at a step of 1 (a claim that must excuse nothing: found by a held-out review), or a copy
of MuJoCo's adapter whose mjd_transitionFD is one-sided while it declares centred differences, turns the check red
naming it on a driven arm; faithful copies of both pass beside the built-in engines."""

from __future__ import annotations

import pytest

from tests.helpers import PLANTED_MOTION_FACTORY, assert_caught, run_planted

PLANTED = PLANTED_MOTION_FACTORY + '''
import mujoco
import numpy as np

from simparity.core.articulated.motion import CoreJointMotion
from simparity.core.model.derivatives import FiniteDifferences, StepJacobian
from simparity.core.inhouse import InHouseEngine
from simparity.references.mujoco.adapter import MujocoEngine
from simparity.references.mujoco.joint_motion import MujocoJointMotion



class EulerForRk4(CoreJointMotion):
    """RK4 steps, its Jacobian carried as if the step were explicit Euler's."""

    def step_jacobian(self, q, qdot, tau):
        scheme, self._scheme = self._scheme, "explicit_euler" if self._scheme == "rk4" else self._scheme
        try:
            return super().step_jacobian(q, qdot, tau)
        finally:
            self._scheme = scheme


class NoVelocityTerms(CoreJointMotion):
    """The step's Jacobian with every dq'/dqdot and dqdot'/dqdot entry as at rest: I h and I (the Coriolis and
    damping terms dropped)."""

    def step_jacobian(self, q, qdot, tau):
        found = super().step_jacobian(q, qdot, tau)
        n = found.by_force.shape[-1]
        by_state = np.array(found.by_state)
        by_state[:, :n, n:], by_state[:, n:, n:] = self._dt * np.eye(n), np.eye(n)
        return StepJacobian(by_state, found.by_force)


class TenPercentBigStep(CoreJointMotion):
    """The step's change (dx'/dx - I) 10 % too large, declared forward differences at a step of 1."""

    def step_jacobian(self, q, qdot, tau):
        found = super().step_jacobian(q, qdot, tau)
        identity = np.eye(found.by_state.shape[-1])
        steps = np.ones(len(found.by_state))
        return StepJacobian(identity + 1.1 * (found.by_state - identity), found.by_force,
                            FiniteDifferences(False, steps, steps))


class OneSided(MujocoJointMotion):
    """mjd_transitionFD called forward (flg_centered 0), the Jacobian still declared centred."""

    def step_jacobian(self, q, qdot, tau):
        original = mujoco.mjd_transitionFD
        mujoco.mjd_transitionFD = lambda m, d, eps, centred, *rest: original(m, d, eps, False, *rest)
        try:
            return super().step_jacobian(q, qdot, tau)
        finally:
            mujoco.mjd_transitionFD = original


CoreCopy = _engine(InHouseEngine, CoreJointMotion, "core-copy")
EulerForRk4Engine = _engine(InHouseEngine, EulerForRk4, "core-euler-jacobian")
MujocoCopy = _engine(MujocoEngine, MujocoJointMotion, "mujoco-copy")
OneSidedEngine = _engine(MujocoEngine, OneSided, "mujoco-one-sided")
NoVelocityTermsEngine = _engine(InHouseEngine, NoVelocityTerms, "core-no-velocity-terms")
TenPercentBigStepEngine = _engine(InHouseEngine, TenPercentBigStep, "core-ten-percent-big-step")
'''


def _run(tmp_path, monkeypatch, capsys, plugin: str) -> tuple[int, list[str], str]:
    return run_planted(tmp_path, monkeypatch, capsys, "planted_step_jacobians", PLANTED, "driven-arm", plugin)


@pytest.mark.slow
@pytest.mark.parametrize("plugin, name, metric", [
    ("EulerForRk4Engine", "core-euler-jacobian", "step_jacobian_error_max"),
    ("OneSidedEngine", "mujoco-one-sided", "step_jacobian_step_excess"),
    ("NoVelocityTermsEngine", "core-no-velocity-terms", "step_jacobian_error_max"),
    ("TenPercentBigStepEngine", "core-ten-percent-big-step", "step_jacobian_step_excess")])
def test_a_planted_step_jacobian_bug_is_caught_naming_the_engine(tmp_path, monkeypatch, capsys, plugin, name, metric):
    assert_caught(_run(tmp_path, monkeypatch, capsys, plugin), name, metric)


@pytest.mark.slow
@pytest.mark.parametrize("plugin", ["CoreCopy", "MujocoCopy"])
def test_faithful_copies_of_the_step_jacobians_pass(tmp_path, monkeypatch, capsys, plugin):
    code, violations, out = _run(tmp_path, monkeypatch, capsys, plugin)
    assert code == 0 and not violations, out[-2000:]
