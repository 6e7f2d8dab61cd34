"""The references' own drag and applied-force code against numbers computed by hand (tests/helpers.py)."""

import numpy as np

from simparity.references.common import external_forces
from simparity.references.common.conventions import quat_wxyz_to_matrix
from tests.helpers import HAND_WRENCH, hand_wrench_forces

HAND_TOL = 1e-14  # the hand values are written to 15 digits


def test_drag_applied_and_weight_sum_to_the_hand_computed_wrench():
    """Drag in wind + applied force + weight, and angular drags + the applied force's torque, by hand."""
    h, forces = HAND_WRENCH, hand_wrench_forces()
    rotation = quat_wxyz_to_matrix(np.array(h["quat_wxyz"]))[None]
    applied_force, applied_torque = external_forces.applied_wrench_world(forces, rotation)
    force = (h["mass"] * np.array(h["gravity"]) + applied_force[0]
             + external_forces.drag_force_world(forces, np.array([h["velocity"]]))[0])
    torque = applied_torque[0] + external_forces.drag_torque_world(forces, np.array([h["omega"]]))[0]
    np.testing.assert_allclose(force, h["expected_force"], rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(torque, h["expected_torque"], rtol=0, atol=HAND_TOL)


def test_which_drags_a_scene_has():
    """has_drag / has_angular_drag follow the scene's coefficients."""
    forces = hand_wrench_forces()
    assert external_forces.has_drag(forces) and external_forces.has_angular_drag(forces)
    assert not external_forces.has_drag(type(forces)(gravity_world=np.zeros(3)))
