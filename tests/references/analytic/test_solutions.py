"""Closed-form ground truths (references.analytic.solutions) against tight numerical solves."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from simparity.core.dynamics.inertia import inertia_solid_box
from simparity.core.rotations import (
    geodesic_angle_quat_wxyz,
    quat_wxyz_multiply,
    quat_wxyz_normalize,
    quat_wxyz_to_matrix,
)
from simparity.comparisons.measure.invariants import angular_momentum_world, kinetic_energy
from simparity.references.analytic.solutions import (
    intermediate_axis_flip_period,
    linear_angular_drag_isotropic,
    linear_drag,
    projectile,
    quadratic_drag_along_line,
    torque_free_asymmetric,
    torque_free_axisymmetric,
)

# rtol = atol of the DOP853 reference solves: about the tightest SciPy accepts.
ODE_TOL = 1e-13

# Closed form vs DOP853, relative to the state's scale: the solve's own error over a few
# hundred to a few thousand steps at ODE_TOL is ~1e-12.
TRANSLATION_RTOL = 1e-11

# Rotation vs DOP853 over 10 s [rad for orientation, relative to |omega| for omega]: the
# float64 solve loses ~5e-11 to round-off near the Gazebo box's separatrix (m = 1 - 1.4e-4),
# while the closed form agrees with an extended-precision solve to ~2e-14 (see below).
ROTATION_TOL = 2e-10

# Closed form vs the extended-precision (80-bit) DOP853 solve: the brief's accuracy target
# for the Gazebo box, omega to 1e-13 relative, orientation to 1e-11 rad over 10 s.
OMEGA_TARGET_RTOL = 1e-13
ORIENTATION_TARGET = 1e-11

# omega_body(0) against the input, relative to |omega0|: phase inversion then forward
# evaluation, each a few roundings (measured <= 2.5e-16).
REPRODUCE_RTOL = 1e-15

# Energy and angular momentum along a closed form, relative: a few roundings per sample.
INVARIANT_RTOL = 1e-13

# Flip period vs the spacing of sign changes located by DOP853's dense-output events.
PERIOD_RTOL = 1e-9

# The Gazebo box of the Dzhanibekov demo: 10 kg, 0.1 x 0.4 x 0.9 m, spun near its y axis.
GAZEBO_INERTIA = np.diag(inertia_solid_box(10.0, [0.1, 0.4, 0.9])).copy()
GAZEBO_OMEGA = np.array([0.1, 5.0, 0.1])


def _solve(rhs, y0: np.ndarray, times: np.ndarray, **kwargs):
    return solve_ivp(
        rhs, (times[0], times[-1]), y0, method="DOP853", rtol=ODE_TOL, atol=ODE_TOL, t_eval=times, **kwargs
    )


def _pure(v: np.ndarray) -> np.ndarray:
    """(..., 3) -> (..., 4) pure quaternion (0, v)."""
    return np.concatenate([np.zeros(v.shape[:-1] + (1,)), v], axis=-1)


def _euler_rhs(inertia: np.ndarray):
    """d/dt (omega_body, q) of a torque-free body: Euler's equations and q' = q (0, omega_b) / 2."""

    def rhs(t, y):
        w = y[:3]
        return np.concatenate([np.cross(inertia * w, w) / inertia, 0.5 * quat_wxyz_multiply(y[3:], _pure(w))])

    return rhs


def _random_quat(rng: np.random.Generator) -> np.ndarray:
    return quat_wxyz_normalize(rng.normal(size=4))


def _assert_rotation_close(quat, omega_body, reference, scale: float, tol: float = ROTATION_TOL):
    """Orientation within tol [rad] and omega_body within tol * scale of a (T, 7) reference."""
    assert np.abs(omega_body - reference[:, :3]).max() <= tol * scale
    assert geodesic_angle_quat_wxyz(quat, reference[:, 3:]).max() <= tol


def test_projectile_matches_numerical():
    """Projectile position and velocity equal a DOP853 solve of x'' = g."""
    x0, v0, g = np.array([1.0, -2.0, 3.0]), np.array([4.0, 0.5, 9.0]), np.array([0.0, 0.0, -9.81])
    times = np.linspace(0.0, 3.0, 61)
    ref = _solve(lambda t, y: np.concatenate([y[3:], g]), np.concatenate([x0, v0]), times).y.T
    position, velocity = projectile(x0, v0, g, times)
    np.testing.assert_allclose(position, ref[:, :3], atol=TRANSLATION_RTOL * np.abs(ref[:, :3]).max())
    np.testing.assert_allclose(velocity, ref[:, 3:], atol=TRANSLATION_RTOL * np.abs(ref[:, 3:]).max())


@pytest.mark.parametrize("k", [0.0, 1e-9, 0.3, 5.0])
def test_linear_drag_matches_numerical(k):
    """Linear drag in moving air equals a DOP853 solve of v' = g - k (v - w), also for k -> 0."""
    x0, v0 = np.array([0.0, 1.0, 2.0]), np.array([3.0, -1.0, 8.0])
    g, w = np.array([0.0, 0.0, -9.81]), np.array([2.0, 1.0, 0.0])
    times = np.linspace(0.0, 4.0, 81)
    rhs = lambda t, y: np.concatenate([y[3:], g - k * (y[3:] - w)])  # noqa: E731
    ref = _solve(rhs, np.concatenate([x0, v0]), times).y.T
    position, velocity = linear_drag(x0, v0, g, k, times, air_velocity=w)
    np.testing.assert_allclose(position, ref[:, :3], atol=TRANSLATION_RTOL * np.abs(ref[:, :3]).max())
    np.testing.assert_allclose(velocity, ref[:, 3:], atol=TRANSLATION_RTOL * np.abs(ref[:, 3:]).max())


