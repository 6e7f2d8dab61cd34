"""Scene files: every built-in scene loads; every kind of bad input is rejected with file, key and reason."""

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from simparity.comparisons.scenes.library import builtin_paths
from simparity.comparisons.scenes.describe import describe
from simparity.comparisons.scenes.loading.scene_file import (
    LENGTH_UNITS, load_scene, load_scenes, parse_scene, parse_scenes,
)
from simparity.core.model.files import tomllib
from simparity.core.model.errors import SceneError

VALID_DYNAMICS = """
[scene]
name = "drop"
kind = "dynamics"
reference = "analytic"

[world]
gravity_world = [0.0, 0.0, -9.81]

[[body]]
name = "ball"
mass = 1.5
inertia_body_diagonal = [0.1, 0.1, 0.1]
velocity_world = [1.0, 0.0, 0.0]

[simulation]
duration = 1.0
dt = [0.01]
"""

VALID_KINEMATICS = """
[scene]
name = "arm"
kind = "kinematics"
reference = "core"

[chain]
[[chain.joint]]
name = "j1"
type = "revolute"
axis = [0.0, 0.0, 1.0]
lower = -1.0
upper = 1.0
"""

# (name, base text, old fragment, new fragment, key named in the error, words in the error)
BROKEN = [
    ("unknown key", VALID_DYNAMICS, 'name = "ball"', 'name = "ball"\ncolour = "red"', "body[0].colour", "unknown key"),
    ("unknown table", VALID_DYNAMICS, "[world]", "[weather]\n[world]", "weather", "unknown key"),
    ("short vector", VALID_DYNAMICS, "velocity_world = [1.0, 0.0, 0.0]", "velocity_world = [1.0, 0.0]",
     "body[0].velocity_world", "expected a list of 3 numbers, got 2 values"),
    ("nan mass", VALID_DYNAMICS, "mass = 1.5", "mass = nan", "body[0].mass", "not finite"),
    ("inf gravity", VALID_DYNAMICS, "[0.0, 0.0, -9.81]", "[0.0, inf, -9.81]", "world.gravity_world[1]", "not finite"),
    ("zero mass", VALID_DYNAMICS, "mass = 1.5", "mass = 0", "body[0].mass", "is not positive"),
    ("negative mass", VALID_DYNAMICS, "mass = 1.5", "mass = -2.0", "body[0].mass", "is not positive"),
    ("text mass", VALID_DYNAMICS, "mass = 1.5", 'mass = "heavy"', "body[0].mass", "expected a number"),
    ("zero quaternion", VALID_DYNAMICS, 'name = "ball"', 'name = "ball"\nquat_wxyz = [0, 0, 0, 0]',
     "body[0].quat_wxyz", "all zeros"),
    ("missing mass", VALID_DYNAMICS, "mass = 1.5\n", "", "body[0].mass", "missing required key"),
    ("missing simulation", VALID_DYNAMICS, "[simulation]\nduration = 1.0\ndt = [0.01]\n", "", "simulation",
     "missing required table"),
    ("bad kind", VALID_DYNAMICS, 'kind = "dynamics"', 'kind = "fluid"', "scene.kind", "allowed: dynamics, kinematics"),
    ("bad reference", VALID_DYNAMICS, 'reference = "analytic"', 'reference = "havok"', "scene.reference",
     "allowed: core, analytic, mujoco, pybullet, pinocchio, tight"),
    ("bad unit", VALID_DYNAMICS, 'reference = "analytic"', 'reference = "analytic"\nlength_unit = "furlong"',
     "scene.length_unit", "allowed: m, cm, mm, ft, in"),
    ("dt not dividing", VALID_DYNAMICS, "dt = [0.01]", "dt = [0.3]", "simulation.dt[0]", "not a whole number of steps"),
    ("dt and rate", VALID_DYNAMICS, "dt = [0.01]", "dt = [0.01]\nrate_hz = [100]", "simulation.dt", "exactly one"),
    ("negative dt", VALID_DYNAMICS, "dt = [0.01]", "dt = [-0.01]", "simulation.dt[0]", "is not positive"),
    ("non-positive inertia", VALID_DYNAMICS, "[0.1, 0.1, 0.1]", "[0.1, -0.1, 0.1]",
     "body[0].inertia_body_diagonal[1]", "is not positive"),
    ("triangle inequality", VALID_DYNAMICS, "[0.1, 0.1, 0.1]", "[0.1, 0.1, 0.3]", "body[0].inertia_body_diagonal",
     "triangle inequality"),
    ("non-symmetric inertia", VALID_DYNAMICS, "inertia_body_diagonal = [0.1, 0.1, 0.1]",
     "inertia_body = [[0.1, 0.01, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]]", "body[0].inertia_body", "symmetric"),
    ("indefinite inertia", VALID_DYNAMICS, "inertia_body_diagonal = [0.1, 0.1, 0.1]",
     "inertia_body = [[0.1, 0.2, 0.0], [0.2, 0.1, 0.0], [0.0, 0.0, 0.1]]", "body[0].inertia_body",
     "positive definite"),
    ("two inertias", VALID_DYNAMICS, "inertia_body_diagonal = [0.1, 0.1, 0.1]",
     "inertia_body_diagonal = [0.1, 0.1, 0.1]\ninertia_body = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]",
     "body[0].inertia_body_diagonal", "exactly one"),
    ("negative drag", VALID_DYNAMICS, "mass = 1.5", "mass = 1.5\nlinear_drag = -0.1", "body[0].linear_drag",
     "is negative"),
    ("wind without drag", VALID_DYNAMICS, "[world]", "[world]\nair_velocity_world = [1.0, 0.0, 0.0]",
     "world.air_velocity_world", "wind needs a body with linear_drag or quadratic_drag"),
    ("force without vector", VALID_DYNAMICS, "velocity_world = [1.0, 0.0, 0.0]",
     "velocity_world = [1.0, 0.0, 0.0]\n[[body.force]]\npoint_body = [0, 0, 0]",
     "body[0].force[0].force_world", "missing required key"),
    ("unknown force key", VALID_DYNAMICS, "velocity_world = [1.0, 0.0, 0.0]",
     "velocity_world = [1.0, 0.0, 0.0]\n[[body.force]]\nforce_world = [0, 0, 1]\ntorque = 1",
     "body[0].force[0].torque", "unknown key"),
    ("unknown integrator list", VALID_DYNAMICS, "dt = [0.01]", "dt = [0.01]\nintegrators = []",
     "simulation.integrators", "non-empty list"),
    ("unknown integrator", VALID_DYNAMICS, "dt = [0.01]", 'dt = [0.01]\nintegrators = ["rk4", "rk5"]',
     "simulation.integrators[1]", "no engine has an integrator 'rk5'"),
    ("overflowing number", VALID_DYNAMICS, "mass = 1.5", "mass = 1" + "0" * 400, "body[0].mass", "is not finite"),
    ("chain in dynamics", VALID_DYNAMICS, "[world]", "[chain]\n[world]", "chain", "not part of a dynamics scene"),
    ("bad joint type", VALID_KINEMATICS, 'type = "revolute"', 'type = "spherical"', "chain.joint[0].type",
     "allowed: revolute, prismatic"),
    ("lower without upper", VALID_KINEMATICS, "upper = 1.0\n", "", "chain.joint[0].upper", "need both"),
    ("inverted limits", VALID_KINEMATICS, "upper = 1.0", "upper = -2.0", "chain.joint[0].upper", "is below lower"),
    ("zero axis", VALID_KINEMATICS, "axis = [0.0, 0.0, 1.0]", "axis = [0.0, 0.0, 0.0]", "chain.joint[0].axis",
     "all zeros"),
    ("no joints", VALID_KINEMATICS, '[[chain.joint]]\nname = "j1"\ntype = "revolute"\naxis = [0.0, 0.0, 1.0]\n'
     "lower = -1.0\nupper = 1.0\n", "", "chain.joint", "exactly one chain source"),
    ("two chain sources", VALID_KINEMATICS, "[chain]", '[chain]\nurdf = "robot.urdf"', "chain.joint",
     "exactly one chain source"),
    ("missing urdf", VALID_KINEMATICS, '[[chain.joint]]\nname = "j1"\ntype = "revolute"\naxis = [0.0, 0.0, 1.0]\n'
     "lower = -1.0\nupper = 1.0\n", 'urdf = "no-such.urdf"\n', "chain.urdf", "no such URDF file"),
    ("ik start outside limits", VALID_KINEMATICS.replace('kind = "kinematics"', 'kind = "ik"'), "[chain]",
     "[targets]\nstart = [2.0]\n[chain]", "targets.start", "outside its limits"),
    ("ik unknown hard target", VALID_KINEMATICS.replace('kind = "kinematics"', 'kind = "ik"'), "[chain]",
     '[targets]\nhard = ["inside_out"]\n[chain]', "targets.hard[0]", "unknown hard target"),
    ("zero configurations", VALID_KINEMATICS, "[chain]", "[sampling]\nconfigurations = 0\n[chain]",
     "sampling.configurations", "whole numbers 1 to"),
]


