"""Joint values in Pinocchio's configuration vector: a continuous joint is two numbers there, (cos q, sin q)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def configuration(model: pin.Model, idx_q: list[int], continuous: list[bool], q_row: np.ndarray) -> np.ndarray:
    """Pinocchio configuration (nq,) of ``model`` with the chain's joint values ``q_row`` (n,) [rad or m] at
    ``idx_q``: (cos, sin) for the ``continuous`` ones, the neutral configuration elsewhere (held joints)."""
    q = pin.neutral(model)
    for value, at, is_continuous in zip(q_row, idx_q, continuous):
        if is_continuous:
            q[at], q[at + 1] = np.cos(value), np.sin(value)
        else:
            q[at] = value
    return q
