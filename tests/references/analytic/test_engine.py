"""The analytic engine: closed forms where they exist, n/a with a reason where they do not."""

import numpy as np
import pytest

from simparity.core.inhouse import InHouseEngine
from simparity.core.rotations import geodesic_angle_quat_wxyz, so3_exp

from simparity.core.kinematics import forward_kinematics, jacobian_world
from simparity.references.analytic.engine import AnalyticEngine
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


def test_applied_force_torque_is_not_available():
    """A body turned by a force at a point has no closed form here: refused (not faked), body named."""
    scene = builtin("point-force-torque")
    support = AnalyticEngine().supports_dynamics(scene, "exact")
    assert not support.ok and "applied force" in support.reason and "'box'" in support.reason


# Core RK4 at dt = 1e-3 over 2 s is within ~1e-11 of the exact solution; the closed forms are
# 1e-13 or better (tests/references/analytic/test_solutions.py), so 1e-9 checks the frame bookkeeping.
TUMBLING_TOL = 1e-9


@pytest.mark.slow
@pytest.mark.parametrize("moments, rotated", [((0.1, 0.2, 0.3), False), ((0.1, 0.2, 0.3), True),
                                              ((0.2, 0.2, 0.3), False), ((0.1, 0.3, 0.3), True)])
def test_tumbling_closed_forms_in_any_body_frame(moments, rotated):
    """Asymmetric and axisymmetric tumbling, principal axes aligned or not, match a fine RK4 run."""
    r = so3_exp(np.array([0.3, -0.5, 0.7])) if rotated else np.eye(3)
    scene = tumbling_box(inertia_body=r @ np.diag(moments) @ r.T, duration=2.0, dt=1e-3)
    n = scene.n_steps(1e-3)
    exact = AnalyticEngine().build_dynamics(scene, "exact", 1e-3).run(n)
    fine = InHouseEngine().build_dynamics(scene, "rk4", 1e-3).run(n)
    assert geodesic_angle_quat_wxyz(exact.quat_wxyz, fine.quat_wxyz).max() <= TUMBLING_TOL
    np.testing.assert_allclose(exact.angular_velocity_world, fine.angular_velocity_world, atol=TUMBLING_TOL)


def test_two_link_ik_picks_the_branch_nearest_the_start_and_reports_unreachable():
    """The closed form solves reachable targets to 1e-12 near the start branch; far targets are unreachable."""
    from simparity.core.ik.jacobian_solvers import IKOptions

    scene = builtin("lecture-2link-ik")
    model = AnalyticEngine().build_ik(scene.chain, "two_link", IKOptions())
    q_true = np.array([[0.4, 0.9], [-1.0, 0.5]])  # elbow on the start's side (q2 > 0)
    target = forward_kinematics(scene.chain, q_true).position_world[:, -1]
    result = model.solve(target, None, scene.q_start)
    np.testing.assert_allclose(result.q, q_true, atol=1e-12)
    assert result.success.all() and result.position_residual.max() < 1e-12
    far = model.solve(np.array([[3.0, 0.0, 0.0]]), None, scene.q_start)
    assert not far.success[0] and far.reason[0] == "unreachable"
    np.testing.assert_allclose(far.position_residual, [3.0 - 1.8], atol=1e-12)  # nearest reachable point
