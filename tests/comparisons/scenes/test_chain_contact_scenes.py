"""A joint-motion scene's contact (``[[plane]]``, ``[contact]``, ``[[contact.sphere]]``, issue #46): read as written,
every meaningless input refused in one line naming its key, and the engines (or integrators) that do not model a
chain's contact n/a with their reason."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
import pytest

from simparity.comparisons.scenes.library import resolve
from simparity.comparisons.scenes.loading.scene_file import parse_scene
from simparity.core.model.errors import SceneError
from simparity.core.model.scenes.joint_motion import JointMotionScene
from simparity.references.pinocchio.adapter import PinocchioEngine
from simparity.references.pybullet.adapter import PybulletEngine


@pytest.fixture(scope="module")
def data() -> dict:
    return tomllib.loads(Path(resolve("solo12-drop-stand")).read_text(encoding="utf-8"))


def _edited(data: dict, edit) -> dict:
    out = copy.deepcopy(data)
    edit(out)
    return out


def test_the_scene_reads_as_written(data):
    scene = parse_scene(data)
    contact = scene.contact
    assert isinstance(scene, JointMotionScene) and contact is not None
    assert [s.frame for s in contact.spheres] == ["FL_FOOT", "base_link", "base_link", "base_link"]
    np.testing.assert_array_equal(contact.spheres[1].centre_xyz, [0.1946, -0.14695, -0.32])
    assert contact.radii.tolist() == [0.02] * 4
    np.testing.assert_array_equal(contact.plane.normal_world, [0.0, 0.0, 1.0])
    assert contact.penalty_stiffness == 1e4
    mass = scene.chain.base_inertia.mass + sum(j.link.mass for j in scene.chain.joints)
    assert contact.penalty_damping == pytest.approx(2 * np.sqrt(1e4 * mass), rel=1e-15)  # critical on the mass


@pytest.mark.parametrize("edit, key, words", [
    (lambda d: d["plane"].append({"coefficients": [1.0, 0.0, 0.0, 5.0]}), "plane", "one [[plane]]"),
    (lambda d: d["contact"].update(sphere=[]), "contact.sphere", "one or more tables"),
    (lambda d: d["contact"]["sphere"][0].update(frame="FR_FOOT"), "contact.sphere[0].frame", "FL_FOOT"),
    (lambda d: d["contact"]["sphere"][0].update(radius=0.0), "contact.sphere[0].radius", "> 0"),
    (lambda d: d["contact"]["sphere"][1].update(centre_xyz=[0.0, 0.0]), "contact.sphere[1].centre_xyz", "3 numbers"),
    (lambda d: d["contact"].update(penalty_stiffness=-1.0), "contact.penalty_stiffness", "> 0"),
    (lambda d: d["contact"].update(penalty_damping=-1.0), "contact.penalty_damping", ">= 0"),
    (lambda d: d["contact"].update(friction=-0.5), "contact.friction", ">= 0"),
    (lambda d: d["contact"].update(friction=500.0), "contact.friction", "physical range"),
    (lambda d: d["contact"].update(friction="0.5"), "contact.friction", "a number"),
    (lambda d: d["contact"].update(friction=0.5, friction_speed=0.0), "contact.friction_speed", "> 0"),
    (lambda d: d["contact"].update(stands="yes"), "contact.stands", "true or false"),
    (lambda d: d["contact"].update(friction_speed=0.05), "contact.friction_speed", "friction > 0"),
    (lambda d: d["initial"].update(base_position=[0.0, 0.0, 0.33]), "contact.sphere[0]", "inside the plane"),
    (lambda d: d.pop("plane"), "contact", "without a [[plane]]"),
    (lambda d: d["plane"][0].update(coefficients=[0.0, 0.0, 0.0, 1.0]), "plane[0].coefficients", "all zeros"),
    (lambda d: d["simulation"].update(perturbation=1e-6), "simulation.perturbation", "allowed: 0"),
    (lambda d: d["contact"].update(rest_after=0.5), "contact.rest_after", "before the end of the run"),
    (lambda d: d["contact"].update(rest_after=-0.1), "contact.rest_after", "> 0"),
])
def test_a_meaningless_contact_is_refused_in_one_line_naming_its_key(data, edit, key, words):
    with pytest.raises(SceneError) as caught:
        parse_scene(_edited(data, edit), "drop.toml")
    message = str(caught.value)
    assert key in message and words in message and "\n" not in message, message


@pytest.mark.parametrize("engine, integrator", [(PinocchioEngine(), "rk4"), (PinocchioEngine(), "dop853")])
def test_engines_without_a_chain_s_contact_say_why(data, engine, integrator):
    """Pinocchio's contact is velocity-level: only its semi-implicit Euler steps it."""
    scene = parse_scene(data)
    support = engine.supports_joint_motion(scene, integrator)
    assert not support.ok and support.reason


def test_pinocchio_steps_contact_with_semi_implicit_euler_only(data):
    scene = parse_scene(data)
    assert PinocchioEngine().supports_joint_motion(scene, "semi_implicit_euler").ok
    assert "semi_implicit_euler" in PinocchioEngine().supports_joint_motion(scene, "rk4").reason


