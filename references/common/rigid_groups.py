"""Rigid groups summed from an engine's bodies, with the references' own code (a reference never borrows core's).

An engine that keeps the links welded by fixed joints as bodies of their own (MuJoCo without ``fusestatic``,
PyBullet always) reports each body; the group of a chain joint is the bodies whose nearest moving joint up the tree
is that joint. Their sum: M = sum m_k, c = sum m_k c_k / M, I = sum R_k I_k R_k^T + m_k (|r_k|^2 E - r_k r_k^T) with
r_k = c_k - c (Steiner's theorem), all in base-frame axes. A massless group has its centre of mass at the joint's
origin (nothing to weigh it elsewhere).
"""

from __future__ import annotations

import numpy as np


def summed(masses: np.ndarray, coms_world: np.ndarray, inertias_world: np.ndarray,
           origin_world: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """(M, c (3,), I about c (3, 3)) of bodies (K,), (K, 3), (K, 3, 3) [kg, m, kg m^2], all world axes."""
    total = float(np.sum(masses))
    if total <= 0:
        return 0.0, np.asarray(origin_world, dtype=float), np.sum(inertias_world, axis=0) if len(masses) else \
            np.zeros((3, 3))
    com = np.einsum("k,ki->i", masses, coms_world) / total
    r = coms_world - com
    steiner = masses[:, None, None] * (np.einsum("ki,ki->k", r, r)[:, None, None] * np.eye(3)
                                       - np.einsum("ki,kj->kij", r, r))
    return total, com, np.sum(inertias_world + steiner, axis=0)
