"""The references' own derivations of a scene file's numbers (references/common/scene_inputs, dh_frames,
point_masses), against hand-computed values and the direct DH product (core.dh.dh_forward, a different code path
from core's chain_from_dh, and from these modules)."""

import numpy as np
import pytest

from simparity.core.dh import UR5_DH, dh_forward
from simparity.core.model.scenes.chain import DHTable
from simparity.references.common.dh_frames import dh_frames
from simparity.references.common.point_masses import point_mass_properties
from simparity.references.common.scene_inputs import as_given
from tests.helpers import builtin

EXACT = 1e-15
"""A handful of float64 operations on numbers of size ~1."""

CHAIN_PRODUCT = 1e-14
"""[m, 1] Six DH rows composed two ways: rounding of ~10 products of 4 x 4 matrices of size ~1."""


def test_two_point_masses_have_the_reduced_mass_tensor():
    """m1 at x1, m2 at x2 on the x axis: M = m1 + m2, COM (m1 x1 + m2 x2) / M, I_yy = I_zz = m1 m2 / M (x1 - x2)^2."""
    m1, m2, x1, x2 = 2.0, 0.5, 0.3, -0.7
    mass, center, inertia = point_mass_properties(np.array([m1, m2]), np.array([[x1, 0, 0], [x2, 0, 0.0]]))
    reduced = m1 * m2 / (m1 + m2) * (x1 - x2) ** 2
    assert mass == m1 + m2
    np.testing.assert_allclose(center, [(m1 * x1 + m2 * x2) / (m1 + m2), 0, 0], atol=EXACT)
    np.testing.assert_allclose(inertia, np.diag([0.0, reduced, reduced]), atol=EXACT)


def test_products_of_inertia_carry_the_physical_sign():
    """Two unit masses at +-(a, a, 0): I_xy = -sum m x y = -2 a^2 (the slide's table prints it without the minus)."""
    a = 0.4
    _, _, inertia = point_mass_properties(np.ones(2), np.array([[a, a, 0.0], [-a, -a, 0.0]]))
    np.testing.assert_allclose(inertia, [[2 * a * a, -2 * a * a, 0], [-2 * a * a, 2 * a * a, 0], [0, 0, 4 * a * a]],
                               atol=EXACT)
    assert np.array_equal(inertia, inertia.T)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_dh_frames_compose_to_the_direct_dh_product(convention):
    """The joint frames and end effector, composed with each joint's rotation Rz(q_i), give the plain product of the
    table's rows at theta = theta_offset + q."""
    table = DHTable(convention, np.array(UR5_DH["a"]), np.array(UR5_DH["alpha"]), np.array(UR5_DH["d"]),
                    np.array([0.1, -0.2, 0.3, 0.0, 0.5, -0.4]))
    q = np.random.default_rng(3).uniform(-np.pi, np.pi, size=6)
    joints, (tip_xyz, tip_rotation) = dh_frames(table)
    pose = np.eye(4)
    for (xyz, rotation), angle in zip(joints, q):
        step = np.eye(4)
        step[:3, :3], step[:3, 3] = rotation, xyz
        spin = np.eye(4)
        spin[:2, :2] = [[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]
        pose = pose @ step @ spin
    tip = np.eye(4)
    tip[:3, :3], tip[:3, 3] = tip_rotation, tip_xyz
    expected = dh_forward(table.a, table.alpha, table.d, table.theta_offset + q, convention)
    np.testing.assert_allclose(pose @ tip, expected, atol=CHAIN_PRODUCT)


def test_a_scene_with_nothing_derived_reaches_the_references_as_it_is():
    """A URDF chain, a body given by its mass and tensor: the same object (nothing recomputed, nothing copied)."""
    for name in ("iiwa-kinematics", "dzhanibekov"):
        scene = builtin(name)
        assert as_given(scene) is scene
