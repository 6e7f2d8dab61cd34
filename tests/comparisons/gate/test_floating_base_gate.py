"""Issue #43's held-out check of floating bases through the gate: a user's engine that is MuJoCo's adapter with one
planted bug in its floating-base conversion (a free-joint angular velocity left in the body frame, the mass matrix
left in MuJoCo's coordinates, a linear velocity read in the base's local frame, the quaternion handed over in xyzw
order, the links' kinetic energy from an unturned angular velocity) turns the check red naming it; a
faithful copy of the same adapter passes beside the built-in engines."""

from __future__ import annotations

import pytest

from tests.helpers import PLANTED_ENGINE_FACTORY, assert_caught, run_planted

PLANTED = PLANTED_ENGINE_FACTORY + '''
import numpy as np

from simparity.references.common.floating_base import base_rotations, turned_base
from simparity.references.mujoco.adapter import MujocoEngine
from simparity.references.mujoco.floating import MujocoFloatingDynamics
from simparity.references.mujoco.joint_dynamics import MujocoJointDynamics


class Faithful(MujocoFloatingDynamics):
    pass


class BodyAngular(MujocoFloatingDynamics):
    """The project's world-axes angular velocity given to MuJoCo as its body-frame one."""

    def bias_forces(self, q, qdot):
        return turned_base(base_rotations(q), MujocoJointDynamics.bias_forces(self, q, qdot), False, True)

    def inverse_dynamics(self, q, qdot, qddot):
        rotation = base_rotations(q)
        own = MujocoJointDynamics.inverse_dynamics(self, q, qdot, turned_base(rotation, qddot, False, True, True))
        return turned_base(rotation, own, False, True)

    def forward_dynamics(self, q, qdot, tau):
        rotation = base_rotations(q)
        own = MujocoJointDynamics.forward_dynamics(self, q, qdot, turned_base(rotation, tau, False, True, True))
        return turned_base(rotation, own, False, True)

    def link_kinetic_energy(self, q, qdot):
        return MujocoJointDynamics.link_kinetic_energy(self, q, qdot)


class UnturnedMass(MujocoFloatingDynamics):
    """M left in MuJoCo's own coordinates (its angular rows and columns in the body frame)."""

    def mass_matrix(self, q):
        return MujocoJointDynamics.mass_matrix(self, q)


class LocalLinear(MujocoFloatingDynamics):
    """The linear velocity and force turned into the base's frame, as if MuJoCo's were local like Pinocchio's."""

    def bias_forces(self, q, qdot):
        rotation = base_rotations(q)
        own = MujocoJointDynamics.bias_forces(self, q, turned_base(rotation, qdot, True, True, True))
        return turned_base(rotation, own, True, True)


class XyzwQuat(MujocoFloatingDynamics):
    """MuJoCo given the quaternion in xyzw order (its qpos is wxyz); the conversion's R is right (a held-out review's)."""

    def _set(self, q_row, qdot_row, tau_row=None):
        q_row = np.array(q_row, dtype=float)
        q_row[3:7] = q_row[[4, 5, 6, 3]]
        super()._set(q_row, qdot_row, tau_row)


class EnergyUnturned(MujocoFloatingDynamics):
    """The links' kinetic energy with the world-axes angular velocity given as MuJoCo's body-frame one, only there."""

    def link_kinetic_energy(self, q, qdot):
        return MujocoJointDynamics.link_kinetic_energy(self, q, qdot)


FaithfulEngine = _engine(MujocoEngine, Faithful, "mujoco-copy")
BodyAngularEngine = _engine(MujocoEngine, BodyAngular, "mujoco-body-angular")
UnturnedMassEngine = _engine(MujocoEngine, UnturnedMass, "mujoco-unturned-mass")
LocalLinearEngine = _engine(MujocoEngine, LocalLinear, "mujoco-local-linear")
XyzwQuatEngine = _engine(MujocoEngine, XyzwQuat, "mujoco-xyzw")
EnergyUnturnedEngine = _engine(MujocoEngine, EnergyUnturned, "mujoco-energy-unturned")
'''


def _run(tmp_path, monkeypatch, capsys, plugin: str) -> tuple[int, list[str], str]:
    return run_planted(tmp_path, monkeypatch, capsys, "planted_floating", PLANTED, "solo12-floating-dynamics", plugin)


@pytest.mark.slow
@pytest.mark.parametrize("plugin, name, metric", [
    ("BodyAngularEngine", "mujoco-body-angular", "bias_force_error_max"),
    ("UnturnedMassEngine", "mujoco-unturned-mass", "mass_matrix_error_max"),
    ("LocalLinearEngine", "mujoco-local-linear", "bias_force_error_max"),
    ("XyzwQuatEngine", "mujoco-xyzw", "mass_matrix_error_max"),
    ("EnergyUnturnedEngine", "mujoco-energy-unturned", "kinetic_energy_residual"),
])
def test_a_planted_floating_base_convention_bug_is_caught_naming_the_engine(tmp_path, monkeypatch, capsys, plugin,
                                                                           name, metric):
    assert_caught(_run(tmp_path, monkeypatch, capsys, plugin), name, metric)


@pytest.mark.slow
def test_a_faithful_copy_of_the_adapter_passes(tmp_path, monkeypatch, capsys):
    code, violations, out = _run(tmp_path, monkeypatch, capsys, "FaithfulEngine")
    assert code == 0 and not violations, out[-2000:]