@pytest.mark.parametrize(
    "v0, g",
    [
        ([0.0, 0.0, 30.0], [0.0, 0.0, -9.81]),  # thrown up: tan phase, apex, tanh phase
        ([0.0, 0.0, 0.0], [0.0, 0.0, -9.81]),  # dropped from rest
        ([0.0, -60.0, 0.0], [0.0, -9.81, 0.0]),  # faster than terminal speed: coth
        ([3.0, -4.0, 12.0], [0.0, 0.0, 0.0]),  # no gravity, any direction
    ],
)
def test_quadratic_drag_matches_numerical(v0, g):
    """Quadratic drag along the line of gravity equals a DOP853 solve of v' = g - c |v| v."""
    x0, v0, g, c = np.array([1.0, 2.0, 3.0]), np.array(v0), np.array(g), 0.02
    times = np.linspace(0.0, 8.0, 161)
    rhs = lambda t, y: np.concatenate([y[3:], g - c * np.linalg.norm(y[3:]) * y[3:]])  # noqa: E731
    ref = _solve(rhs, np.concatenate([x0, v0]), times).y.T
    position, velocity = quadratic_drag_along_line(x0, v0, g, c, times)
    np.testing.assert_allclose(position, ref[:, :3], atol=TRANSLATION_RTOL * np.abs(ref[:, :3]).max())
    np.testing.assert_allclose(velocity, ref[:, 3:], atol=TRANSLATION_RTOL * np.abs(ref[:, 3:]).max())


def test_quadratic_drag_rejects_velocity_off_the_line():
    """A velocity not parallel to gravity has no closed form and raises ValueError."""
    with pytest.raises(ValueError, match="parallel to gravity"):
        quadratic_drag_along_line(np.zeros(3), [1.0, 0.0, 5.0], [0.0, 0.0, -9.81], 0.1, np.linspace(0, 1, 5))


