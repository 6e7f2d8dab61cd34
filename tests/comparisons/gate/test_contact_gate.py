"""Issue #46's planted contact bugs through the gate: a user's engine that is core or MuJoCo's adapter with one planted
bug (the plane's normal turned, so that it pulls; the contact forces reported with their sign flipped; MuJoCo's spheres
twice as large, so that they touch early; one sphere's force left out of what is reported) turns the check of
``solo12-drop-stand`` red naming it and the metric that sees it; a faithful copy passes. A sweep (a run of the scene
per bug), in ``.ci/run``."""

from __future__ import annotations

import pytest

from tests.helpers import PLANTED_MOTION_FACTORY, assert_caught, run_planted

PLANTED = PLANTED_MOTION_FACTORY + '''
from dataclasses import replace

from simparity.core.articulated.motion import CoreJointMotion
from simparity.core.inhouse import InHouseEngine
from simparity.core.model.scenes.contact import Plane
from simparity.references.mujoco.adapter import MujocoEngine
from simparity.references.mujoco.joint_motion import MujocoJointMotion


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

    def contact_forces(self, q, qdot):
        return -super().contact_forces(q, qdot)


class FatSpheres(MujocoJointMotion):
    """MuJoCo given spheres of twice the scene's radius: contact before the feet touch."""

    def __init__(self, scene, integrator, dt):
        fat = tuple(replace(s, radius=2 * s.radius) for s in scene.contact.spheres)
        super().__init__(replace(scene, contact=replace(scene.contact, spheres=fat)), integrator, dt)


class LostSphere(MujocoJointMotion):
    """One sphere's force left out of what is reported."""

    def contact_forces(self, q, qdot):
        forces = super().contact_forces(q, qdot)
        forces[:, 0] = 0.0
        return forces


FaithfulEngine = _engine(MujocoEngine, Faithful, "mujoco-copy")
PullingEngine = _engine(InHouseEngine, Pulling, "core-pulling")
FlippedForcesEngine = _engine(MujocoEngine, FlippedForces, "mujoco-flipped-forces")
FatSpheresEngine = _engine(MujocoEngine, FatSpheres, "mujoco-fat-spheres")
LostSphereEngine = _engine(MujocoEngine, LostSphere, "mujoco-lost-sphere")
'''


def _run(tmp_path, monkeypatch, capsys, plugin: str) -> tuple[int, list[str], str]:
    return run_planted(tmp_path, monkeypatch, capsys, "planted_contact", PLANTED, "solo12-drop-stand", plugin,
                       engines="mujoco")


@pytest.mark.sweep
@pytest.mark.slow
@pytest.mark.parametrize("plugin, name, metric", [
    ("PullingEngine", "core-pulling", "contact_penetration_max"),
    ("FlippedForcesEngine", "mujoco-flipped-forces", "signorini_violation_max"),
    ("FatSpheresEngine", "mujoco-fat-spheres", "signorini_violation_max"),
    ("LostSphereEngine", "mujoco-lost-sphere", "rest_weight_error"),
])
def test_a_planted_contact_bug_is_caught_naming_the_engine(tmp_path, monkeypatch, capsys, plugin, name, metric):
    assert_caught(_run(tmp_path, monkeypatch, capsys, plugin), name, metric)


@pytest.mark.sweep
@pytest.mark.slow
def test_a_faithful_copy_of_the_adapter_passes(tmp_path, monkeypatch, capsys):
    code, violations, out = _run(tmp_path, monkeypatch, capsys, "FaithfulEngine")
    assert code == 0 and not violations, out[-2000:]
