"""Issue #46's planted contact bugs through the gate: a user's engine that is core or MuJoCo's adapter with one planted
bug (the plane's normal turned, so that it pulls; the contact forces reported with their sign flipped; MuJoCo's spheres
twice as large, so that they touch early; one sphere's force left out of what is reported; MuJoCo's spheres reported
from their bodies' centres of mass; MuJoCo's forces read without
the applied torque; Pinocchio's impulses reported as forces; a Pinocchio contact that bounces, so that the arm never
rests; PyBullet's spheres left with Bullet's default friction; on a slope with friction: MuJoCo's contact without the
friction or with its pyramidal cone, its friction reported on the wrong side, PyBullet's spheres given twice the
friction or its cone friction off (a box), core's friction turned along the slip or reported but not applied) turns the check of ``solo12-drop-stand``, ``pendulum-press``, ``arm-strike-press`` or
``solo12-incline-slide`` red naming it and the metric that sees it; faithful copies of MuJoCo, Pinocchio and PyBullet
pass on them and on ``solo12-incline-stand``. A sweep (a run of the scene per bug), in ``.ci/run``."""

from __future__ import annotations

import pytest

from tests.helpers import PLANTED_MOTION_FACTORY, assert_caught, run_planted

PLANTED = PLANTED_MOTION_FACTORY + '''
from dataclasses import replace

import mujoco
import numpy as np

from simparity.core.articulated import stepping
from simparity.core.articulated.chain_contact import ChainContactForces
from simparity.core.articulated.chain_impulse import RigidContact
from simparity.core.articulated.motion import CoreJointMotion
from simparity.core.inhouse import InHouseEngine
from simparity.core.model.scenes.contact import Plane
from simparity.references.mujoco.adapter import MujocoEngine
from simparity.references.mujoco.joint_motion import MujocoJointMotion
from simparity.references.pinocchio.adapter import PinocchioEngine
from simparity.references.pinocchio.contact import PlaneContact
from simparity.references.pinocchio.floating_motion import PinocchioFloatingMotion
from simparity.references.pinocchio.joint_motion import PinocchioJointMotion
from simparity.references.pybullet.adapter import PybulletEngine
from simparity.references.pybullet.joint_motion import PybulletJointMotion
from simparity.references.pybullet.quiet import pybullet


class Faithful(MujocoJointMotion):
    pass


class Pulling(CoreJointMotion):
    """Core with the plane's normal turned: the same plane, its free side the other one, so the spring pulls."""

    def __init__(self, scene, scheme, dt):
        plane = scene.contact.plane
        turned = Plane(-plane.normal_world, -plane.offset, plane.name)
        super().__init__(replace(scene, contact=replace(scene.contact, plane=turned)), scheme, dt)


class FlippedForces(MujocoJointMotion):
    """MuJoCo's forces read as acting on the plane instead of the sphere."""

    def contact_forces(self, q, qdot, times):
        return -super().contact_forces(q, qdot, times)


class FatSpheres(MujocoJointMotion):
    """MuJoCo given spheres of twice the scene's radius: contact before the feet touch."""

    def __init__(self, scene, integrator, dt):
        fat = tuple(replace(s, radius=2 * s.radius) for s in scene.contact.spheres)
        super().__init__(replace(scene, contact=replace(scene.contact, spheres=fat)), integrator, dt)


class WithoutTorque(MujocoJointMotion):
    """MuJoCo's forces read at each state without the applied torque: its soft contact then misses the torque's
    share."""

    def contact_forces(self, q, qdot, times):
        return self._contact.forces(self._qpos, self._dof, q, self._own(q, qdot),
                                    np.zeros((len(q), self.model.nv)))


class ComCentres(MujocoJointMotion):
    """MuJoCo's sphere centres reported from each body's centre of mass instead of its frame (xipos for xpos), its
    dynamics right."""

    def contact_centres(self, q):
        reader, m = self._contact, self.model
        bodies = m.geom_bodyid[reader._geoms]
        out = np.empty((len(q), len(bodies), 3))
        for b, row in enumerate(np.asarray(q, dtype=float)):
            reader._set(self._qpos, self._dof, row, None)
            mujoco.mj_kinematics(m, reader._data)
            d = reader._data
            out[b] = d.geom_xpos[reader._geoms] - d.xpos[bodies] + d.xipos[bodies]
        return out


class LostSphere(MujocoJointMotion):
    """One sphere's force left out of what is reported."""

    def contact_forces(self, q, qdot, times):
        forces = super().contact_forces(q, qdot, times)
        forces[:, 0] = 0.0
        return forces


def PinocchioCopy(scene, integrator, dt):
    """Pinocchio's own simulation of the scene, as its adapter builds it."""
    return PinocchioEngine().build_joint_motion(scene, integrator, dt)


class ImpulsesAsForces(PinocchioFloatingMotion):
    """Pinocchio's contact impulses reported as forces: the division by dt forgotten."""

    def contact_forces(self, q, qdot, times):
        return self._dt * super().contact_forces(q, qdot, times)


class BouncingContact(PlaneContact):
    """Newton's restitution 0.5 on every contact solve (the impulses x 1.5): a resting sphere is thrown up each step."""

    def solve(self, configuration, v_free):
        impulses, change = super().solve(configuration, v_free)
        return 1.5 * impulses, 1.5 * change


class Bouncing(PinocchioJointMotion):
    """Pinocchio's arm with a contact that bounces: it chatters on the plane and never comes to rest."""

    def __init__(self, scene, integrator, dt):
        super().__init__(scene, integrator, dt)
        self._contact = BouncingContact(self._model, scene.chain, scene.contact)


class PybulletCopy(PybulletJointMotion):
    pass


class DefaultFriction(PybulletJointMotion):
    """PyBullet's spheres left with Bullet's default lateral friction (0.5): the plane holds them sideways."""

    def __init__(self, scene, integrator, dt):
        super().__init__(scene, dt)
        for world, contact in ((self._world, self._contact), (self._probe, self._probe_contact)):
            for body in world.bodies:
                for link in set(contact.links):
                    pybullet.changeDynamics(body, link, lateralFriction=0.5, physicsClientId=world.client)


class DoubleFriction(PybulletJointMotion):
    """PyBullet's spheres given twice the scene's friction (the plane's own 1 replaced by 2: Bullet multiplies)."""

    def __init__(self, scene, integrator, dt):
        super().__init__(scene, dt)
        for world, contact in ((self._world, self._contact), (self._probe, self._probe_contact)):
            pybullet.changeDynamics(contact.plane, -1, lateralFriction=2.0, physicsClientId=world.client)


class BoxFriction(PybulletJointMotion):
    """PyBullet with its cone friction off (enableConeFriction 0): each friction row clamped alone, a box."""

    def __init__(self, scene, integrator, dt):
        super().__init__(scene, dt)
        for world in (self._world, self._probe):
            pybullet.setPhysicsEngineParameter(enableConeFriction=0, physicsClientId=world.client)


class PushingForces(ChainContactForces):
    """Core's penalty forces with the friction turned along the slip: restitution on the tangential velocity."""

    def _state(self, q, qdot):
        forces, arms, columns, rotation = super()._state(q, qdot)
        normal = self._contact.plane.normal_world
        along = (forces @ normal)[..., None] * normal
        return along - (forces - along), arms, columns, rotation


class PushingFriction(CoreJointMotion):
    """Core stepping and reporting :class:`PushingForces`."""

    def __init__(self, scene, scheme, dt):
        original, stepping.ChainContactForces = stepping.ChainContactForces, PushingForces
        try:
            super().__init__(scene, scheme, dt)
        finally:
            stepping.ChainContactForces = original
        self._contact = PushingForces(scene.chain, scene.contact)


class UnappliedFriction(CoreJointMotion):
    """Core stepping on a frictionless plane while reporting the scene's Coulomb friction at each sampled state."""

    def __init__(self, scene, scheme, dt):
        super().__init__(replace(scene, contact=replace(scene.contact, friction=0.0)), scheme, dt)
        self._contact = ChainContactForces(scene.chain, scene.contact)


class NoFriction(MujocoJointMotion):
    """MuJoCo's contact built without the scene's friction (condim 1 on every geom): the feet slide freely."""

    def __init__(self, scene, integrator, dt):
        super().__init__(scene, integrator, dt)
        self.model.geom_condim[:] = 1


class Pyramid(MujocoJointMotion):
    """MuJoCo left with its default pyramidal cone: a friction pyramid inside the Coulomb cone, direction-dependent."""

    def __init__(self, scene, integrator, dt):
        super().__init__(scene, integrator, dt)
        self.model.opt.cone = mujoco.mjtCone.mjCONE_PYRAMIDAL


class WrongSideFriction(MujocoJointMotion):
    """MuJoCo's friction reported as the force on the plane (its tangential part's sign flipped), the normal right."""

    def __init__(self, scene, integrator, dt):
        super().__init__(scene, integrator, dt)
        self._normal = np.asarray(scene.contact.plane.normal_world)

    def contact_forces(self, q, qdot, times):
        forces = super().contact_forces(q, qdot, times)
        along = (forces @ self._normal)[..., None] * self._normal
        return along - (forces - along)


class CoreCopy(CoreJointMotion):
    pass


class LateImpulses(RigidContact):
    """Impulses without time backed up: applied at the end of the step in which a sphere crossed the plane."""

    def _backed_up(self, t, q, qdot, h, candidates):
        s, sphere = super()._backed_up(t, q, qdot, h, candidates)
        return (1.0 if s > 0 else s), sphere


class NoBackup(CoreJointMotion):
    """Core's rigid contact with its impacts left where the step found them (the lecture's back-up missing)."""

    def __init__(self, scene, integrator, dt):
        super().__init__(scene, integrator, dt)
        self._rigid = LateImpulses(scene, integrator)


FaithfulEngine = _engine(MujocoEngine, Faithful, "mujoco-copy")
CoreCopyEngine = _engine(InHouseEngine, CoreCopy, "core-copy")
NoBackupEngine = _engine(InHouseEngine, NoBackup, "core-no-backup")
PybulletCopyEngine = _engine(PybulletEngine, lambda scene, integrator, dt: PybulletCopy(scene, dt), "pybullet-copy")
DefaultFrictionEngine = _engine(PybulletEngine, DefaultFriction, "pybullet-default-friction")
DoubleFrictionEngine = _engine(PybulletEngine, DoubleFriction, "pybullet-double-friction")
BoxFrictionEngine = _engine(PybulletEngine, BoxFriction, "pybullet-box-friction")
PushingFrictionEngine = _engine(InHouseEngine, PushingFriction, "core-pushing-friction")
UnappliedFrictionEngine = _engine(InHouseEngine, UnappliedFriction, "core-unapplied-friction")
NoFrictionEngine = _engine(MujocoEngine, NoFriction, "mujoco-no-friction")
PyramidEngine = _engine(MujocoEngine, Pyramid, "mujoco-pyramid")
WrongSideFrictionEngine = _engine(MujocoEngine, WrongSideFriction, "mujoco-wrong-side-friction")
BouncingEngine = _engine(PinocchioEngine, Bouncing, "pinocchio-bouncing")
PinocchioCopyEngine = _engine(PinocchioEngine, PinocchioCopy, "pinocchio-copy")
ImpulsesAsForcesEngine = _engine(PinocchioEngine, ImpulsesAsForces, "pinocchio-impulses-as-forces")
PullingEngine = _engine(InHouseEngine, Pulling, "core-pulling")
FlippedForcesEngine = _engine(MujocoEngine, FlippedForces, "mujoco-flipped-forces")
FatSpheresEngine = _engine(MujocoEngine, FatSpheres, "mujoco-fat-spheres")
LostSphereEngine = _engine(MujocoEngine, LostSphere, "mujoco-lost-sphere")
ComCentresEngine = _engine(MujocoEngine, ComCentres, "mujoco-com-centres")
WithoutTorqueEngine = _engine(MujocoEngine, WithoutTorque, "mujoco-without-torque")
'''


