"""Issue #43's held-out check of floating bases through the gate: a user's engine that is MuJoCo's adapter with one
planted bug in its floating-base conversion (a free-joint angular velocity left in the body frame, the mass matrix
left in MuJoCo's coordinates, a linear velocity read in the base's local frame, the quaternion handed over in xyzw
order, the links' kinetic energy from an unturned angular velocity) turns the check red naming it; a
faithful copy of the same adapter passes beside the built-in engines."""

from __future__ import annotations

import sys

import pytest

from simparity.comparisons.cli.main import main

PLANTED = '''
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


def _engine(model_class, engine_name):
    class Planted(MujocoEngine):
        name = engine_name

        def build_joint_dynamics(self, chain, method, gravity_world):
            return model_class(chain, gravity_world)

    Planted.__name__ = model_class.__name__ + "Engine"
    return Planted


FaithfulEngine = _engine(Faithful, "mujoco-copy")
BodyAngularEngine = _engine(BodyAngular, "mujoco-body-angular")
UnturnedMassEngine = _engine(UnturnedMass, "mujoco-unturned-mass")
LocalLinearEngine = _engine(LocalLinear, "mujoco-local-linear")
XyzwQuatEngine = _engine(XyzwQuat, "mujoco-xyzw")
EnergyUnturnedEngine = _engine(EnergyUnturned, "mujoco-energy-unturned")
'''


def _run(tmp_path, monkeypatch, capsys, plugin: str) -> tuple[int, list[str], str]:
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", f"{tmp_path}:{':'.join(sys.path)}")  # the probes and workers import it
    (tmp_path / "planted_floating.py").write_text(PLANTED, encoding="utf-8")
    code = main(["run", "solo12-floating-dynamics", "--quick", "--check", "--engines",
                 f"core,mujoco,pybullet,pinocchio,planted_floating:{plugin}", "--out", str(tmp_path / "run"),
                 "--history", str(tmp_path / "h.db"), "--no-report", "--jobs", "1"])
    out = capsys.readouterr().out
    return code, [line for line in out.splitlines() if line.startswith("violation: ")], out


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
    code, violations, out = _run(tmp_path, monkeypatch, capsys, plugin)
    assert code == 1, out[-2000:]
    assert {line.split()[2] for line in violations} == {name}, violations
    assert any(metric in line for line in violations), violations


@pytest.mark.slow
def test_a_faithful_copy_of_the_adapter_passes(tmp_path, monkeypatch, capsys):
    code, violations, out = _run(tmp_path, monkeypatch, capsys, "FaithfulEngine")
    assert code == 0 and not violations, out[-2000:]