def _write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("name, base, old, new, key, words", BROKEN, ids=[b[0] for b in BROKEN])
def test_broken_scene_is_rejected_with_file_key_and_reason(tmp_path, name, base, old, new, key, words):
    """Each broken file raises SceneError naming the file, the key path and what was wrong."""
    assert old in base, f"test table out of date: {old!r}"
    path = _write(tmp_path, base.replace(old, new, 1))
    with pytest.raises(SceneError) as caught:
        load_scene(path)
    assert caught.value.source == str(path)
    assert caught.value.key == key
    assert words in str(caught.value)


def test_unreadable_and_invalid_toml_files(tmp_path):
    """A missing file, a file that is not TOML and one that is not UTF-8 are SceneErrors too."""
    (tmp_path / "latin1.toml").write_bytes("[scene]\nname = \"caf\xe9\"\n".encode("latin-1"))
    with pytest.raises(SceneError, match="not UTF-8"):
        load_scene(tmp_path / "latin1.toml")
    with pytest.raises(SceneError, match="no such scene file"):
        load_scene(tmp_path / "missing.toml")
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(_write(tmp_path, "[scene\nname = 1"))


def test_valid_scenes_load_with_defaults_and_units(tmp_path):
    """Defaults fill in (identity orientation, zero velocities, 100 configurations); lengths are scaled to metres."""
    scene = load_scene(_write(tmp_path, VALID_DYNAMICS))
    body = scene.bodies[0]
    assert scene.description == ""  # none given: nothing (a "-" rendered as a Markdown bullet in the report)
    np.testing.assert_array_equal(body.quat_wxyz, [1, 0, 0, 0])
    np.testing.assert_array_equal(body.angular_velocity_world, [0, 0, 0])
    assert scene.n_steps(scene.dts[0]) == 100
    feet = load_scene(_write(tmp_path, VALID_DYNAMICS.replace(
        'reference = "analytic"', 'reference = "analytic"\nlength_unit = "ft"'), "ft.toml"))
    np.testing.assert_allclose(feet.forces.gravity_world, [0, 0, -9.81 * LENGTH_UNITS["ft"]], rtol=1e-15)
    np.testing.assert_allclose(feet.bodies[0].inertia_body, 0.1 * LENGTH_UNITS["ft"] ** 2 * np.eye(3), rtol=1e-15)
    assert feet.bodies[0].mass == 1.5
    arm = load_scene(_write(tmp_path, VALID_KINEMATICS, "arm.toml"))
    assert arm.n_configurations == 100 and arm.chain.n_joints == 1
    assert arm.configurations().shape == (100, 1) and np.all(np.abs(arm.configurations()) <= 1.0)


