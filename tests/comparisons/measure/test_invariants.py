"""Energy and angular momentum of rigid bodies."""

import numpy as np

from simparity.comparisons.measure.invariants import angular_momentum_world, kinetic_energy, potential_energy
from simparity.core.rotations import so3_exp

EXACT_TOL = 1e-14


def test_values_by_hand():
    """A 2 kg body at 3 m/s spinning at 2 rad/s about a 0.5 kg m^2 principal axis: E = 9 + 1 J, L = 1."""
    inertia = np.diag([0.5, 0.7, 0.9])
    energy = kinetic_energy(2.0, inertia, np.array([3.0, 0, 0]), np.array([2.0, 0, 0]), np.eye(3))
    np.testing.assert_allclose(energy, 10.0, atol=EXACT_TOL)
    np.testing.assert_allclose(angular_momentum_world(inertia, np.array([2.0, 0, 0]), np.eye(3)), [1.0, 0, 0])
    np.testing.assert_allclose(potential_energy(2.0, np.array([0, 0, -9.81]), np.array([0, 0, 1.0])), 19.62)


def test_frame_independence():
    """Rotating body and angular velocity together leaves E unchanged and rotates L."""
    rng = np.random.default_rng(5)
    inertia, omega_body = np.diag([0.1, 0.2, 0.3]), rng.normal(size=3)
    r = so3_exp(rng.normal(size=(10, 3)))
    omega_world = r @ omega_body
    energy = kinetic_energy(1.0, inertia, np.zeros(3), omega_world, r)
    np.testing.assert_allclose(energy, 0.5 * omega_body @ inertia @ omega_body, atol=EXACT_TOL)
    np.testing.assert_allclose(angular_momentum_world(inertia, omega_world, r), r @ (inertia @ omega_body),
                               atol=EXACT_TOL)
