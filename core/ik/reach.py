"""An upper bound on how far a chain's end effector can be from its first joint."""

from __future__ import annotations

import numpy as np

from simparity.core.model.scenes.chain import Chain


def reach_upper_bound(chain: Chain) -> tuple[np.ndarray, float]:
    """Centre and radius of a ball that holds every end-effector position.

    The first joint's frame origin is fixed in the world. Every later joint origin and
    the end-effector origin sit at a fixed offset in the previous link frame, and a
    prismatic joint adds at most max(|lower|, |upper|) along its axis, so by the triangle
    inequality |E - O_1| <= sum_{i >= 2} |origin_xyz_i| + |end_effector_xyz| +
    sum_prismatic max(|lower_i|, |upper_i|). The bound is attained when all those
    offsets can be aligned (e.g. the KUKA iiwa stretched straight up); otherwise the true
    reach is smaller. It is infinite with an unlimited prismatic joint.

    Returns
    -------
    center_world : (3,) ndarray
        The first joint's origin [m].
    radius : float
        [m].
    """
    offsets = sum(float(np.linalg.norm(j.origin_xyz)) for j in chain.joints[1:])
    offsets += float(np.linalg.norm(chain.end_effector_xyz))
    travel = sum(max(abs(j.lower), abs(j.upper)) for j in chain.joints if j.type == "prismatic")
    return np.array(chain.joints[0].origin_xyz), offsets + travel