def test_ik_lengths_follow_the_length_unit(tmp_path):
    """In a millimetre IK scene the position tolerance and prismatic start values are converted to metres."""
    text = VALID_KINEMATICS.replace('kind = "kinematics"', 'kind = "ik"\nlength_unit = "mm"').replace(
        "[chain]", "[targets]\nposition_tolerance = 0.01\nstart = [0.0, 250.0]\n[chain]") + (
        '\n[[chain.joint]]\nname = "slide"\ntype = "prismatic"\naxis = [1.0, 0.0, 0.0]\nlower = 0.0\nupper = 500.0\n')
    scene = load_scene(_write(tmp_path, text))
    assert scene.position_tolerance == pytest.approx(1e-5)
    np.testing.assert_allclose(scene.q_start, [0.0, 0.25])
    assert scene.chain.upper[1] == pytest.approx(0.5)


def test_forces_load_per_body_with_units(tmp_path):
    """Drag and applied forces become per-body arrays; bodies without a drag get 0; lengths scale."""
    text = VALID_DYNAMICS.replace('velocity_world = [1.0, 0.0, 0.0]', 'velocity_world = [1.0, 0.0, 0.0]\n'
                                  'quadratic_drag = 0.2\n[[body.force]]\n'
                                  'force_world = [0.0, 0.0, 1.0]\npoint_body = [1.0, 0.0, 0.0]') + (
        '\n[[body]]\nname = "other"\nmass = 1.0\ninertia_body_diagonal = [1.0, 1.0, 1.0]\n')
    text = text.replace('reference = "analytic"', 'reference = "tight"\nlength_unit = "cm"')  # no closed form
    scene = load_scene(_write(tmp_path, text))
    np.testing.assert_allclose(scene.forces.quadratic_drag, [0.2 / 0.01, 0.0])  # kg/m: per length
    assert scene.forces.linear_drag is None
    (applied,) = scene.forces.applied
    assert applied.body == 0
    np.testing.assert_allclose(applied.point_body, [0.01, 0, 0])
    np.testing.assert_allclose(applied.force_world, [0, 0, 0.01])  # N = kg m/s^2: per length


