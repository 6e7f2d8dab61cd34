"""Metamorphic transforms map a scene as physics says, and results carry back into the scene's units.

A closed-form reference run on the transformed scene must equal the transformed reference run (positions
L R x + t, velocities (L/T) R v, orientations q_R q, angular velocities R omega / T, times T t, bodies in the
new order); chains move with their base; units round-trip; a transform that a scene cannot express is a
one-line error.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from simparity.comparisons.scenes import library
from simparity.comparisons.common.scene_hash import scene_hash
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.invariance.perturb import ulp_perturbed
from simparity.comparisons.invariance.rounding_allowance import rounding_floors
from simparity.comparisons.invariance.transforms import (
    FIXED_TRANSFORMS,
    TRANSFORM_NAMES,
    Transform,
    fixed_transforms,
    transform_scene,
)
from simparity.comparisons.invariance.units import Dimension, unit_dimensions, unit_factor
from simparity.core.model.errors import TransformError, UnitError
from simparity.core.model.scenes.bodies import AppliedForce

CLOSED_FORM_RTOL = 1e-9
"""The closed forms evaluated in two frames agree to rounding of their operands (sines, elliptic functions of
arguments ~1-100): 1e-9 of the state's size leaves a margin of 10^5 over what is measured (~1e-14)."""

ROUND_TRIP_RTOL = 4 * np.finfo(float).eps
"""A value multiplied by a unit factor and divided by it again: two roundings."""

FIXED = {t.name: t for t in FIXED_TRANSFORMS}
GENERAL = Transform("general", translation_world=[3.0, -1.5, 40.0],
                    quat_wxyz=Rotation.from_rotvec([0.3, -1.1, 0.7]).as_quat(scalar_first=True),
                    length_scale=2.3, mass_scale=0.7, time_scale=1.7)
"""Every part at once: turned, moved, rescaled."""


def _scene(name: str):
    return library.load([name])[0]


def _short(scene, steps: int = 50):
    """The scene at its coarsest time step for ``steps`` steps (a closed form has no step error)."""
    dt = max(scene.dts)
    return replace(scene, dts=(dt,), duration=steps * dt)


def _run(scene, engine: str = "analytic"):
    e = make_engine(engine)
    integrator = e.scene_integrators(scene)[0]
    return e.build_dynamics(scene, integrator, scene.dts[0]).run(scene.n_steps(scene.dts[0]))


def _close(a, b, scale) -> None:
    assert np.max(np.abs(np.asarray(a) - np.asarray(b))) <= CLOSED_FORM_RTOL * max(scale, 1.0)


@pytest.mark.parametrize("name", ["lecture-projectile", "falling-linear-drag", "wind", "dzhanibekov",
                                  "symmetric-top", "ball-bounce-k05", "incline-bounce", "block-slide"])
@pytest.mark.parametrize("transform", [GENERAL, FIXED["translate"], FIXED["ms"]], ids=lambda t: t.name)
def test_the_closed_form_of_a_transformed_scene_is_the_transformed_closed_form(name, transform):
    """The analytic reference run on the transformed scene equals its run on the scene, transformed."""
    scene = _short(_scene(name))
    base, moved = _run(scene), _run(transform_scene(scene, transform))
    rotation, length, time = transform.rotation_matrix, transform.length_scale, transform.time_scale
    size = float(np.abs(base.position_world).max()) * length + float(np.abs(transform.translation_world).max())
    _close(moved.times, time * base.times, time * base.times[-1])
    _close(moved.position_world, length * base.position_world @ rotation.T + transform.translation_world, size)
    speed = float(np.abs(base.velocity_world).max()) * length / time
    _close(moved.velocity_world, (length / time) * base.velocity_world @ rotation.T, speed)
    _close(moved.angular_velocity_world, base.angular_velocity_world @ rotation.T / time,
           float(np.abs(base.angular_velocity_world).max()) / time)
    turned = Rotation.from_quat(transform.quat_wxyz, scalar_first=True) * Rotation.from_quat(
        base.quat_wxyz.reshape(-1, 4), scalar_first=True)
    angle = (turned.inv() * Rotation.from_quat(moved.quat_wxyz.reshape(-1, 4), scalar_first=True)).magnitude()
    assert angle.max() <= CLOSED_FORM_RTOL


