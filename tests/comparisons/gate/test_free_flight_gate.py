"""Issue #46's planted bugs in a floating base's motion through the gate: a user's engine that is MuJoCo's or
PyBullet's adapter or core with one planted bug (the base's angular velocity handed over unturned, the joints' torques
also applied to the base as if an actuator had no reaction, the base 1 % heavy, PyBullet's base inertial frame taken
for the base link) turns the check of ``solo12-free-flight`` (``go1-free-flight`` for the last: Solo-12's base has its
centre of mass at its origin, Go1's 2.2 cm off, and Go1 spins at 3.9 rad/s, so the point the base is read at turns
away from the base's origin) red naming it and the metric that sees it; a faithful copy of MuJoCo's or PyBullet's
adapter passes beside the built-in engines. A sweep (about a minute: four runs of the scene), in
``.ci/run``."""

from __future__ import annotations

import pytest

from tests.helpers import PLANTED_MOTION_FACTORY, assert_caught, run_planted

PLANTED = PLANTED_MOTION_FACTORY + '''
from dataclasses import replace

from simparity.core.articulated.motion import CoreJointMotion
from simparity.core.inhouse import InHouseEngine
from simparity.core.model.scenes.chain import LinkInertia
from simparity.references.mujoco.adapter import MujocoEngine
from simparity.references.mujoco.joint_motion import MujocoJointMotion
from simparity.references.pybullet.adapter import PybulletEngine
from simparity.references.pybullet.floating_body import BaseInertial
from simparity.references.pybullet.joint_motion import PybulletJointMotion


class Faithful(MujocoJointMotion):
    pass


class Unturned(MujocoJointMotion):
    """The project's world-axes angular velocity handed to MuJoCo as its body-frame one, and read back so."""

    def _own(self, q, qdot):
        return qdot

    def run(self, n_steps):
        floating, self._floating = self._floating, None
        try:
            return super().run(n_steps)
        finally:
            self._floating = floating


class NoReaction(MujocoJointMotion):
    """The joints' torques also applied to the base's rotation: an actuator whose reaction on its parent is lost."""

    def __init__(self, scene, integrator, dt):
        super().__init__(scene, integrator, dt)
        self._control[0, 0, self._dof[3:6]] = scene.torque


class HeavyBase(CoreJointMotion):
    """Core with the floating base 1 % heavier than the file says."""

    def __init__(self, scene, scheme, dt):
        base = scene.chain.base_inertia
        heavy = LinkInertia(1.01 * base.mass, base.com_xyz, 1.01 * base.inertia_com)
        super().__init__(replace(scene, chain=replace(scene.chain, base_inertia=heavy)), scheme, dt)


class PybulletCopy(PybulletJointMotion):
    pass


class InertialAsLink(PybulletJointMotion):
    """PyBullet's free base put and read as if its inertial frame were the base link's (its offset forgotten)."""

    def __init__(self, scene, dt):
        super().__init__(scene, dt)
        for bodies in (self._world, self._model, self._probe):
            if bodies is not None and bodies.base is not None:
                bodies.base = BaseInertial(0.0 * bodies.base.position, bodies.base.quat_wxyz)


FaithfulEngine = _engine(MujocoEngine, Faithful, "mujoco-copy")
PybulletCopyEngine = _engine(PybulletEngine, lambda scene, integrator, dt: PybulletCopy(scene, dt), "pybullet-copy")
InertialAsLinkEngine = _engine(PybulletEngine, lambda scene, integrator, dt: InertialAsLink(scene, dt),
                               "pybullet-inertial-as-link")
UnturnedEngine = _engine(MujocoEngine, Unturned, "mujoco-unturned")
NoReactionEngine = _engine(MujocoEngine, NoReaction, "mujoco-no-reaction")
HeavyBaseEngine = _engine(InHouseEngine, HeavyBase, "core-heavy-base")
'''


def _run(tmp_path, monkeypatch, capsys, plugin: str,
         scene: str = "solo12-free-flight") -> tuple[int, list[str], str]:
    """Beside Pinocchio, the scene's reference, alone: the built-in engines' rows are the suite's own business."""
    return run_planted(tmp_path, monkeypatch, capsys, "planted_free_flight", PLANTED, scene, plugin,
                       engines="pinocchio")


@pytest.mark.sweep
@pytest.mark.slow
@pytest.mark.parametrize("plugin, name, metric, scene", [
    ("UnturnedEngine", "mujoco-unturned", "chain_angular_momentum_drift_max", "solo12-free-flight"),
    ("NoReactionEngine", "mujoco-no-reaction", "chain_angular_momentum_drift_max", "solo12-free-flight"),
    ("HeavyBaseEngine", "core-heavy-base", "joint_angle_error_max", "solo12-free-flight"),
    ("InertialAsLinkEngine", "pybullet-inertial-as-link", "joint_angle_error_max", "go1-free-flight"),
])
def test_a_planted_free_flight_bug_is_caught_naming_the_engine(tmp_path, monkeypatch, capsys, plugin, name, metric,
                                                                scene):
    assert_caught(_run(tmp_path, monkeypatch, capsys, plugin, scene), name, metric)


@pytest.mark.sweep
@pytest.mark.slow
@pytest.mark.parametrize("plugin, scene", [("FaithfulEngine", "solo12-free-flight"), ("FaithfulEngine", "go1-free-flight"),
                                           ("PybulletCopyEngine", "solo12-free-flight"),
                                           ("PybulletCopyEngine", "go1-free-flight")])
def test_a_faithful_copy_of_the_adapter_passes(tmp_path, monkeypatch, capsys, plugin, scene):
    code, violations, out = _run(tmp_path, monkeypatch, capsys, plugin, scene)
    assert code == 0 and not violations, out[-2000:]


@pytest.mark.sweep
@pytest.mark.slow
def test_a_user_s_engine_rk4_is_held_by_rk4_where_mujoco_did_not_run(tmp_path, monkeypatch, capsys):
    """A user's RK4 that, as MuJoCo's, moves its free joint by the exponential map (scheme engine_rk4) has no built-in
    of its kind without MuJoCo in the run: it is cross-checked against core's and Pinocchio's RK4 (its family), at
    twice their error. A held-out trial's MuJoCo copy handing over the angular velocity unturned passed otherwise
    (0.6 rad against 1.5e-7)."""
    source = PLANTED + '''

class UnturnedRK4(Unturned):
    pass


UnturnedRK4Engine = _engine(MujocoEngine, UnturnedRK4, "mujoco-unturned-rk4")
'''
    result = run_planted(tmp_path, monkeypatch, capsys, "planted_family", source, "go1-free-flight",
                         "UnturnedRK4Engine", engines="core,pinocchio")
    assert_caught(result, "mujoco-unturned-rk4", "cross-check: 2 x the largest built-in rk4")
