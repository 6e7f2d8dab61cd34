"""Pinocchio's joint-space mass matrix, whole: ``crba``'s upper triangle mirrored into the lower one."""

from __future__ import annotations

import numpy as np
import pinocchio as pin


def mass_matrix(model: pin.Model, data: pin.Data, configuration: np.ndarray) -> np.ndarray:
    """M (nv, nv) at Pinocchio's ``configuration`` (nq,), armature included: ``crba`` (4.1 fills both triangles; the
    strict lower one is taken from the upper all the same, as the documentation promises only the upper)."""
    upper = np.triu(pin.crba(model, data, configuration))
    return upper + np.triu(upper, 1).T
