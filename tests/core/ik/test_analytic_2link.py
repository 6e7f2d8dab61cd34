"""The lecture's analytic two-link IK: both branches reach the target, unreachable ones the nearest point."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.core.ik.analytic_2link import two_link_fk, two_link_ik

# Both elbow branches must put the end point on the target to float64 rounding:
# |x| <= L1 + L2 ~ 1 m, a few operations each ~1e-16.
REACH_TOLERANCE = 1e-12
# The slide's arccos forms vs the atan2 forms, radii kept 0.05 m off both boundaries:
# arccos(c) has error ~eps / sqrt(1 - c^2) <= ~1e-14 rad there.
SLIDE_TOLERANCE = 1e-10
N_TARGETS = 10_000
L1, L2 = 0.7, 0.4


def _targets(rng, radius: np.ndarray) -> np.ndarray:
    angle = rng.uniform(-np.pi, np.pi, size=radius.shape)
    return np.stack([radius * np.cos(angle), radius * np.sin(angle)], axis=1)


def _reachable_radii(rng, l1: float, l2: float) -> np.ndarray:
    """Uniform radii plus radii 1e-6 .. 1e-15 (relative) inside both boundaries, where arccos
    would lose half its digits."""
    inner, outer = abs(l1 - l2), l1 + l2
    gaps = 10.0 ** -rng.uniform(6, 15, size=(2, N_TARGETS // 10))
    return np.concatenate([rng.uniform(inner, outer, size=N_TARGETS),
                           outer * (1 - gaps[0]), inner + (outer - inner) * gaps[1]])


@pytest.mark.parametrize("lengths", [(L1, L2), (L2, L1), (0.5, 0.5)], ids=["long-short", "short-long", "equal"])
def test_both_branches_reach_reachable_targets(lengths):
    """Each elbow branch reproduces seeded reachable targets (interior and near-boundary) to 1e-12."""
    l1, l2 = lengths
    rng = np.random.default_rng(21)
    radii = _reachable_radii(rng, l1, l2)
    target = _targets(rng, radii)
    solution = two_link_ik(l1, l2, target)
    reached = two_link_fk(l1, l2, solution.q)
    np.testing.assert_allclose(reached, np.broadcast_to(target[:, None], reached.shape), rtol=0, atol=REACH_TOLERANCE)


def test_branches_are_the_two_elbows():
    """Branch 0 bends the elbow counter-clockwise (t2 >= 0), branch 1 clockwise, with equal |t2|."""
    rng = np.random.default_rng(22)
    solution = two_link_ik(L1, L2, _targets(rng, rng.uniform(0.35, 1.05, size=1000)))
    assert np.all(solution.q[:, 0, 1] >= 0) and np.all(solution.q[:, 1, 1] <= 0)
    np.testing.assert_allclose(solution.q[:, 0, 1], -solution.q[:, 1, 1], rtol=0, atol=REACH_TOLERANCE)
    assert np.all(solution.reachable)


def test_matches_the_slide_arccos_formulas():
    """Where the slide's arccos formulas hold (Y >= 0), branch 1 equals them."""
    rng = np.random.default_rng(23)
    radius = rng.uniform(0.35, 1.05, size=1000)
    angle = rng.uniform(0.0, np.pi, size=1000)
    x, y = radius * np.cos(angle), radius * np.sin(angle)
    theta_t = np.arccos(x / radius)
    theta1 = np.arccos((L1**2 + radius**2 - L2**2) / (2 * L1 * radius)) + theta_t
    interior = np.arccos((L1**2 + L2**2 - radius**2) / (2 * L1 * L2))
    theta2 = -(np.pi - interior)
    q = two_link_ik(L1, L2, np.stack([x, y], axis=1)).q[:, 1]
    wrapped = np.angle(np.exp(1j * (q[:, 0] - theta1)))
    np.testing.assert_allclose(wrapped, 0.0, rtol=0, atol=SLIDE_TOLERANCE)
    np.testing.assert_allclose(q[:, 1], theta2, rtol=0, atol=SLIDE_TOLERANCE)


def test_unreachable_targets_give_the_nearest_point():
    """Targets outside L1 + L2 or inside |L1 - L2| are flagged and solved for the nearest reachable point."""
    rng = np.random.default_rng(24)
    outside = _targets(rng, rng.uniform(1.1 + 1e-9, 5.0, size=500))
    inside = _targets(rng, rng.uniform(1e-9, 0.3 - 1e-9, size=500))
    target = np.concatenate([outside, inside, [[0.0, 0.0]]])
    solution = two_link_ik(L1, L2, target)
    assert not np.any(solution.reachable)
    radius = np.linalg.norm(solution.reached_xy, axis=1)
    np.testing.assert_allclose(radius[:500], L1 + L2, rtol=0, atol=REACH_TOLERANCE)
    np.testing.assert_allclose(radius[500:], abs(L1 - L2), rtol=0, atol=REACH_TOLERANCE)
    direction = np.einsum("bi,bi->b", solution.reached_xy[:-1], target[:-1]) / (
        np.linalg.norm(target[:-1], axis=1) * radius[:-1])
    np.testing.assert_allclose(direction, 1.0, rtol=0, atol=REACH_TOLERANCE)
    np.testing.assert_allclose(solution.reached_xy[-1], [abs(L1 - L2), 0.0], rtol=0, atol=REACH_TOLERANCE)
    reached = two_link_fk(L1, L2, solution.q)
    np.testing.assert_allclose(reached, np.broadcast_to(solution.reached_xy[:, None], reached.shape),
                               rtol=0, atol=REACH_TOLERANCE)
    assert np.all(np.isfinite(solution.q))


def test_bad_input_is_rejected():
    """Non-positive lengths and non-finite or mis-shaped targets raise ValueError."""
    with pytest.raises(ValueError, match="link lengths"):
        two_link_ik(0.0, 1.0, np.zeros((1, 2)))
    with pytest.raises(ValueError, match="target_xy"):
        two_link_ik(1.0, 1.0, np.array([[np.nan, 0.0]]))
    with pytest.raises(ValueError, match="target_xy"):
        two_link_ik(1.0, 1.0, np.zeros(2))
