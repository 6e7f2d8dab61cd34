"""Core's wrench against numbers computed by hand (tests/helpers.py HAND_WRENCH)."""

import numpy as np

from simparity.core.dynamics.forces import make_wrench, without_gravity
from simparity.core.dynamics.rigid_body import MassProperties
from simparity.core.rotations import quat_wxyz_to_matrix
from simparity.core.model.scenes.bodies import AppliedForce, Forces, RigidBody
from tests.helpers import HAND_WRENCH, hand_wrench_forces

HAND_TOL = 1e-14  # the hand values are written to 15 digits


def _props():
    h = HAND_WRENCH
    return MassProperties.of((RigidBody("b", h["mass"], np.diag([0.1, 0.2, 0.3]), np.zeros(3), h["quat_wxyz"],
                                        h["velocity"], h["omega"]),))


def test_no_forces_means_zero_wrench():
    """A scene without forces pushes nothing."""
    force, torque = make_wrench(Forces(), _props())(0.0, np.zeros((1, 3)), np.eye(3)[None], np.ones((1, 3)),
                                                    np.ones((1, 3)))
    assert not force.any() and not torque.any()


def test_every_term_against_the_hand_computed_wrench():
    """Gravity, drag in wind, quadratic drag, angular drags and a force at a body point, summed by hand."""
    h = HAND_WRENCH
    rotation = quat_wxyz_to_matrix(np.array(h["quat_wxyz"]))[None]
    force, torque = make_wrench(hand_wrench_forces(), _props())(
        0.0, np.zeros((1, 3)), rotation, np.array([h["velocity"]]), np.array([h["omega"]]))
    np.testing.assert_allclose(force[0], h["expected_force"], rtol=0, atol=HAND_TOL)
    np.testing.assert_allclose(torque[0], h["expected_torque"], rtol=0, atol=HAND_TOL)


def test_the_lever_turns_with_the_body():
    """Unturned, the same force at (0.5, 0, 0) has no torque (lever parallel to the force)."""
    pushed = Forces(applied=(AppliedForce(0, [1.0, 0.0, 0.0], [0.5, 0.0, 0.0]),))
    _, torque = make_wrench(pushed, _props())(0.0, np.zeros((1, 3)), np.eye(3)[None], np.zeros((1, 3)),
                                              np.zeros((1, 3)))
    np.testing.assert_allclose(torque, 0.0, atol=HAND_TOL)


def test_conservation_flags_and_names():
    """Gravity alone conserves energy and L; linear drag only energy is lost; applied forces exert torque."""
    gravity = Forces(np.array([0, 0, -9.81]))
    assert gravity.conserves_energy and gravity.conserves_angular_momentum and gravity.names() == ("gravity",)
    drag = Forces(np.array([0, 0, -9.81]), linear_drag=np.array([0.1]))
    assert not drag.conserves_energy and drag.conserves_angular_momentum
    pushed = Forces(applied=(AppliedForce(0, [1, 0, 0], [0, 1, 0]),))
    assert pushed.exerts_torque and not pushed.conserves_angular_momentum
    assert without_gravity(drag).names() == ("linear_drag",)