@pytest.fixture(scope="module")
def rigid() -> dict:
    return tomllib.loads(Path(resolve("pendulum-bounce")).read_text(encoding="utf-8"))


def test_a_rigid_contact_reads_as_written(rigid):
    contact = parse_scene(rigid).contact
    assert contact.rigid and contact.restitution == 0.5 and contact.rest_speed == 0.01
    assert contact.penalty_stiffness is None and contact.penalty_damping is None
    del rigid["contact"]["rest_speed"]
    assert parse_scene(rigid).contact.rest_speed == 1e-3  # the default, as the free bodies'


@pytest.mark.parametrize("edit, key, words", [
    (lambda d: d["contact"].update(restitution=1.5), "contact.restitution", "outside [0, 1]"),
    (lambda d: d["contact"].update(restitution=-0.1), "contact.restitution", "outside [0, 1]"),
    (lambda d: d["contact"].update(restitution="0.5"), "contact.restitution", "a number"),
    (lambda d: d["contact"].update(rest_speed=0.0), "contact.rest_speed", "> 0"),
    (lambda d: d["contact"].update(penalty_stiffness=1e4), "contact.penalty_stiffness", "not both"),
    (lambda d: d["contact"].update(penalty_damping=10.0), "contact.penalty_damping", "not both"),
    (lambda d: d["contact"].update(friction=0.5), "contact.friction", "a rigid contact's impacts are frictionless"),
    (lambda d: d["contact"].update(friction_speed=0.1), "contact.friction_speed", "on a soft contact"),
])
def test_a_meaningless_rigid_contact_is_refused_in_one_line_naming_its_key(rigid, edit, key, words):
    with pytest.raises(SceneError) as caught:
        parse_scene(_edited(rigid, edit), "bounce.toml")
    message = str(caught.value)
    assert key in message and words in message and "\n" not in message, message


def test_friction_reads_as_written_and_defaults_to_a_frictionless_plane(data, rigid):
    assert parse_scene(data).contact.friction == 0.0 and parse_scene(data).contact.friction_speed == 1e-2
    edited = parse_scene(_edited(data, lambda d: d["contact"].update(friction=0.6, friction_speed=0.05))).contact
    assert (edited.friction, edited.friction_speed) == (0.6, 0.05)
    assert parse_scene(_edited(rigid, lambda d: d["contact"].update(friction=0.0))).contact.friction == 0.0
    assert str(parse_scene(_edited(data, lambda d: d["contact"].update(friction=-0.0))).contact.friction) == "0.0"
    assert not parse_scene(data).contact.stands
    assert parse_scene(_edited(data, lambda d: d["contact"].update(stands=True))).contact.stands


def test_a_rest_speed_on_a_soft_contact_is_refused(data):
    with pytest.raises(SceneError, match="contact.rest_speed: a rest speed on a soft contact"):
        parse_scene(_edited(data, lambda d: d["contact"].update(rest_speed=0.01)), "drop.toml")


@pytest.mark.parametrize("restitution, plastic_engines", [(0.5, False), (0.0, True)])
def test_a_rigid_contact_runs_where_an_engine_has_it(rigid, restitution, plastic_engines):
    """MuJoCo's contact is soft: never; Pinocchio's loop and PyBullet's step are plastic: restitution 0 only."""
    from simparity.references.mujoco.adapter import MujocoEngine

    scene = parse_scene(_edited(rigid, lambda d: d["contact"].update(restitution=restitution)))
    mujoco = MujocoEngine().supports_joint_motion(scene, "rk4")
    assert not mujoco.ok and "soft" in mujoco.reason
    for engine, integrator in ((PinocchioEngine(), "semi_implicit_euler"), (PybulletEngine(), "euler")):
        support = engine.supports_joint_motion(scene, integrator)
        assert support.ok == plastic_engines, support.reason
        assert support.ok or "restitution 0.5" in support.reason


def test_core_as_the_reference_of_a_floating_rigid_contact_is_refused_in_one_line():
    """Core steps impulses on a fixed base only: a floating base's rigid contact named core its reference and passed
    with "core measured nothing" (a held-out trial); it is refused at load, saying why."""
    with open(resolve("solo12-drop-stand"), "rb") as f:
        data = tomllib.load(f)
    data["contact"] = {k: v for k, v in data["contact"].items() if not k.startswith("penalty_")} | {"restitution": 0.0}
    with pytest.raises(SceneError) as caught:
        parse_scene(data, "drop.toml")
    message = str(caught.value)
    assert "scene.reference" in message and "fixed base only" in message and "\n" not in message, message


def test_stands_on_a_fixed_base_is_refused_in_one_line():
    data = tomllib.loads(Path(resolve("pendulum-press")).read_text(encoding="utf-8"))
    with pytest.raises(SceneError) as caught:
        parse_scene(_edited(data, lambda d: d["contact"].update(stands=True)), "press.toml")
    message = str(caught.value)
    assert "contact.stands" in message and "floating base" in message and "\n" not in message, message