def test_absent_forces_stay_absent():
    """A scene without [world] has no gravity at all (None), not zero gravity."""
    scene = parse_scene(tomllib.loads(VALID_DYNAMICS.replace("[world]\ngravity_world = [0.0, 0.0, -9.81]\n", "")))
    assert scene.forces.gravity_world is None
    assert scene.forces.names() == ()


@pytest.mark.parametrize("name", sorted(builtin_paths()))
def test_every_builtin_scene_loads(name):
    """The built-in library is valid: every file loads and names itself after its file (a sweep: its base)."""
    scenes = load_scenes(builtin_paths()[name])
    assert [s.sweep.base if s.sweep else s.name for s in scenes] == [name] * len(scenes)


HAND_EXACT = 1e-15
"""[m, kg m^2] Values worked out by hand from numbers with few digits: the loader's arithmetic rounds them at
~1e-16 relative on entries of order 1."""


VALID_CONTACT = """
[scene]
name = "bounce"
kind = "dynamics"
reference = "core"

[world]
gravity_world = [0.0, 0.0, -9.81]

[[plane]]
name = "floor"
coefficients = [0.0, 0.0, 2.0, 1.0]

[[plane]]
name = "wall"
coefficients = [-3.0, 4.0, 0.0, 10.0]

[contact]
methods = ["backup", "penalty"]
restitution = 0.8
friction_kinetic = 0.2
rest_speed = 0.01

[[contact.pair]]
body = "ball"
plane = "wall"
restitution = 0.3

[[body]]
name = "ball"
mass = 1.0
inertia_body_diagonal = [0.004, 0.004, 0.004]
position_world = [0.0, 0.0, 1.0]
shape = "sphere"
radius = 0.1

[[body]]
name = "tri"
position_world = [0.0, 0.0, 1.0]
friction_static = 0.6
friction_kinetic = 0.5

[[body.point_mass]]
mass = 1.0
position = [1.0, 0.0, 0.0]

[[body.point_mass]]
mass = 2.0
position = [0.0, 1.0, 0.0]

[[body.point_mass]]
mass = 1.0
position = [0.0, 0.0, 1.0]

[[body.point_mass]]
mass = 1.0
position = [0.0, 0.0, 0.0]

[simulation]
duration = 1.0
dt = [0.01]
"""


