"""Core's rotations against an independent library: SciPy's Rotation (scalar_first=True).

Core's quaternions are (w, x, y, z), rotation matrices map body to world, rpy is URDF's;
each function is compared with SciPy's on random inputs, so a convention slip in core
(order, sign, transpose) fails here instead of agreeing with itself in a round trip.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from simparity.core import rotations as rot

# Two float64 implementations of the same formula on values of size 1 differ by a few ulps.
AGREEMENT_TOL = 1e-14
# so3_log near pi and rpy near gimbal lock divide by small numbers; they keep ~12 digits.
ILL_CONDITIONED_TOL = 1e-12


@pytest.fixture
def rng():
    return np.random.default_rng(20070305)


def _quats(rng, n):
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _same_rotation(a, b):
    """|<a, b>| = 1 for quaternions of the same rotation (q and -q)."""
    return np.abs(np.abs(np.sum(a * b, axis=-1)) - 1.0).max()


def test_quaternion_to_matrix_is_scipys(rng):
    """(w, x, y, z) -> body-to-world matrix, as SciPy with the scalar first."""
    q = _quats(rng, 2000)
    np.testing.assert_allclose(rot.quat_wxyz_to_matrix(q), Rotation.from_quat(q, scalar_first=True).as_matrix(),
                               atol=AGREEMENT_TOL)


def test_matrix_to_quaternion_is_scipys(rng):
    """Shepperd's method, every branch (half turns included), gives SciPy's quaternion up to sign."""
    r = np.concatenate([Rotation.from_quat(_quats(rng, 2000)).as_matrix(),
                        Rotation.from_rotvec(np.pi * np.eye(3)).as_matrix()])
    q = rot.matrix_to_quat_wxyz(r)
    assert _same_rotation(q, Rotation.from_matrix(r).as_quat(scalar_first=True)) <= AGREEMENT_TOL
    assert np.all(q[:, 0] >= 0)


def test_hamilton_product_composes_like_scipy(rng):
    """a * b is the rotation b first, then a: SciPy's Rotation(a) * Rotation(b)."""
    a, b = _quats(rng, 500), _quats(rng, 500)
    expected = (Rotation.from_quat(a, scalar_first=True) * Rotation.from_quat(b, scalar_first=True))
    assert _same_rotation(rot.quat_wxyz_multiply(a, b), expected.as_quat(scalar_first=True)) <= AGREEMENT_TOL


def test_exp_and_rotvec_are_scipys(rng):
    """so3_exp and quat_wxyz_from_rotvec are SciPy's from_rotvec, small angles included."""
    v = rng.normal(size=(1000, 3)) * rng.uniform(0, np.pi, size=(1000, 1)) / np.sqrt(3)
    v = np.concatenate([v, 1e-9 * rng.normal(size=(10, 3))])
    np.testing.assert_allclose(rot.so3_exp(v), Rotation.from_rotvec(v).as_matrix(), atol=AGREEMENT_TOL)
    assert _same_rotation(rot.quat_wxyz_from_rotvec(v), Rotation.from_rotvec(v).as_quat(scalar_first=True)) \
        <= AGREEMENT_TOL


def test_log_is_scipys(rng):
    """so3_log is SciPy's as_rotvec (angle in [0, pi]), close to pi included."""
    v = rng.normal(size=(1000, 3))
    v *= (rng.uniform(0, np.pi * (1 - 1e-6), size=1000) / np.linalg.norm(v, axis=1))[:, None]
    r = Rotation.from_rotvec(v).as_matrix()
    np.testing.assert_allclose(rot.so3_log(r), Rotation.from_matrix(r).as_rotvec(), atol=ILL_CONDITIONED_TOL)


def test_geodesic_angles_are_scipys_magnitude(rng):
    """The angle between two orientations is the magnitude of the relative rotation, sign-blind."""
    a, b = _quats(rng, 500), _quats(rng, 500)
    expected = (Rotation.from_quat(a, scalar_first=True).inv() * Rotation.from_quat(b, scalar_first=True)).magnitude()
    np.testing.assert_allclose(rot.geodesic_angle_quat_wxyz(a, b), expected, atol=ILL_CONDITIONED_TOL)
    np.testing.assert_allclose(rot.geodesic_angle_quat_wxyz(a, -b), expected, atol=ILL_CONDITIONED_TOL)
    np.testing.assert_allclose(rot.geodesic_angle_matrix(rot.quat_wxyz_to_matrix(a), rot.quat_wxyz_to_matrix(b)),
                               expected, atol=ILL_CONDITIONED_TOL)


def test_rpy_is_scipys_extrinsic_xyz(rng):
    """URDF rpy = Rz(yaw) Ry(pitch) Rx(roll) = SciPy's extrinsic 'xyz'; matrix_to_rpy gives the same matrix back."""
    rpy = rng.uniform(-1, 1, size=(1000, 3)) * [np.pi, np.pi / 2, np.pi]
    np.testing.assert_allclose(rot.rpy_to_matrix(rpy), Rotation.from_euler("xyz", rpy).as_matrix(), atol=AGREEMENT_TOL)
    locked = Rotation.from_euler("xyz", [[0.3, np.pi / 2, -0.7], [0.3, -np.pi / 2, -0.7]]).as_matrix()
    r = np.concatenate([Rotation.from_euler("xyz", rpy).as_matrix(), locked])
    np.testing.assert_allclose(Rotation.from_euler("xyz", rot.matrix_to_rpy(r)).as_matrix(), r,
                               atol=ILL_CONDITIONED_TOL)


def test_exp_about_z_by_hand():
    """exp of (0, 0, a) is the planar rotation by a about z (written out)."""
    a = 0.7
    expected = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    np.testing.assert_allclose(rot.so3_exp(np.array([0, 0, a])), expected, atol=AGREEMENT_TOL)


def test_orthonormalize_returns_the_nearest_rotation(rng):
    """A perturbed rotation comes back orthonormal with determinant +1, close to the original."""
    r = Rotation.from_rotvec(rng.normal(size=(50, 3))).as_matrix()
    fixed = rot.orthonormalize(r + 1e-6 * rng.normal(size=r.shape))
    np.testing.assert_allclose(fixed @ np.swapaxes(fixed, -1, -2), np.broadcast_to(np.eye(3), fixed.shape),
                               atol=AGREEMENT_TOL)
    np.testing.assert_allclose(np.linalg.det(fixed), 1.0, atol=AGREEMENT_TOL)
    assert np.abs(fixed - r).max() < 1e-5
