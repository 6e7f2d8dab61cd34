"""IK targets: random ones are reachable poses; each hard target is what its name says."""

import dataclasses

import numpy as np

from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.execute.ik_targets import ORIENTATION_ONLY, hard_target, random_targets
from simparity.core.ik.reach import reach_upper_bound
from simparity.core.kinematics import forward_kinematics
from simparity.core.rotations import geodesic_angle_matrix
from tests.helpers import builtin

EXACT_TOL = 1e-12  # FK evaluated twice in float64


def _fk(scene):
    """The scene's reference FK, which makes its targets."""
    return make_engine(scene.reference).build_kinematics(scene.chain)


def test_random_targets_are_poses_of_seeded_configurations():
    """Each random target is the end-effector pose of the scene's seeded configuration; reruns agree."""
    scene = builtin("iiwa-ik")
    targets = random_targets(scene, _fk(scene))
    frames = forward_kinematics(scene.chain, scene.configurations())
    np.testing.assert_allclose(targets.position_world, frames.position_world[:, -1], atol=EXACT_TOL)
    np.testing.assert_allclose(targets.rotation_world, frames.rotation_world[:, -1], atol=EXACT_TOL)
    assert len(targets.position_world) == scene.n_targets == 1000
    np.testing.assert_array_equal(random_targets(scene, _fk(scene)).position_world, targets.position_world)


def test_hard_targets_are_what_they_say():
    """Beyond reach is 1.5x the bound away; at_base is joint 1; near_limits is inside the limits; in-place keeps position."""
    scene = builtin("iiwa-ik")
    center, radius = reach_upper_bound(scene.chain)
    far = hard_target(scene, "beyond_reach", _fk(scene))
    np.testing.assert_allclose(np.linalg.norm(far.position_world[0] - center), 1.5 * radius)
    np.testing.assert_allclose(hard_target(scene, "at_base", _fk(scene)).position_world[0], center)
    start = forward_kinematics(scene.chain, scene.q_start[None])
    turned = hard_target(scene, "orientation_in_place", _fk(scene))
    np.testing.assert_allclose(turned.position_world[0], start.position_world[0, -1], atol=EXACT_TOL)
    np.testing.assert_allclose(geodesic_angle_matrix(turned.rotation_world[0], start.rotation_world[0, -1]), np.pi / 2)
    for name in ("near_limits", "stretched", "wrist_flip"):
        assert hard_target(scene, name, _fk(scene)).position_world.shape == (1, 3)


def test_position_scenes_have_position_targets():
    """A position scene's targets carry no orientation."""
    scene = builtin("lecture-2link-ik")
    assert scene.target_kind == "position"
    assert random_targets(scene, _fk(scene)).rotation_world is None
    assert hard_target(scene, "near_limits", _fk(scene)).rotation_world is None
    assert set(ORIENTATION_ONLY) == {"orientation_in_place", "wrist_flip"}
    assert not set(dataclasses.asdict(scene)["hard_targets"]) & set(ORIENTATION_ONLY)