def test_contact_scene_loads_planes_materials_and_point_mass_bodies(tmp_path):
    """Planes are normalised; materials cascade scene -> body -> pair; a point-mass body's mass, COM and
    tensor are computed with the physical sign (checked against values worked out by hand)."""
    scene = load_scene(_write(tmp_path, VALID_CONTACT))
    floor, wall = scene.contact.planes
    np.testing.assert_array_equal(floor.normal_world, [0.0, 0.0, 1.0])
    assert floor.offset == 0.5  # 2 z + 1 = 0 is z = -0.5
    np.testing.assert_allclose(wall.normal_world, [-0.6, 0.8, 0.0], rtol=0, atol=HAND_EXACT)
    assert wall.offset == 2.0
    np.testing.assert_array_equal(scene.contact.restitution, [[0.8, 0.3], [0.8, 0.8]])
    np.testing.assert_array_equal(scene.contact.friction_kinetic, [[0.2, 0.2], [0.5, 0.5]])
    np.testing.assert_array_equal(scene.contact.friction_static, [[0.2, 0.2], [0.6, 0.6]])
    assert scene.contact.methods == ("backup", "penalty") and scene.contact.rest_speed == 0.01
    tri = scene.bodies[1]
    # By hand: M = 5; COM = (1, 2, 1) / 5; r_i = q_i - COM; I = sum m (|r|^2 E - r r^T), e.g.
    # I_xy = -sum m x y = -(0.8 (-0.4) + 2 (-0.2) 0.6 + (-0.2)(-0.4) + (-0.2)(-0.4)) = 0.4.
    assert tri.mass == 5.0
    np.testing.assert_allclose(tri.position_world, [0.2, 0.4, 1.2], rtol=0, atol=HAND_EXACT)
    hand = np.array([[2.0, 0.4, 0.2], [0.4, 1.6, 0.4], [0.2, 0.4, 2.0]])
    np.testing.assert_allclose(tri.inertia_body, hand, rtol=0, atol=HAND_EXACT)
    assert scene.contact.shapes[1].kind == "points"
    np.testing.assert_allclose(scene.contact.shapes[1].points_body[0], [0.8, -0.4, -0.2], rtol=0, atol=HAND_EXACT)
    assert scene.contact.shapes[0].kind == "sphere" and scene.contact.shapes[0].radius == 0.1


def test_scene_without_planes_has_no_contact():
    """No [[plane]]: contact is None, and engines are given none."""
    assert parse_scene(tomllib.loads(VALID_DYNAMICS)).contact is None


