"""Issue #44's planted bugs in a user's derivatives, through the gate: a copy of Pinocchio's adapter whose ∂τ/∂q is
transposed, or whose ∂τ/∂q̇ misses its Coriolis (velocity) terms, turns the check red naming it on a 3-D arm; a
faithful copy passes beside the built-in engines."""

from __future__ import annotations

import pytest

from tests.helpers import PLANTED_ENGINE_FACTORY, assert_caught, run_planted

PLANTED = PLANTED_ENGINE_FACTORY + '''
from dataclasses import replace

import numpy as np

from simparity.references.pinocchio.adapter import PinocchioEngine
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


FaithfulEngine = _engine(PinocchioEngine, Faithful, "pinocchio-copy")
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
def test_a_faithful_copy_of_the_derivatives_passes(tmp_path, monkeypatch, capsys):
    code, violations, out = _run(tmp_path, monkeypatch, capsys, "FaithfulEngine")
    assert code == 0 and not violations, out[-2000:]