def test_isotropic_angular_drag_matches_numerical():
    """omega0 e^{-ct/I} about a fixed axis equals a DOP853 solve of L' = -c omega, q' = (0, omega) q / 2."""
    rng = np.random.default_rng(10)
    inertia, drag, omega0, q0 = 0.4, 0.3, rng.normal(size=3) * 3, _random_quat(rng)
    times = np.linspace(0.0, 5.0, 101)

    def rhs(t, y):
        omega = y[:3] / inertia
        return np.concatenate([-drag * omega, 0.5 * quat_wxyz_multiply(_pure(omega), y[3:])])

    ref = _solve(rhs, np.concatenate([inertia * omega0, q0]), times).y.T
    quat, omega_world, omega_body = linear_angular_drag_isotropic(inertia, drag, omega0, q0, times)
    scale = np.linalg.norm(omega0)
    assert np.abs(omega_world - ref[:, :3] / inertia).max() <= ROTATION_TOL * scale
    assert geodesic_angle_quat_wxyz(quat, ref[:, 3:]).max() <= ROTATION_TOL
    body = np.einsum("tij,ti->tj", quat_wxyz_to_matrix(quat), omega_world)
    np.testing.assert_allclose(body, omega_body, atol=INVARIANT_RTOL * scale)


@pytest.mark.slow
def test_axisymmetric_matches_numerical():
    """Steady precession of a symmetric top equals a DOP853 solve of Euler's equations."""
    rng = np.random.default_rng(11)
    inertia, omega0, q0 = np.array([0.5, 0.5, 0.2]), np.array([1.5, -0.7, 6.0]), _random_quat(rng)
    times = np.linspace(0.0, 10.0, 201)
    ref = _solve(_euler_rhs(inertia), np.concatenate([omega0, q0]), times).y.T
    quat, _, omega_body = torque_free_axisymmetric(inertia, omega0, q0, times)
    _assert_rotation_close(quat, omega_body, ref, np.linalg.norm(omega0))


def test_axisymmetric_rejects_unequal_moments():
    """I1 != I2 raises ValueError."""
    with pytest.raises(ValueError, match="I1 == I2"):
        torque_free_axisymmetric([1.0, 1.1, 2.0], [1.0, 0.0, 1.0], [1.0, 0, 0, 0], [0.0, 1.0])


ASYMMETRIC_CASES = {
    "gazebo box near intermediate axis": (GAZEBO_INERTIA, GAZEBO_OMEGA, 10.0),
    "near minor axis, moments unsorted": (np.array([0.9, 0.2, 0.5]), np.array([0.4, -6.0, 0.3]), 10.0),
    "near major axis, negative spin": (np.array([1.0, 2.0, 3.0]), np.array([0.5, -0.8, -2.0]), 10.0),
    "1e-7 from the intermediate axis": (np.array([1.0, 2.0, 3.0]), np.array([1e-7, 1.0, 0.0]), 10.0),
    # I = (2, 3, 6), omega = (3, w2, 1) has L^2 = 2 E I2 exactly; the saddle it approaches
    # makes any solve diverge, so the horizon is short.
    "on the separatrix": (np.array([2.0, 3.0, 6.0]), np.array([-3.0, 0.5, 1.0]), 3.0),
    "spin about the intermediate axis": (np.array([1.0, 2.0, 3.0]), np.array([0.0, -2.0, 0.0]), 10.0),
}


@pytest.mark.slow
@pytest.mark.parametrize("inertia, omega0, duration", ASYMMETRIC_CASES.values(), ids=ASYMMETRIC_CASES.keys())
def test_asymmetric_matches_numerical(inertia, omega0, duration):
    """Elliptic functions + quadrature equal a DOP853 solve; the quaternion has no sign jumps."""
    q0 = _random_quat(np.random.default_rng(12))
    times = np.linspace(0.0, duration, 1001)
    ref = _solve(_euler_rhs(inertia), np.concatenate([omega0, q0]), times).y.T
    quat, omega_world, omega_body = torque_free_asymmetric(inertia, omega0, q0, times)
    _assert_rotation_close(quat, omega_body, ref, np.linalg.norm(omega0))
    scale = np.linalg.norm(omega0)
    assert np.linalg.norm(np.diff(quat, axis=0), axis=1).max() < scale * (times[1] - times[0])
    world = np.einsum("tij,tj->ti", quat_wxyz_to_matrix(quat), omega_body)
    np.testing.assert_allclose(world, omega_world, atol=INVARIANT_RTOL * scale)


