"""Rotation helpers: quaternions (w, x, y, z), matrices, rotation vectors, rpy."""

import numpy as np
import pytest

from simparity.core import rotations as rot

# Round trips through float64 formulas: a few ulps of values of size 1.
ROUND_TRIP_TOL = 1e-14


@pytest.fixture
def rng():
    return np.random.default_rng(20070305)


def test_quaternion_matrix_round_trip(rng):
    """matrix -> quaternion -> matrix is the identity, for every branch of Shepperd's method."""
    q = rot.quat_wxyz_normalize(rng.normal(size=(2000, 4)))
    r = rot.quat_wxyz_to_matrix(q)
    np.testing.assert_allclose(rot.quat_wxyz_to_matrix(rot.matrix_to_quat_wxyz(r)), r, atol=ROUND_TRIP_TOL)
    # Half-turns exercise the x, y, z branches.
    half_turns = rot.so3_exp(np.pi * np.eye(3))
    np.testing.assert_allclose(rot.quat_wxyz_to_matrix(rot.matrix_to_quat_wxyz(half_turns)), half_turns,
                               atol=ROUND_TRIP_TOL)


def test_quaternion_product_matches_matrix_product(rng):
    """R(a * b) = R(a) R(b): the Hamilton product composes rotations in the project's convention."""
    a, b = rot.quat_wxyz_normalize(rng.normal(size=(2, 500, 4)))
    np.testing.assert_allclose(
        rot.quat_wxyz_to_matrix(rot.quat_wxyz_multiply(a, b)),
        rot.quat_wxyz_to_matrix(a) @ rot.quat_wxyz_to_matrix(b), atol=ROUND_TRIP_TOL)


def test_exp_log_and_rotvec_agree(rng):
    """so3_exp and quat_wxyz_from_rotvec give the same rotation; so3_log inverts so3_exp below pi."""
    v = rng.normal(size=(1000, 3))
    v *= (rng.uniform(0, np.pi * 0.999, size=1000) / np.linalg.norm(v, axis=1))[:, None]
    np.testing.assert_allclose(rot.so3_exp(v), rot.quat_wxyz_to_matrix(rot.quat_wxyz_from_rotvec(v)), atol=ROUND_TRIP_TOL)
    np.testing.assert_allclose(rot.so3_log(rot.so3_exp(v)), v, atol=1e-12)
    tiny = 1e-9 * rng.normal(size=(10, 3))
    np.testing.assert_allclose(rot.so3_log(rot.so3_exp(tiny)), tiny, atol=1e-22, rtol=1e-9)


def test_exp_is_rodrigues_about_z():
    """exp of (0, 0, a) is the planar rotation by a about z."""
    a = 0.7
    expected = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    np.testing.assert_allclose(rot.so3_exp(np.array([0, 0, a])), expected, atol=ROUND_TRIP_TOL)


def test_geodesic_angle_is_sign_blind(rng):
    """q and -q are 0 rad apart; a known rotation of 0.3 rad measures 0.3 rad."""
    q = rot.quat_wxyz_normalize(rng.normal(size=(100, 4)))
    np.testing.assert_allclose(rot.geodesic_angle_quat_wxyz(q, -q), 0, atol=1e-7)
    turned = rot.quat_wxyz_multiply(q, rot.quat_wxyz_from_rotvec(np.array([0.3, 0, 0])))
    np.testing.assert_allclose(rot.geodesic_angle_quat_wxyz(q, turned), 0.3, atol=ROUND_TRIP_TOL)
    np.testing.assert_allclose(
        rot.geodesic_angle_matrix(rot.quat_wxyz_to_matrix(q), rot.quat_wxyz_to_matrix(turned)), 0.3, atol=1e-12)


def test_rpy_is_urdf_convention_and_round_trips(rng):
    """rpy = Rz(yaw) Ry(pitch) Rx(roll), as URDF; matrix_to_rpy inverts it, gimbal lock included."""
    roll, pitch, yaw = 0.1, -0.4, 1.2
    rz = rot.so3_exp(np.array([0, 0, yaw]))
    ry = rot.so3_exp(np.array([0, pitch, 0]))
    rx = rot.so3_exp(np.array([roll, 0, 0]))
    np.testing.assert_allclose(rot.rpy_to_matrix(np.array([roll, pitch, yaw])), rz @ ry @ rx, atol=ROUND_TRIP_TOL)
    rpy = rng.uniform(-1, 1, size=(1000, 3)) * [np.pi, np.pi / 2, np.pi]
    r = rot.rpy_to_matrix(rpy)
    np.testing.assert_allclose(rot.rpy_to_matrix(rot.matrix_to_rpy(r)), r, atol=ROUND_TRIP_TOL)
    for pitch in (np.pi / 2, -np.pi / 2):
        locked = rot.rpy_to_matrix(np.array([0.3, pitch, -0.7]))
        np.testing.assert_allclose(rot.rpy_to_matrix(rot.matrix_to_rpy(locked)), locked, atol=ROUND_TRIP_TOL)


def test_orthonormalize_returns_the_nearest_rotation(rng):
    """A perturbed rotation comes back orthonormal with determinant +1, close to the original."""
    r = rot.so3_exp(rng.normal(size=(50, 3)))
    noisy = r + 1e-6 * rng.normal(size=r.shape)
    fixed = rot.orthonormalize(noisy)
    np.testing.assert_allclose(fixed @ np.swapaxes(fixed, -1, -2), np.broadcast_to(np.eye(3), fixed.shape), atol=ROUND_TRIP_TOL)
    np.testing.assert_allclose(np.linalg.det(fixed), 1.0, atol=ROUND_TRIP_TOL)
    assert np.abs(fixed - r).max() < 1e-5
