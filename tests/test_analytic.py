"""The analytic engine: closed forms where they exist, n/a with a reason where they do not."""

import numpy as np

from core.kinematics import forward_kinematics, jacobian_world
from references.analytic import AnalyticEngine
from tests.helpers import builtin, exact_projectile, random_chain, tumbling_box

# Two float64 evaluations of equivalent closed forms on a ~2.4 m arm.
EXACT_TOL = 1e-13


def test_planar_closed_form_matches_core():
    """The sum-of-rotated-links FK and its derivative equal core's cross-product Jacobian."""
    scene = builtin("lecture-planar-arm")
    q = scene.configurations()
    model = AnalyticEngine().build_kinematics(scene.chain)
    poses, ref = model.forward_kinematics(q), forward_kinematics(scene.chain, q)
    np.testing.assert_allclose(poses.position_world, ref.position_world, atol=EXACT_TOL)
    np.testing.assert_allclose(poses.rotation_world, ref.rotation_world, atol=EXACT_TOL)
    np.testing.assert_allclose(model.jacobian_world(q), jacobian_world(scene.chain, q), atol=EXACT_TOL)


def test_non_planar_chain_is_not_available_with_reason():
    """A spatial chain has no closed form here: support is refused and the joint is named."""
    support = AnalyticEngine().supports_kinematics(random_chain(np.random.default_rng(3), 4))
    assert not support.ok and "joint 'j0'" in support.reason


def test_projectile_is_the_parabola():
    """The analytic engine's trajectory is x0 + v0 t + g t^2 / 2 at every sample."""
    scene = builtin("lecture-projectile")
    traj = AnalyticEngine().build_dynamics(scene, "exact", scene.dts[0]).run(scene.n_steps(scene.dts[0]))
    position, velocity = exact_projectile(scene, traj.times)
    np.testing.assert_allclose(traj.position_world, position, atol=EXACT_TOL)
    np.testing.assert_allclose(traj.velocity_world, velocity, atol=EXACT_TOL)


def test_unsteady_rotation_is_not_available():
    """A body tumbling about a non-principal axis is refused (not faked) with the body named."""
    support = AnalyticEngine().supports_dynamics(tumbling_box(), "exact")
    assert not support.ok and "box" in support.reason