BROKEN_CONTACT = [
    ("restitution above 1", "restitution = 0.8", "restitution = 1.2", "contact.restitution", "outside [0, 1]"),
    ("negative friction", "friction_kinetic = 0.2", "friction_kinetic = -0.2", "contact.friction_kinetic",
     "negative"),
    ("kinetic above static", "friction_static = 0.6", "friction_static = 0.4", "body[1].friction_kinetic",
     "exceeds friction_static"),
    ("static below inherited kinetic", 'name = "ball"\nmass', 'name = "ball"\nfriction_static = 0.1\nmass',
     "body[0].friction_static", "below the friction_kinetic 0.2 this table inherits"),
    ("zero normal", "coefficients = [0.0, 0.0, 2.0, 1.0]", "coefficients = [0.0, 0.0, 0.0, 1.0]",
     "plane[0].coefficients", "all zeros"),
    ("far plane", "coefficients = [0.0, 0.0, 2.0, 1.0]", "coefficients = [0.0, 0.0, 1e-300, 2.0]",
     "plane[0].coefficients", "the plane lies 2e+300 m from the origin"),
    ("short plane", "coefficients = [0.0, 0.0, 2.0, 1.0]", "coefficients = [0.0, 0.0, 2.0]",
     "plane[0].coefficients", "expected a list of 4 numbers"),
    ("unknown method", 'methods = ["backup", "penalty"]', 'methods = ["teleport"]', "contact.methods[0]",
     "no contact method"),
    ("unknown shape", 'shape = "sphere"', 'shape = "cone"', "body[0].shape", "not allowed"),
    ("radius on a box", 'shape = "sphere"', 'shape = "box"\nhalf_extents = [0.1, 0.1, 0.1]', "body[0].radius",
     "given for a box shape"),
    ("sphere without radius", "radius = 0.1\n", "", "body[0].radius", "missing required key"),
    ("zero rest speed", "rest_speed = 0.01", "rest_speed = 0.0", "contact.rest_speed", "not positive"),
    ("pair with unknown plane", 'plane = "wall"', 'plane = "ceiling"', "contact.pair[0].plane", "not allowed"),
    ("starts inside", "position_world = [0.0, 0.0, 1.0]\nshape", "position_world = [0.0, 0.0, -0.55]\nshape",
     "body[0].position_world", "starts 0.15 m inside plane 'floor'"),
    ("mass with point masses", 'name = "tri"', 'name = "tri"\nmass = 3.0', "body[1].mass",
     "computed from the point masses"),
    ("coplanar point masses", "position = [0.0, 0.0, 1.0]", "position = [2.0, -1.0, 0.0]", "body[1].point_mass",
     "the points lie in one plane"),
    ("core reference without backup", 'methods = ["backup", "penalty"]', 'methods = ["act_after", "penalty"]',
     "scene.reference", "leave out backup"),
    ("points shape without masses", 'shape = "sphere"\nradius = 0.1', 'shape = "points"', "body[0].shape",
     "needs the body's [[body.point_mass]]"),
]


@pytest.mark.parametrize("name, old, new, key, words", BROKEN_CONTACT, ids=[b[0] for b in BROKEN_CONTACT])
def test_broken_contact_scene_is_rejected_with_key_and_reason(tmp_path, name, old, new, key, words):
    """Each meaningless contact value raises SceneError naming the file, the key path and what was wrong."""
    assert old in VALID_CONTACT, f"test table out of date: {old!r}"
    path = _write(tmp_path, VALID_CONTACT.replace(old, new, 1))
    with pytest.raises(SceneError) as caught:
        load_scene(path)
    assert caught.value.source == str(path)
    assert caught.value.key == key
    assert words in str(caught.value)


def test_contact_keys_without_a_plane_are_rejected(tmp_path):
    """A restitution with nothing to bounce on is a mistake, not a silent no-op."""
    text = VALID_DYNAMICS.replace('name = "ball"', 'name = "ball"\nrestitution = 0.5')
    with pytest.raises(SceneError) as caught:
        load_scene(_write(tmp_path, text))
    assert caught.value.key == "body[0].restitution" and "no [[plane]]" in str(caught.value)


# --- sweeps --------------------------------------------------------------------------------------------

SWEPT = VALID_DYNAMICS + """
[sweep]
"body[ball].velocity_world[0]" = [1.0, 2.0]
"simulation.dt" = {start = 0.01, stop = 0.04, num = 2}
"""

DOCS = Path(__file__).resolve().parents[3] / "docs" / "scenes.md"