def test_a_permutation_lists_the_bodies_in_another_order_with_their_materials_shapes_and_forces():
    """incline-blocks reordered: body i of the new scene is body order[i] of the old, with its shape, its
    materials, its drags and the applied forces on it; the analytic runs agree body by body."""
    scene = _short(_scene("incline-blocks"))
    transform = Transform("swap", body_order=(1, 0))
    swapped = transform_scene(scene, transform)
    assert [b.name for b in swapped.bodies] == [b.name for b in reversed(scene.bodies)]
    assert swapped.contact.materials == tuple(reversed(scene.contact.materials))
    assert all(np.array_equal(a.half_extents_body, b.half_extents_body)
               for a, b in zip(swapped.contact.shapes, reversed(scene.contact.shapes)))
    base, moved = _run(scene), _run(swapped)
    np.testing.assert_array_equal(moved.position_world, base.position_world[:, ::-1])
    pushed = replace(scene, forces=replace(scene.forces, applied=(AppliedForce(1, [0.0, 0.0, 1.0], [0.1, 0.0, 0.0]),),
                                           linear_drag=np.array([0.1, 0.2])))
    moved_forces = transform_scene(pushed, transform).forces
    assert moved_forces.applied[0].body == 0 and moved_forces.linear_drag.tolist() == [0.2, 0.1]


def test_a_permutation_round_trips():
    """Reordering by an order and then by its inverse gives the scene back, exactly."""
    scene = _scene("incline-blocks")
    there = transform_scene(scene, Transform("there", body_order=(1, 0)))
    assert scene_hash(transform_scene(there, Transform("back", body_order=(1, 0)))) == scene_hash(scene)


def test_the_fixed_shuffle_moves_every_multibody_scene_and_leaves_one_body_alone():
    shuffle = FIXED["permute"]
    assert shuffle.order_for(2) == (1, 0) and shuffle.order_for(1) == (0,)
    assert sorted(shuffle.order_for(7)) == list(range(7)) and shuffle.order_for(7) != tuple(range(7))
    assert not shuffle.changes(_scene("ball-bounce-k05")) and shuffle.changes(_scene("incline-blocks"))


@pytest.mark.parametrize("name", ["ur5-kinematics", "lecture-planar-arm"])
def test_a_chain_moves_with_its_base_and_scales_with_its_lengths(name):
    """FK of the transformed chain (core's and MuJoCo's) is L R FK + t for every frame, and R for its rotation."""
    scene = _scene(name)
    q = scene.configurations()[:20]
    moved = transform_scene(scene, GENERAL)
    for engine in ("core", "mujoco"):
        model, turned = (make_engine(engine).build_kinematics(s.chain) for s in (scene, moved))
        before, after = model.forward_kinematics(q), turned.forward_kinematics(q)
        _close(after.position_world, GENERAL.point(before.position_world), 100.0)
        _close(after.rotation_world, GENERAL.rotation_matrix @ before.rotation_world, 1.0)


def test_an_ik_scene_scales_its_tolerance_and_prismatic_values():
    scene = _scene("ur5-ik")
    moved = transform_scene(scene, FIXED["rescale"])
    assert moved.position_tolerance == pytest.approx(FIXED["rescale"].length_scale * scene.position_tolerance)
    assert moved.orientation_tolerance == scene.orientation_tolerance
    np.testing.assert_array_equal(moved.q_start, scene.q_start)  # revolute: radians


def test_mass_time_and_order_leave_a_chain_as_it_is():
    scene = _scene("ur5-kinematics")
    for name in ("ms", "permute"):
        assert not FIXED[name].changes(scene) and transform_scene(scene, FIXED[name]) is scene


