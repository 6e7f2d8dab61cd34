"""The scene's forces as a wrench: each term as the lecture writes it, absent terms absent."""

import numpy as np

from simparity.core.forces import make_wrench, without_gravity
from simparity.core.rigid_body import MassProperties
from simparity.core.rotations import so3_exp
from simparity.core.scene import AppliedForce, Forces
from tests.helpers import tumbling_box

EXACT_TOL = 1e-15  # the same few float64 operations on both sides


def _props(n=2):
    bodies = tumbling_box().bodies * n
    return MassProperties.of(bodies)


def _state(rng, n=2):
    return (rng.normal(size=(n, 3)), so3_exp(rng.normal(size=(n, 3))), rng.normal(size=(n, 3)),
            rng.normal(size=(n, 3)))


def test_no_forces_means_zero_wrench():
    """A scene without forces pushes nothing."""
    x, r, v, w = _state(np.random.default_rng(1))
    force, torque = make_wrench(Forces(), _props())(0.0, x, r, v, w)
    assert not force.any() and not torque.any()


def test_each_term_is_the_lectures():
    """F = M g - b (v - w) - c |v - w| (v - w) + f; tau = -k omega - kq |omega| omega + (R p) x f."""
    rng = np.random.default_rng(2)
    x, r, v, w = _state(rng)
    g, air = np.array([0, 0, -9.81]), np.array([1.0, 2.0, 0.0])
    b, c, k, kq = np.array([0.5, 0.0]), np.array([0.1, 0.2]), np.array([0.0, 0.03]), np.array([0.01, 0.0])
    f, p = np.array([0.0, 1.0, 2.0]), np.array([0.1, -0.2, 0.3])
    forces = Forces(g, air, b, c, k, kq, (AppliedForce(1, f, p),))
    props = _props()
    force, torque = make_wrench(forces, props)(0.0, x, r, v, w)
    rel = v - air
    expected_force = (props.mass[:, None] * g - b[:, None] * rel
                      - c[:, None] * np.linalg.norm(rel, axis=1, keepdims=True) * rel)
    expected_force[1] += f
    expected_torque = -k[:, None] * w - kq[:, None] * np.linalg.norm(w, axis=1, keepdims=True) * w
    expected_torque[1] += np.cross(r[1] @ p, f)
    np.testing.assert_allclose(force, expected_force, atol=EXACT_TOL)
    np.testing.assert_allclose(torque, expected_torque, atol=EXACT_TOL)


def test_conservation_flags_and_names():
    """Gravity alone conserves energy and L; linear drag only energy is lost; applied forces exert torque."""
    gravity = Forces(np.array([0, 0, -9.81]))
    assert gravity.conserves_energy and gravity.conserves_angular_momentum and gravity.names() == ("gravity",)
    drag = Forces(np.array([0, 0, -9.81]), linear_drag=np.array([0.1]))
    assert not drag.conserves_energy and drag.conserves_angular_momentum
    pushed = Forces(applied=(AppliedForce(0, [1, 0, 0], [0, 1, 0]),))
    assert pushed.exerts_torque and not pushed.conserves_angular_momentum
    assert without_gravity(drag).names() == ("linear_drag",)