def test_a_sweep_expands_into_variants_in_the_sweeps_order():
    scenes = parse_scenes(tomllib.loads(SWEPT), "swept.toml")
    assert [s.name for s in scenes] == ["drop_velocity_world.0-1.0_dt-0.01", "drop_velocity_world.0-1.0_dt-0.04",
                                        "drop_velocity_world.0-2.0_dt-0.01", "drop_velocity_world.0-2.0_dt-0.04"]
    assert [s.sweep.values for s in scenes] == [
        (("body[ball].velocity_world[0]", 1.0), ("simulation.dt", 0.01)),
        (("body[ball].velocity_world[0]", 1.0), ("simulation.dt", 0.04)),
        (("body[ball].velocity_world[0]", 2.0), ("simulation.dt", 0.01)),
        (("body[ball].velocity_world[0]", 2.0), ("simulation.dt", 0.04))]
    assert {(s.sweep.base, s.sweep.count) for s in scenes} == {("drop", 4)} and [s.sweep.index for s in scenes] == [0, 1, 2, 3]
    assert [s.dts for s in scenes] == [(0.01,), (0.04,), (0.01,), (0.04,)]
    assert [s.bodies[0].velocity_world[0] for s in scenes] == [1.0, 1.0, 2.0, 2.0]


def test_a_variant_is_the_scene_written_by_hand_with_its_values():
    """The variant loads exactly as the file with those values typed in (only its name and sweep differ)."""
    variant = parse_scenes(tomllib.loads(SWEPT))[3]
    by_hand = parse_scene(tomllib.loads(VALID_DYNAMICS.replace("velocity_world = [1.0, 0.0, 0.0]",
                                                               "velocity_world = [2.0, 0.0, 0.0]")
                                        .replace("dt = [0.01]", "dt = [0.04]")))
    assert describe(dataclasses.replace(variant, name="drop", sweep=None)) == describe(by_hand)
    assert parse_scenes(tomllib.loads(VALID_DYNAMICS))[0].sweep is None


def test_sweep_values_are_as_written_in_the_files_length_unit():
    text = VALID_DYNAMICS.replace('reference = "analytic"', 'reference = "analytic"\nlength_unit = "cm"').replace(
        'name = "ball"', 'name = "ball"\nposition_world = [0.0, 0.0, 50.0]') + '[sweep]\n"body[0].position_world[2]" = [50, 100]\n'
    scenes = parse_scenes(tomllib.loads(text))
    assert [s.sweep.values[0][1] for s in scenes] == [50.0, 100.0]
    assert [s.bodies[0].position_world[2] for s in scenes] == [pytest.approx(0.5, rel=HAND_EXACT),
                                                              pytest.approx(1.0, rel=HAND_EXACT)]


def test_ik_and_kinematics_scenes_sweep_their_seeds_and_chain():
    ik = VALID_KINEMATICS.replace('kind = "kinematics"', 'kind = "ik"').replace(
        "[chain]", "[targets]\ncount = 5\nseed = 0\n[chain]") + '[sweep]\n"targets.seed" = {start = 0, stop = 2, num = 3}\n'
    seeds = parse_scenes(tomllib.loads(ik))
    assert [s.seed for s in seeds] == [0, 1, 2] and all(type(s.sweep.values[0][1]) is int for s in seeds)
    assert not np.array_equal(seeds[0].configurations(), seeds[1].configurations())
    arm = VALID_KINEMATICS.replace('axis = [0.0, 0.0, 1.0]', 'axis = [0.0, 0.0, 1.0]\norigin_xyz = [0.5, 0.0, 0.0]') + (
        '[sweep]\n"chain.joint[j1].origin_xyz[0]" = [0.25, 0.75]\n"chain.joint[j1].upper" = [0.5]\n')
    arms = parse_scenes(tomllib.loads(arm))
    assert [s.chain.joints[0].origin_xyz[0] for s in arms] == [0.25, 0.75] and {s.chain.joints[0].upper for s in arms} == {0.5}
    assert {s.chain.name for s in arms} == {"arm"}   # the chain keeps the file's name


def test_a_file_with_a_sweep_is_not_one_scene(tmp_path):
    with pytest.raises(SceneError, match=r"sweep: the file sweeps keys: it is several scenes.*load_scenes"):
        load_scene(_write(tmp_path, SWEPT))
    assert len(load_scenes(_write(tmp_path, SWEPT))) == 4


