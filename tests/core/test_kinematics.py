"""In-house forward kinematics and the lecture's Jacobian."""

import numpy as np

from simparity.core.kinematics import finite_difference_jacobian_world, forward_kinematics, jacobian_world
from tests.helpers import builtin, random_chain

# Central differences with h = 1e-6 on ~1 m chains: truncation ~h^2 = 1e-12, rounding
# ~1e-16 / h = 1e-10; 1e-8 bounds both with margin.
FINITE_DIFFERENCE_TOL = 1e-8
# Two float64 evaluations of the same closed form: a few ulps.
EXACT_TOL = 1e-14


def test_planar_arm_jacobian_is_the_lecture_formula():
    """Each column of the planar arm's Jacobian is (0,0,1) x (E - P_i) with angular part (0,0,1)."""
    scene = builtin("lecture-planar-arm")
    q = scene.configurations()[:20]
    frames = forward_kinematics(scene.chain, q).position_world
    end, joints = frames[:, -1], frames[:, :-1]
    # Joint i sits at the origin of its own frame: P_1 = 0, P_2 = frame 1, ...
    expected = np.cross([0.0, 0.0, 1.0], end[:, None, :] - joints)
    jac = jacobian_world(scene.chain, q)
    np.testing.assert_allclose(jac[:, :3, :].transpose(0, 2, 1), expected, atol=EXACT_TOL)
    np.testing.assert_array_equal(jac[:, 3:, :], np.broadcast_to([[0.0], [0.0], [1.0]], (20, 3, 3)))


def test_planar_arm_fk_at_a_known_pose():
    """At (pi/2, -pi/2, 0) the tip of the 1.0/0.8/0.6 m arm is at (1.4, 1.0, 0)."""
    scene = builtin("lecture-planar-arm")
    tip = forward_kinematics(scene.chain, np.array([[np.pi / 2, -np.pi / 2, 0.0]])).position_world[0, -1]
    np.testing.assert_allclose(tip, [1.4, 1.0, 0.0], atol=EXACT_TOL)


def test_jacobian_matches_finite_differences_on_random_spatial_chains():
    """Revolute and prismatic columns agree with central differences through the manifold."""
    rng = np.random.default_rng(11)
    for n in (1, 4, 9):
        chain = random_chain(rng, n)
        q = rng.uniform(-np.pi, np.pi, size=(50, n))
        np.testing.assert_allclose(
            jacobian_world(chain, q), finite_difference_jacobian_world(chain, q), atol=FINITE_DIFFERENCE_TOL)


def test_batched_and_single_configurations_agree():
    """Evaluating a batch equals evaluating its rows one by one."""
    rng = np.random.default_rng(12)
    chain = random_chain(rng, 6)
    q = rng.uniform(-1, 1, size=(7, 6))
    batch = jacobian_world(chain, q)
    for k in range(len(q)):
        np.testing.assert_array_equal(jacobian_world(chain, q[k]), batch[k : k + 1])