def test_a_urdf_chain_refuses_to_move_in_one_line():
    with pytest.raises(TransformError, match=r"iiwa-kinematics\.toml: transform rotate: chain .* URDF file .*"
                       r"\(allowed: a chain written in the scene file"):
        transform_scene(_scene("iiwa-kinematics"), FIXED["rotate"])


@pytest.mark.parametrize("fields, key", [
    (dict(length_scale=-1.0), "length_scale"), (dict(time_scale=0.0), "time_scale"),
    (dict(mass_scale=math.inf), "mass_scale"), (dict(quat_wxyz=[0, 0, 0, 0]), "quat_wxyz"),
    (dict(translation_world=[1.0, math.nan, 0.0]), "translation_world"),
])
def test_a_bad_transform_is_refused_naming_its_key(fields, key):
    with pytest.raises(TransformError, match=key):
        Transform("bad", **fields)


def test_a_body_order_must_be_an_order_of_the_scene_s_bodies():
    with pytest.raises(TransformError, match="not an order of the scene's 2 bodies"):
        transform_scene(_scene("incline-blocks"), Transform("bad", body_order=(0, 0)))


def test_a_rotation_may_be_given_as_a_matrix():
    matrix = Rotation.from_rotvec([0.2, 0.4, -0.1]).as_matrix()
    np.testing.assert_allclose(Transform.from_rotation_matrix("m", matrix).rotation_matrix, matrix, atol=1e-15)
    with pytest.raises(TransformError, match="proper rotation"):
        Transform.from_rotation_matrix("mirror", np.diag([1.0, 1.0, -1.0]))


def test_fixed_transforms_are_named_and_an_unknown_name_is_one_line():
    assert TRANSFORM_NAMES == ("translate", "rotate", "permute", "rescale", "ms")
    assert [t.name for t in fixed_transforms(["ms", "rotate", "ms"])] == ["ms", "rotate"]
    with pytest.raises(TransformError, match=r"--transform: spin: no such transform \(allowed: translate, rotate"):
        fixed_transforms(["spin"])
    assert np.linalg.norm(FIXED["translate"].translation_world) == pytest.approx(2000.0)
    assert FIXED["ms"].time_scale == 1000.0 and FIXED["ms"].length_scale == 1.0


@pytest.mark.parametrize("unit, dimension", [
    ("m", Dimension(length=1)), ("m/s", Dimension(length=1, time=-1)), ("s", Dimension(time=1)),
    ("rad/s", Dimension(time=-1)), ("rad", Dimension()), ("1", Dimension()), ("J", Dimension(2, 1, -2)),
    ("kg m^2", Dimension(2, 1, 0)), ("m/s^2", Dimension(length=1, time=-2)),
])
def test_units_have_their_dimensions(unit, dimension):
    assert unit_dimensions(unit) == (dimension,)


@pytest.mark.parametrize("unit, factor", [("m", 2.3), ("m/s", 2.3 / 1.7), ("s", 1.7), ("rad/s", 1 / 1.7),
                                          ("rad", 1.0), ("1", 1.0)])
def test_values_carry_back_into_the_scene_s_units(unit, factor):
    """A value of the transformed scene divided by its unit's factor; times the factor again gives it back."""
    assert GENERAL.to_scene_units(factor, unit) == pytest.approx(1.0, rel=ROUND_TRIP_RTOL)
    value = 0.123456789
    assert GENERAL.to_scene_units(value * unit_factor(unit, 2.3, 0.7, 1.7), unit) == pytest.approx(
        value, rel=ROUND_TRIP_RTOL)


def test_an_unknown_or_mixed_unit_is_never_converted_by_a_guess():
    with pytest.raises(UnitError, match="unknown symbol 'furlong'"):
        GENERAL.to_scene_units(1.0, "furlong")
    with pytest.raises(UnitError, match="more than one '/'"):
        unit_dimensions("m/s/s")
    with pytest.raises(UnitError, match="mixes dimensions"):
        GENERAL.to_scene_units(1.0, "m/rad or 1")
    assert FIXED["rotate"].to_scene_units(0.5, "m/rad or 1") == 0.5  # no change of units: nothing to mix


