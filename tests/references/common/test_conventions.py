"""The references' conventions, checked by hand: quaternion order, URDF rpy, principal axes."""

import numpy as np

from simparity.references.common import conventions as c

EXACT_TOL = 1e-15  # a few float64 operations on values of size 1


def test_quaternion_is_scalar_first():
    """(cos 45 deg, 0, 0, sin 45 deg) is a quarter turn about z: x -> y."""
    q = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])
    np.testing.assert_allclose(c.quat_wxyz_to_matrix(q) @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=EXACT_TOL)
    np.testing.assert_allclose(c.xyzw_from_wxyz(q), [0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)])
    np.testing.assert_allclose(c.wxyz_from_xyzw(c.xyzw_from_wxyz(q)), q)


def test_rpy_is_urdfs():
    """rpy (0.1, -0.4, 1.2) is Rz(1.2) Ry(-0.4) Rx(0.1), each written out."""
    roll, pitch, yaw = 0.1, -0.4, 1.2
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    np.testing.assert_allclose(c.rpy_to_matrix([roll, pitch, yaw]), rz @ ry @ rx, atol=EXACT_TOL)
    np.testing.assert_allclose(c.matrix_to_rpy(rz @ ry @ rx), [roll, pitch, yaw], atol=1e-14)


def test_products_compose_b_first():
    """about_z * about_x applies the quarter turn about x first, then the one about z."""
    about_x = np.array([np.cos(np.pi / 4), np.sin(np.pi / 4), 0.0, 0.0])
    about_z = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])
    both = c.quat_wxyz_to_matrix(c.quat_wxyz_multiply(about_z, about_x))
    np.testing.assert_allclose(both @ [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], atol=EXACT_TOL)  # x turns y to z; z keeps z
    np.testing.assert_allclose(both @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=EXACT_TOL)  # x keeps x; z turns it to y


def test_rotation_angle_between_matrices():
    """Two orientations 0.3 rad apart about any axis measure 0.3 rad; the same one 0."""
    r = c.rotvec_to_matrix([0.2, -0.5, 0.9])
    turned = r @ c.rotvec_to_matrix([0.0, 0.3, 0.0])
    np.testing.assert_allclose(c.rotation_angle(r, turned), 0.3, atol=1e-14)
    np.testing.assert_allclose(c.rotation_angle(r, r), 0.0, atol=1e-14)


def test_quaternion_angle_is_accurate_from_small_to_half_turn():
    """(cos a/2, sin a/2 n) against the identity measures a, down to 1e-9 rad (no arccos floor), and the sign
    of a quaternion does not matter."""
    axis = np.array([2.0, -1.0, 2.0]) / 3.0
    for angle in (1e-9, 0.3, 3.0):
        q = np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * axis])
        np.testing.assert_allclose(c.quat_wxyz_angle([1.0, 0, 0, 0], q), angle, rtol=1e-12)
        np.testing.assert_allclose(c.quat_wxyz_angle([1.0, 0, 0, 0], -q), angle, rtol=1e-12)


def test_non_finite_matrix_gives_a_non_finite_quaternion():
    """A blown-up state stays visibly blown up instead of raising in SciPy's SVD."""
    q = c.matrix_to_quat_wxyz(np.stack([np.eye(3), np.full((3, 3), np.nan)]))
    np.testing.assert_allclose(q[0], [1.0, 0, 0, 0])
    assert np.isnan(q[1]).all()


def test_principal_axes_of_a_rotated_box():
    """The tensor Q diag(1, 2, 3) Q^T gives back the moments 1, 2, 3 and a proper rotation."""
    q = c.rotvec_to_matrix([0.3, -0.2, 0.5])
    moments, axes = c.principal_axes(q @ np.diag([1.0, 2.0, 3.0]) @ q.T)
    np.testing.assert_allclose(moments, [1.0, 2.0, 3.0], atol=1e-14)
    np.testing.assert_allclose(axes @ np.diag(moments) @ axes.T, q @ np.diag([1.0, 2.0, 3.0]) @ q.T, atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(axes), 1.0, atol=EXACT_TOL)