def _run(tmp_path, monkeypatch, capsys, plugin: str, scene: str = "solo12-drop-stand") -> tuple[int, list[str], str]:
    return run_planted(tmp_path, monkeypatch, capsys, "planted_contact", PLANTED, scene, plugin, engines="mujoco")


@pytest.mark.sweep
@pytest.mark.slow
@pytest.mark.parametrize("plugin, name, metric, scene", [
    ("PullingEngine", "core-pulling", "contact_penetration_max", "solo12-drop-stand"),
    ("FlippedForcesEngine", "mujoco-flipped-forces", "signorini_violation_max", "solo12-drop-stand"),
    ("FatSpheresEngine", "mujoco-fat-spheres", "signorini_violation_max", "solo12-drop-stand"),
    ("LostSphereEngine", "mujoco-lost-sphere", "rest_weight_error", "solo12-drop-stand"),
    ("ComCentresEngine", "mujoco-com-centres", "contact_centre_error", "pendulum-press"),
    ("WithoutTorqueEngine", "mujoco-without-torque", "rest_equilibrium_error", "pendulum-press"),
    ("ImpulsesAsForcesEngine", "pinocchio-impulses-as-forces", "rest_weight_error", "solo12-drop-stand"),
    ("BouncingEngine", "pinocchio-bouncing", "rest_acceleration_max", "arm-strike-press"),
    ("DefaultFrictionEngine", "pybullet-default-friction", "friction_cone_violation_max", "arm-strike-press"),
    ("DoubleFrictionEngine", "pybullet-double-friction", "friction_cone_violation_max", "solo12-incline-slide"),
    ("BoxFrictionEngine", "pybullet-box-friction", "sliding_friction_error", "solo12-incline-slide"),
    ("PushingFrictionEngine", "core-pushing-friction", "sliding_friction_angle_max", "solo12-incline-slide"),
    ("NoFrictionEngine", "mujoco-no-friction", "sliding_friction_error", "solo12-incline-slide"),
    ("UnappliedFrictionEngine", "core-unapplied-friction", "friction_impulse_error", "solo12-incline-slide"),
    ("NoFrictionEngine", "mujoco-no-friction", "rest_weight_error", "solo12-incline-stand"),  # it slides: not-at-rest
    ("PyramidEngine", "mujoco-pyramid", "sliding_friction_error", "solo12-incline-slide"),
    ("WrongSideFrictionEngine", "mujoco-wrong-side-friction", "sliding_friction_angle_max", "solo12-incline-slide"),
    # (not on pendulum-strike: a plastic strike ends at rest on the plane, where a late impulse is put back at every
    # sample, so the missing back-up is not observable there)
    ("NoBackupEngine", "core-no-backup", "joint_angle_error_max", "pendulum-bounce"),
])
def test_a_planted_contact_bug_is_caught_naming_the_engine(tmp_path, monkeypatch, capsys, plugin, name, metric,
                                                           scene):
    assert_caught(_run(tmp_path, monkeypatch, capsys, plugin, scene), name, metric)


@pytest.mark.sweep
@pytest.mark.slow
@pytest.mark.parametrize("scene, plugin", [
    *((s, p) for s in ("solo12-drop-stand", "pendulum-press", "arm-strike-press")
      for p in ("FaithfulEngine", "PinocchioCopyEngine")),
    *((s, p) for s in ("solo12-incline-stand", "solo12-incline-slide")
      for p in ("FaithfulEngine", "PinocchioCopyEngine", "PybulletCopyEngine")),
    *(("pendulum-press", "PybulletCopyEngine"), ("arm-strike-press", "PybulletCopyEngine"),
      ("solo12-drop-stand", "PybulletCopyEngine")),
    *(("pendulum-bounce", "CoreCopyEngine"), ("pendulum-strike", "CoreCopyEngine"),
      ("pendulum-strike", "PinocchioCopyEngine"), ("pendulum-strike", "PybulletCopyEngine"))])
def test_a_faithful_copy_of_the_adapter_passes(tmp_path, monkeypatch, capsys, scene, plugin):
    code, violations, out = _run(tmp_path, monkeypatch, capsys, plugin, scene)
    assert code == 0 and not violations, out[-2000:]