def test_a_one_ulp_perturbation_moves_the_state_and_the_units_by_one_ulp_seeded():
    """Each state component by one ulp of its vector, and the units of length, mass and time by one ulp each:
    carried back, the perturbed state is the scene's to within two ulps."""
    scene = _scene("dzhanibekov")
    moved, units = ulp_perturbed(scene, 1)
    assert {units.length_scale, units.mass_scale, units.time_scale} <= {np.nextafter(1.0, 2.0), np.nextafter(1.0, 0.0)}
    body, new = scene.bodies[0], moved.bodies[0]
    back = new.angular_velocity_world * units.time_scale
    spacing = np.spacing(np.max(np.abs(body.angular_velocity_world)))
    assert 0 < np.max(np.abs(back - body.angular_velocity_world)) <= 2 * spacing
    assert scene_hash(ulp_perturbed(scene, 1)[0]) == scene_hash(moved) != scene_hash(ulp_perturbed(scene, 2)[0])
    ball, _ = ulp_perturbed(_scene("ball-bounce-k05"), 1)
    assert not np.any(ball.bodies[0].velocity_world)  # at rest stays at rest
    assert ulp_perturbed(_scene("iiwa-ik"), 1)[1].length_scale == 1.0  # a URDF chain keeps its lengths


def test_rounding_allowances_scale_with_the_units_and_grow_far_from_the_origin():
    scene = _scene("lecture-projectile")
    base = rounding_floors(scene)
    rescaled = rounding_floors(transform_scene(scene, FIXED["rescale"]))
    length, mass, time = FIXED["rescale"].length_scale, FIXED["rescale"].mass_scale, FIXED["rescale"].time_scale
    assert rescaled.length == pytest.approx(length * base.length, rel=1e-12)
    assert rescaled.speed == pytest.approx(length / time * base.speed, rel=1e-12)
    assert rescaled.spin == pytest.approx(base.spin / time, rel=1e-12)
    assert rescaled.angle == pytest.approx(base.angle, rel=1e-12) and mass
    ball = _scene("ball-bounce-k05")  # within 40 m of the origin: 2 km away its positions carry ~80 x the rounding
    assert rounding_floors(transform_scene(ball, FIXED["translate"])).length > 50 * rounding_floors(ball).length


def test_a_transform_then_another_is_both_in_turn():
    units = Transform("units", length_scale=1.5, time_scale=0.5)
    both = GENERAL.then(units)
    scene = _short(_scene("ball-bounce-k05"))
    assert scene_hash(transform_scene(scene, both)) == scene_hash(transform_scene(transform_scene(scene, GENERAL),
                                                                                 units)) or np.allclose(
        transform_scene(scene, both).bodies[0].position_world,
        transform_scene(transform_scene(scene, GENERAL), units).bodies[0].position_world, rtol=1e-15, atol=1e-12)
    with pytest.raises(TransformError, match="reorders bodies"):
        GENERAL.then(FIXED["permute"])


URDF_SCENES = ("oblique-arm-swing", "oblique-arm-dynamics")
"""Built-in scenes whose chain every engine reads from a URDF file (its lengths and masses are the file's)."""


@pytest.mark.parametrize("name", URDF_SCENES)
def test_a_urdf_chain_is_perturbed_in_its_unit_of_time_alone(name):
    """The ulp perturbation a failing invariance comparison asks for changes only what a URDF chain's scene can say
    (its state and its unit of time): before, a mass unit one ulp off made it raise TransformError, and a
    `simparity run --transform` of a user's URDF arm ended in exit 2 after running every case."""
    scene = _scene(name)
    for seed in range(8):  # the mass factor is drawn +-1 ulp for each seed: some draw it off 1
        perturbed, units = ulp_perturbed(scene, seed)
        assert units.length_scale == 1.0 and units.mass_scale == 1.0
        assert perturbed.chain.urdf_path == scene.chain.urdf_path