def _dop853_fixed_step_extended(rhs, y0: np.ndarray, duration: float, n_steps: int, every: int) -> np.ndarray:
    """Fixed-step DOP853 (SciPy's 12-stage tableau) in np.longdouble; states every ``every`` steps."""
    tableau = pytest.importorskip("scipy.integrate._ivp.dop853_coefficients")  # private SciPy module
    a = tableau.A[:12, :12].astype(np.longdouble)
    b = tableau.B.astype(np.longdouble)
    h = np.longdouble(duration) / n_steps
    y = y0.astype(np.longdouble)
    out = [y]
    for i in range(n_steps):
        k: list[np.ndarray] = []
        for s in range(12):
            k.append(rhs(y + h * sum((a[s, j] * k[j] for j in range(s)), np.zeros_like(y))))
        y = y + h * sum(b[j] * k[j] for j in range(12))
        if (i + 1) % every == 0:
            out.append(y)
    return np.array(out)


@pytest.mark.slow
@pytest.mark.skipif(np.finfo(np.longdouble).eps > 1e-18, reason="np.longdouble is not extended here")
def test_asymmetric_meets_accuracy_target_for_gazebo_box():
    """Gazebo box over 10 s against an 80-bit solve: omega to 1e-13 relative, orientation to 1e-11 rad."""
    inertia = GAZEBO_INERTIA.astype(np.longdouble)

    def rhs(y):
        w, q = y[:3], y[3:]
        iw = inertia * w
        dw = np.array([iw[1] * w[2] - iw[2] * w[1], iw[2] * w[0] - iw[0] * w[2], iw[0] * w[1] - iw[1] * w[0]])
        dq = 0.5 * np.array([
            -q[1] * w[0] - q[2] * w[1] - q[3] * w[2],
            q[0] * w[0] + q[2] * w[2] - q[3] * w[1],
            q[0] * w[1] + q[3] * w[0] - q[1] * w[2],
            q[0] * w[2] + q[1] * w[1] - q[2] * w[0],
        ])
        return np.concatenate([dw / inertia, dq])

    q0 = _random_quat(np.random.default_rng(13))
    ref = _dop853_fixed_step_extended(rhs, np.concatenate([GAZEBO_OMEGA, q0]), 10.0, 2000, 50).astype(float)
    quat, _, omega_body = torque_free_asymmetric(GAZEBO_INERTIA, GAZEBO_OMEGA, q0, np.linspace(0.0, 10.0, 41))
    assert np.abs(omega_body - ref[:, :3]).max() <= OMEGA_TARGET_RTOL * np.linalg.norm(GAZEBO_OMEGA)
    assert geodesic_angle_quat_wxyz(quat, ref[:, 3:]).max() <= ORIENTATION_TARGET


@pytest.mark.slow
def test_asymmetric_reproduces_initial_omega_in_both_regimes():
    """omega_body(0) equals the input for seeded random moments, signs and both sides of the separatrix."""
    rng = np.random.default_rng(14)
    regimes = set()
    for _ in range(200):
        inertia = rng.uniform(0.1, 2.0, 3)
        omega0 = rng.normal(size=3) * rng.uniform(0.1, 10.0)
        mid = np.sort(inertia)[1]
        regimes.add(np.sum((inertia * omega0) ** 2) > np.sum(inertia * omega0**2) * mid)
        _, _, omega_body = torque_free_asymmetric(inertia, omega0, _random_quat(rng), [0.0])
        assert np.abs(omega_body[0] - omega0).max() <= REPRODUCE_RTOL * np.linalg.norm(omega0)
    assert regimes == {True, False}


