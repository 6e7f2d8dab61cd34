"""The lecture's analytic IK of a planar two-link arm, both elbow solutions.

The arm has links of length L1 and L2 [m] from the origin; joint 1 is the angle of link 1
from the x axis, joint 2 the angle of link 2 relative to link 1 (0 = stretched), both
counter-clockwise [rad]. The end point is

    x = L1 cos(t1) + L2 cos(t1 + t2),   y = L1 sin(t1) + L2 sin(t1 + t2).

The slide solves it with arccos: with r^2 = X^2 + Y^2,

    t_T = arccos(X / r),
    t1  = arccos((L1^2 + r^2 - L2^2) / (2 L1 r)) + t_T,
    cos(180 deg - t2) = (L1^2 + L2^2 - r^2) / (2 L1 L2).

The arccos of the last right-hand side is the interior angle a = 180 deg - |t2| between
the links. On the branch where t1 adds the arccos the joint angle is t2 = -(180 deg - a);
the other branch subtracts it and has t2 = +(180 deg - a). (The slide's closing line
``t2 = arccos(...)`` is a itself, the ``180 deg -`` dropped.) Here the same solutions are
computed with atan2, which is equivalent but holds where arccos does not:

- t_T = atan2(Y, X) equals arccos(X / r) only for Y >= 0 (arccos never returns a negative
  angle) and is defined at r = 0;
- cos(t2) = (r^2 - L1^2 - L2^2) / (2 L1 L2) = c2 is the slide's third line (cos(180 deg - a)
  = -cos a), and sin(t2) = +-s2 with s2 = sqrt(((L1 + L2)^2 - r^2)(r^2 - (L1 - L2)^2)) /
  (2 L1 L2) = sqrt(1 - c2^2) written as a product, so no cancellation near the boundary
  where arccos loses half the digits;
- t1 = atan2(k1 Y - k2 X, k1 X + k2 Y) with k1 = L1 + L2 c2 and k2 = L2 sin(t2) solves
  [k1 -k2; k2 k1] [cos t1; sin t1] = [X; Y], i.e. t1 = t_T - atan2(k2, k1), the slide's
  t_T +- arccos(...) by the law of cosines.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TwoLinkIK:
    """Both elbow solutions of a batch of B targets.

    Attributes
    ----------
    q : (B, 2, 2) ndarray
        [branch, joint] angles [rad]; branch 0 has t2 >= 0 (elbow counter-clockwise),
        branch 1 has t2 <= 0. For an unreachable target both reach ``reached_xy``.
    reachable : (B,) bool ndarray
        |L1 - L2| <= r <= L1 + L2.
    reached_xy : (B, 2) ndarray
        The target where reachable, else the nearest reachable point [m] (on the outer
        circle, or on the inner circle along the target direction; along +x for a target
        exactly at the origin).
    """

    q: np.ndarray
    reachable: np.ndarray
    reached_xy: np.ndarray


def two_link_fk(l1: float, l2: float, q: np.ndarray) -> np.ndarray:
    """End point of the arm [m]. (..., 2) joint angles [rad] -> (..., 2)."""
    q = np.asarray(q, dtype=float)
    t1, t12 = q[..., 0], q[..., 0] + q[..., 1]
    return np.stack([l1 * np.cos(t1) + l2 * np.cos(t12), l1 * np.sin(t1) + l2 * np.sin(t12)], axis=-1)


def two_link_ik(l1: float, l2: float, target_xy: np.ndarray) -> TwoLinkIK:
    """Analytic IK of the planar two-link arm (see the module docstring).

    Parameters
    ----------
    l1, l2 : float
        Link lengths [m], > 0.
    target_xy : (B, 2) ndarray
        End-point targets [m].

    Returns
    -------
    TwoLinkIK
    """
    if not (np.isfinite(l1) and np.isfinite(l2) and l1 > 0 and l2 > 0):
        raise ValueError(f"link lengths must be finite and positive, got {l1}, {l2}")
    target = np.asarray(target_xy, dtype=float)
    if target.ndim != 2 or target.shape[1] != 2 or not np.all(np.isfinite(target)):
        raise ValueError(f"target_xy must be a finite (B, 2) array, got shape {target.shape}")
    r = np.hypot(target[:, 0], target[:, 1])
    outer, inner = l1 + l2, abs(l1 - l2)
    reachable = (r <= outer) & (r >= inner)
    radius = np.clip(r, inner, outer)
    direction = np.where(r[:, None] > 0, target / np.where(r > 0, r, 1.0)[:, None], [1.0, 0.0])
    reached = np.where(reachable[:, None], target, radius[:, None] * direction)
    x, y, rr = reached[:, 0], reached[:, 1], radius * radius

    c2 = (rr - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    s2 = np.sqrt(np.maximum((outer * outer - rr) * (rr - inner * inner), 0.0)) / (2 * l1 * l2)
    q = np.empty((len(r), 2, 2))
    for branch, sign in enumerate((1.0, -1.0)):
        k1, k2 = l1 + l2 * c2, l2 * sign * s2
        q[:, branch, 0] = np.arctan2(k1 * y - k2 * x, k1 * x + k2 * y)
        q[:, branch, 1] = np.arctan2(sign * s2, c2)
    return TwoLinkIK(q=q, reachable=reachable, reached_xy=reached)
