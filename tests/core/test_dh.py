"""DH tables: the Chain built from a table has the FK of the plain DH matrix product."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.core.dh import CONVENTIONS, UR5_DH, chain_from_dh, dh_forward
from simparity.core.model.errors import SceneError
from simparity.core.kinematics import joint_frames

# The chain and the direct product multiply the same elementary matrices grouped
# differently; they differ by float64 rounding only (~1e-15 on a 1 m arm).
FK_TOLERANCE = 1e-12
N_CONFIGURATIONS = 100

# Offsets that are not zero, so that an off-by-one in theta_offset handling shows.
OFFSETS = (0.3, -1.1, 0.7, 2.0, -0.4, 1.3)
MIXED_TYPES = ("revolute", "prismatic", "revolute", "revolute", "prismatic", "revolute")


def _direct(table: dict, q: np.ndarray, theta_offset, types) -> np.ndarray:
    prismatic = np.array([t == "prismatic" for t in types])
    theta = np.asarray(theta_offset) + np.where(prismatic, 0.0, q)
    d = np.asarray(table["d"]) + np.where(prismatic, q, 0.0)
    return dh_forward(table["a"], table["alpha"], d, theta, table["convention"])


@pytest.mark.parametrize("convention", CONVENTIONS)
@pytest.mark.parametrize("types", [("revolute",) * 6, MIXED_TYPES], ids=["revolute", "mixed"])
def test_chain_fk_matches_dh_product(convention, types):
    """The UR5 table (with offsets and prismatic joints) gives the DH product's flange pose."""
    table = {**UR5_DH, "convention": convention}
    chain = chain_from_dh(table["name"], table["a"], table["alpha"], table["d"], OFFSETS,
                          convention=convention, joint_types=types)
    rng = np.random.default_rng(11)
    q = rng.uniform(-np.pi, np.pi, size=(N_CONFIGURATIONS, 6))
    positions, rotations, _ = joint_frames(chain, q)
    expected = _direct(table, q, OFFSETS, types)
    np.testing.assert_allclose(positions[:, -1], expected[:, :3, 3], rtol=0, atol=FK_TOLERANCE)
    np.testing.assert_allclose(rotations[:, -1], expected[:, :3, :3], rtol=0, atol=FK_TOLERANCE)


def test_ur5_published_table():
    """UR5_DH builds the UR5 whose zero pose has the flange at the published position."""
    chain = chain_from_dh(**UR5_DH)
    assert chain.n_joints == 6
    positions, _, _ = joint_frames(chain, np.zeros((1, 6)))
    # Zero pose: x = a2 + a3, y = -(d4 + d6), z = d1 - d5 (UR's standard DH frames).
    np.testing.assert_allclose(positions[0, -1], [-0.425 - 0.39225, -(0.10915 + 0.0823), 0.089159 - 0.09465],
                               rtol=0, atol=FK_TOLERANCE)


def test_zero_q_is_theta_offset():
    """q = 0 of the chain is the table's theta = theta_offset, in both conventions."""
    for convention in CONVENTIONS:
        chain = chain_from_dh("t", UR5_DH["a"], UR5_DH["alpha"], UR5_DH["d"], OFFSETS, convention=convention)
        _, rotations, _ = joint_frames(chain, np.zeros((1, 6)))
        expected = dh_forward(UR5_DH["a"], UR5_DH["alpha"], UR5_DH["d"], OFFSETS, convention)
        np.testing.assert_allclose(rotations[0, -1], expected[:3, :3], rtol=0, atol=FK_TOLERANCE)


def test_modified_joint_frames_are_craig_frames():
    """In the modified convention joint i's child-link frame is Craig's frame i."""
    a, alpha, d = UR5_DH["a"], UR5_DH["alpha"], UR5_DH["d"]
    chain = chain_from_dh("t", a, alpha, d, OFFSETS, convention="modified")
    rng = np.random.default_rng(12)
    q = rng.uniform(-np.pi, np.pi, size=(N_CONFIGURATIONS, 6))
    positions, _, _ = joint_frames(chain, q)
    theta = np.asarray(OFFSETS) + q
    for i in range(1, 7):
        partial = dh_forward(a[:i], alpha[:i], np.broadcast_to(d[:i], (N_CONFIGURATIONS, i)), theta[:, :i], "modified")
        np.testing.assert_allclose(positions[:, i - 1], partial[:, :3, 3], rtol=0, atol=FK_TOLERANCE)


def test_limits_are_carried():
    """Limits given per joint end up on the chain's joints."""
    limits = [(-1.0, 1.0)] * 5 + [(-0.5, 0.25)]
    chain = chain_from_dh(**UR5_DH, limits=limits)
    np.testing.assert_array_equal(chain.lower, [-1.0] * 5 + [-0.5])
    np.testing.assert_array_equal(chain.upper, [1.0] * 5 + [0.25])


@pytest.mark.parametrize("change, key", [
    ({"convention": "craig"}, "convention"),
    ({"a": UR5_DH["a"][:5]}, "a, alpha, d, theta_offset"),
    ({"d": (np.nan,) * 6}, "d"),
    ({"joint_types": ("revolute",) * 5 + ("spherical",)}, "joint_types"),
    ({"limits": [(1.0, -1.0)] * 6}, "limits"),
])
def test_bad_tables_are_rejected(change, key):
    """Malformed tables raise a SceneError naming the offending argument."""
    with pytest.raises(SceneError) as info:
        chain_from_dh(**{**UR5_DH, **change})
    assert info.value.key == key