@pytest.mark.slow
@pytest.mark.parametrize(
    "inertia, omega0",
    [(GAZEBO_INERTIA, GAZEBO_OMEGA), (np.array([3.0, 1.0, 2.0]), np.array([0.2, 4.0, -0.5]))],
    ids=["gazebo box", "near minor axis"],
)
def test_flip_period_matches_sign_changes(inertia, omega0):
    """The period equals the spacing of every other sign change of the flipping component (DOP853 events)."""
    flipping = int(np.argsort(inertia)[1])
    period = intermediate_axis_flip_period(inertia, omega0)

    def crossing(t, y):
        return y[flipping]

    times = np.array([0.0, 2.5 * period])
    sol = _solve(_euler_rhs(inertia), np.concatenate([omega0, [1.0, 0.0, 0.0, 0.0]]), times, events=crossing)
    flips = sol.t_events[0]
    assert len(flips) >= 4
    np.testing.assert_allclose(flips[2:] - flips[:-2], period, rtol=PERIOD_RTOL)


def test_flip_period_is_infinite_without_a_flip():
    """On the separatrix and for a spin about one axis there is no period (inf)."""
    assert intermediate_axis_flip_period([2.0, 3.0, 6.0], [3.0, 0.5, 1.0]) == np.inf
    assert intermediate_axis_flip_period([1.0, 2.0, 3.0], [0.0, 0.0, 4.0]) == np.inf


def test_asymmetric_rejects_equal_moments():
    """Two equal principal moments raise ValueError (use the axisymmetric closed form)."""
    with pytest.raises(ValueError, match="distinct"):
        torque_free_asymmetric([1.0, 1.0, 2.0], [1.0, 0.5, 1.0], [1.0, 0, 0, 0], [0.0])


def test_invariants_are_constant_along_closed_forms():
    """Energy and world angular momentum stay constant along torque-free closed forms and the projectile."""
    rng = np.random.default_rng(15)
    times = np.linspace(0.0, 20.0, 401)
    cases = [
        (torque_free_asymmetric, GAZEBO_INERTIA, GAZEBO_OMEGA),
        (torque_free_asymmetric, np.array([0.9, 0.2, 0.5]), np.array([0.4, -6.0, 0.3])),
        (torque_free_axisymmetric, np.array([0.5, 0.5, 0.2]), np.array([1.5, -0.7, 6.0])),
    ]
    for closed_form, inertia, omega0 in cases:
        quat, omega_world, _ = closed_form(inertia, omega0, _random_quat(rng), times)
        rotation = quat_wxyz_to_matrix(quat)
        energy = kinetic_energy(2.0, np.diag(inertia), np.zeros(3), omega_world, rotation)
        momentum = angular_momentum_world(np.diag(inertia), omega_world, rotation)
        np.testing.assert_allclose(energy, energy[0], rtol=INVARIANT_RTOL)
        scale = np.linalg.norm(momentum[0])
        np.testing.assert_allclose(momentum - momentum[0], 0.0, atol=INVARIANT_RTOL * scale)
    g, mass = np.array([0.0, 0.0, -9.81]), 3.0
    position, velocity = projectile([0.0, 0.0, 1.0], [2.0, 1.0, 15.0], g, times)
    energy = kinetic_energy(mass, np.eye(3), velocity, np.zeros(3), np.eye(3)) - mass * position @ g
    np.testing.assert_allclose(energy, energy[0], rtol=INVARIANT_RTOL)


def test_energy_and_momentum_of_a_rotated_spin():
    """A turned 3 kg body at 1 m/s spinning 2 rad/s about body y (I_yy = 2): E = 4 + 1.5 J, L = R (0, 4, 0)."""
    rotation = quat_wxyz_to_matrix(_random_quat(np.random.default_rng(16)))[None].repeat(2, axis=0)
    inertia = np.diag([1.0, 2.0, 3.0])
    omega_world = rotation @ [0.0, 2.0, 0.0]
    velocity = np.array([[1.0, 0.0, 0.0], [0.0, 0.6, 0.8]])
    energy = kinetic_energy(np.full(2, 3.0), inertia, velocity, omega_world, rotation)
    np.testing.assert_allclose(energy, [5.5, 5.5], rtol=INVARIANT_RTOL)
    momentum = angular_momentum_world(inertia, omega_world, rotation)
    np.testing.assert_allclose(momentum, rotation @ [0.0, 4.0, 0.0], atol=INVARIANT_RTOL)
