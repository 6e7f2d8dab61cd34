"""External forces of a scene as a wrench function (the lecture's "Forces")."""

from __future__ import annotations

import numpy as np

from core.rigid_body import MassProperties, Wrench
from core.scene import Forces


def make_wrench(forces: Forces, props: MassProperties) -> Wrench:
    """Total force and torque about each COM, f(t, x, R, v, omega) -> (F, tau), each (B, 3).

    Gravity: F = M g, no torque. Forces absent from the scene contribute nothing.
    """
    gravity_force = (
        np.zeros((len(props.mass), 3))
        if forces.gravity_world is None
        else props.mass[:, None] * forces.gravity_world[None, :]
    )

    def wrench(t, x, rotation, v, omega):
        return gravity_force, np.zeros_like(gravity_force)

    return wrench


def has_torque(forces: Forces) -> bool:
    """True when some force of the scene can exert a torque about a body's COM."""
    return False