@pytest.mark.parametrize("sweep, key, words", [
    ('"body[ball].velocity_world[0]" = [1.0, 1e7]', "sweep.body[ball].velocity_world[0]",
     "10000000.0 (variant 2 of 2): body[0].velocity_world[0]: 1e+07 is outside the physical range"),
    ('"body[ball].mass" = [1.0, -2.0]', "sweep.body[ball].mass", "-2.0 (variant 2 of 2): body[0].mass: -2.0 is not positive"),
    ('"simulation.dt" = [0.01, 0.3]', "sweep.simulation.dt", "0.3 (variant 2 of 2): simulation.dt[0]: duration 1 s is not"),
    ('"simulation.dt[0]" = [0.5]\n"simulation.duration" = [1.0, 1.25]', "sweep.simulation.dt[0]",   # the key named
     "0.5 (variant 2 of 2, with simulation.duration = 1.25): simulation.dt[0]: duration 1.25 s is not a whole number"),
    ('"body[ball].inertia_body_diagonal[2]" = [0.3]', "sweep.body[ball].inertia_body_diagonal[2]",
     "0.3 (variant 1 of 1): body[0].inertia_body_diagonal: inertia violates the triangle inequality"),
    ('"plane[floor].coefficients[3]" = [1.0, -1.0]\n"body[ball].mass" = [1.5]', "sweep",   # the plane moved onto the ball
     "variant 2 of 2 (plane[floor].coefficients[3] = -1.0, body[ball].mass = 1.5): body[0].position_world: body 'ball' "
     "starts 1 m inside plane 'floor'"),
])
def test_a_variant_the_loader_refuses_names_the_sweep_key_and_value(tmp_path, sweep, key, words):
    plane = '[[plane]]\nname = "floor"\ncoefficients = [0.0, 0.0, 1.0, 1.0]\n' if "plane" in sweep else ""
    path = _write(tmp_path, VALID_DYNAMICS + plane + "[sweep]\n" + sweep + "\n")
    with pytest.raises(SceneError) as caught:
        load_scenes(path)
    assert caught.value.source == str(path) and caught.value.key == key
    assert words in caught.value.problem and caught.value.allowed


def test_the_file_without_its_sweep_must_be_a_scene(tmp_path):
    """An error of the file itself names its own key, as in a file without a sweep."""
    path = _write(tmp_path, SWEPT.replace("mass = 1.5", "mass = -1.5"))
    with pytest.raises(SceneError) as caught:
        load_scenes(path)
    assert caught.value.key == "body[0].mass"


def _docs_section() -> str:
    return DOCS.read_text(encoding="utf-8").split("## Sweeps", 1)[1].split("\n## ", 1)[0]


def test_the_documented_sweep_expands_as_documented():
    """docs/scenes.md's example gives the variants its table lists, and its error is the one it prints."""
    text = re.search(r"```toml\n(.*?)```", _docs_section(), flags=re.S).group(1)
    scenes = parse_scenes(tomllib.loads(text), "bounce.toml")
    names = [s.name for s in scenes]
    assert len(names) == 8 and names[:3] + names[-1:] == [
        "bounce_restitution-0.3_velocity_world.0-0.0", "bounce_restitution-0.3_velocity_world.0-1.0",
        "bounce_restitution-0.5_velocity_world.0-0.0", "bounce_restitution-0.9_velocity_world.0-1.0"]
    for name in names[:3] + names[-1:]:
        assert f"| `{name}` |" in _docs_section()
    assert [s.contact.restitution[0, 0] for s in scenes[::2]] == [0.3, 0.5, 0.7, 0.9]
    bad = text.split("[sweep]")[0] + '[sweep]\n"contact.restitution" = [0.5, 0.8, 1.5]\n'
    with pytest.raises(SceneError) as caught:
        parse_scenes(tomllib.loads(bad), "bounce.toml")
    assert f"simparity: error: {caught.value}" in _docs_section()
