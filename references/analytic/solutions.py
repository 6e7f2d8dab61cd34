"""Closed-form ground truths of free-body motion, as pure functions of time.

Every function takes the sample times ``times`` (T,) [s], measured from the initial state,
and returns arrays with a leading T axis. SI units, float64; quaternions (w, x, y, z),
body to world; angular velocities in the world frame unless the name ends in ``_body``.

Translation: :func:`projectile`, :func:`linear_drag`, :func:`quadratic_drag_along_line`.
Rotation: :func:`linear_angular_drag_isotropic`, :func:`torque_free_axisymmetric`,
:func:`torque_free_asymmetric` (Jacobi elliptic functions + quadrature) and
:func:`intermediate_axis_flip_period`. Rotations are SciPy's (:mod:`simparity.references.common.conventions`), not core's.

Over 600 lines: the asymmetric torque-free solution alone (Jacobi elliptic functions by the Landen ladder,
the precession quadrature, the Euler-angle assembly) is half the module, and the other closed forms share its
helpers.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy.special import ellipkinc, exprel

from simparity.references.common.conventions import (
    matrix_to_quat_wxyz,
    quat_wxyz_conjugate,
    quat_wxyz_from_rotvec,
    quat_wxyz_multiply,
    quat_wxyz_to_matrix,
)

# |x| below which (e^x - 1 - x) / x^2 is summed as a series: 20 terms leave a truncation
# error ~0.5^20 / 22! ~ 1e-27, and above it the direct form loses < 1e-15 to cancellation.
_SERIES_BELOW = 0.5
_SERIES_TERMS = 20

# Relative tolerance for "velocity0 parallel to gravity" and "I1 == I2": such inputs are
# built exactly so; 1e-12 only absorbs rounding, and a departure that small changes the
# motion by less than the accuracy of the references.
_EXACT_INPUT_RTOL = 1e-12

# Gauss-Legendre order of the precession-angle quadrature. Panels are no wider than the
# distance of the integrand's nearest complex pole from the real axis (and 1 in u), so the
# quadrature error is ~(2 + sqrt 5)^(-2 * order) ~ 1e-25 relative: below float64 rounding.
_GL_ORDER = 20
_GL_NODES, _GL_WEIGHTS = np.polynomial.legendre.leggauss(_GL_ORDER)
_MAX_PANEL_WIDTH = 1.0

# Newton steps inverting am(u): SciPy's F(phi | m) starts within ~1e-16 / (1 - m) and each
# step squares the error; 30 is a guard that quadratic convergence never reaches.
_NEWTON_MAX_STEPS = 30


def _vector(a, n: int = 3) -> np.ndarray:
    return np.asarray(a, dtype=float).reshape(n)


def _column(times) -> np.ndarray:
    """(T,) times -> (T, 1)."""
    return np.asarray(times, dtype=float).reshape(-1)[:, None]


def _unit(q) -> np.ndarray:
    """(4,) quaternion scaled to unit norm."""
    q = _vector(q, 4)
    return q / np.linalg.norm(q)


def _nonnegative(value: float, name: str) -> float:
    value = float(value)
    if not value >= 0:
        raise ValueError(f"{name} must be >= 0, got {value}")
    return value


def _exprel2(x: np.ndarray) -> np.ndarray:
    """(e^x - 1 - x) / x^2, accurate for all x (1/2 at x = 0)."""
    x = np.asarray(x, dtype=float)
    small = np.abs(x) < _SERIES_BELOW
    xs = np.where(small, x, 0.0)
    series = sum(xs**n / np.prod(np.arange(1.0, n + 3)) for n in range(_SERIES_TERMS))
    xd = np.where(small, 1.0, x)
    return np.where(small, series, (np.expm1(xd) - xd) / (xd * xd))


def projectile(position0, velocity0, gravity, times) -> tuple[np.ndarray, np.ndarray]:
    """Free flight under constant gravity: x = x0 + v0 t + g t^2 / 2, v = v0 + g t.

    Parameters
    ----------
    position0, velocity0 : (3,) array_like
        [m], [m/s].
    gravity : (3,) array_like
        [m/s^2].
    times : (T,) array_like
        [s].

    Returns
    -------
    position : (T, 3) ndarray
        [m].
    velocity : (T, 3) ndarray
        [m/s].
    """
    t = _column(times)
    x0, v0, g = _vector(position0), _vector(velocity0), _vector(gravity)
    return x0 + v0 * t + 0.5 * g * t * t, v0 + g * t


def linear_drag(
    position0, velocity0, gravity, drag_per_mass: float, times, air_velocity=(0.0, 0.0, 0.0)
) -> tuple[np.ndarray, np.ndarray]:
    """Point mass with linear (Stokes) drag relative to moving air: dv/dt = g - k (v - w).

    v = w + (v0 - w) e^{-kt} + g (1 - e^{-kt}) / k and
    x = x0 + w t + (v0 - w) (1 - e^{-kt}) / k + g (e^{-kt} - 1 + kt) / k^2, evaluated
    without cancellation for small k t (k = 0 gives the projectile).

    Parameters
    ----------
    position0, velocity0, gravity : (3,) array_like
        [m], [m/s], [m/s^2].
    drag_per_mass : float
        k = b / m [1/s], >= 0.
    times : (T,) array_like
        [s].
    air_velocity : (3,) array_like
        w [m/s], constant.

    Returns
    -------
    position : (T, 3) ndarray
        [m].
    velocity : (T, 3) ndarray
        [m/s].
    """
    k = _nonnegative(drag_per_mass, "drag_per_mass")
    t = _column(times)
    x0, v0, g, w = _vector(position0), _vector(velocity0), _vector(gravity), _vector(air_velocity)
    decay = np.exp(-k * t)
    phi1 = t * exprel(-k * t)  # (1 - e^{-kt}) / k
    phi2 = t * t * _exprel2(-k * t)  # (e^{-kt} - 1 + kt) / k^2
    return x0 + w * t + (v0 - w) * phi1 + g * phi2, w + (v0 - w) * decay + g * phi1


def quadratic_drag_along_line(
    position0, velocity0, gravity, drag_per_mass: float, times
) -> tuple[np.ndarray, np.ndarray]:
    """Point mass with quadratic drag moving along the line of gravity: dv/dt = g - c |v| v.

    With G = |g|, terminal speed v_t = sqrt(G / c) and rate r = sqrt(G c), the speed s
    along g obeys ds/dt = G - c |s| s:

    * moving along g (s0 >= 0): s = v_t (s0/v_t + tanh rt) / (1 + s0/v_t tanh rt), which
      covers s0 < v_t (tanh), s0 = v_t (constant) and s0 > v_t (coth);
    * moving against g (s0 < 0): s = -v_t tan(atan(|s0|/v_t) - rt) up to the apex at
      t_top = atan(|s0|/v_t) / r, then s = v_t tanh(r (t - t_top)) from rest;
    * g = 0 (any direction of v0): v = v0 / (1 + c |v0| t),
      x = x0 + v0 ln(1 + c |v0| t) / (c |v0|).

    Parameters
    ----------
    position0, velocity0, gravity : (3,) array_like
        [m], [m/s], [m/s^2]. ``velocity0`` must be parallel (or antiparallel) to
        ``gravity``, unless either is zero.
    drag_per_mass : float
        c = (1/2 rho C_d A) / m [1/m], >= 0.
    times : (T,) array_like
        [s].

    Returns
    -------
    position : (T, 3) ndarray
        [m].
    velocity : (T, 3) ndarray
        [m/s].

    Raises
    ------
    ValueError
        If velocity0 is not parallel to gravity (the motion then leaves the line and has
        no closed form), or drag_per_mass < 0.
    """
    c = _nonnegative(drag_per_mass, "drag_per_mass")
    t = _column(times)
    x0, v0, g = _vector(position0), _vector(velocity0), _vector(gravity)
    big_g, speed0 = np.linalg.norm(g), np.linalg.norm(v0)
    if c == 0:
        return projectile(x0, v0, g, times)
    if big_g == 0:
        a = c * speed0 * t
        log_ratio = np.where(a > 0, np.log1p(a) / np.where(a > 0, a, 1.0), 1.0)  # ln(1 + a) / a
        return x0 + v0 * t * log_ratio, v0 / (1 + a)
    down = g / big_g
    off_line = np.linalg.norm(np.cross(v0, down))
    if off_line > _EXACT_INPUT_RTOL * speed0:
        raise ValueError(
            "quadratic_drag_along_line needs velocity0 parallel to gravity (or one of them zero); "
            f"|velocity0 x gravity| / (|velocity0| |gravity|) = {off_line / speed0:.3g}"
        )
    v_t, rate = np.sqrt(big_g / c), np.sqrt(big_g * c)
    s0 = float(v0 @ down)
    if s0 >= 0:
        ratio, u = s0 / v_t, rate * t
        tanh = np.tanh(u)
        speed = v_t * (ratio + tanh) / (1 + ratio * tanh)
        # ln(cosh u + ratio sinh u) / c, written to neither overflow nor cancel.
        distance = (u + np.log1p(0.5 * (1 - ratio) * np.expm1(-2 * u))) / c
    else:
        ratio = -s0 / v_t
        apex = np.arctan(ratio)
        w = rate * t
        rising = w <= apex
        wr = np.minimum(w, apex)
        tan = np.tan(wr)
        rise_speed = -v_t * (ratio - tan) / (1 + ratio * tan)
        rise_distance = -np.log1p(ratio * np.sin(wr) - 2 * np.sin(0.5 * wr) ** 2) / c
        wf = np.maximum(w - apex, 0.0)
        fall_speed = v_t * np.tanh(wf)
        fall_distance = (-0.5 * np.log1p(ratio * ratio) + wf + np.log1p(0.5 * np.expm1(-2 * wf))) / c
        speed = np.where(rising, rise_speed, fall_speed)
        distance = np.where(rising, rise_distance, fall_distance)
    return x0 + distance * down, speed * down


def _body_from_world(quat_wxyz: np.ndarray, vector_world: np.ndarray) -> np.ndarray:
    """R^T v for (T, 4) quaternions and (T, 3) vectors."""
    return np.einsum("tji,tj->ti", quat_wxyz_to_matrix(quat_wxyz), vector_world)


def _world_from_body(quat_wxyz: np.ndarray, vector_body: np.ndarray) -> np.ndarray:
    """R v for (T, 4) quaternions and (T, 3) vectors."""
    return np.einsum("tij,tj->ti", quat_wxyz_to_matrix(quat_wxyz), vector_body)


def linear_angular_drag_isotropic(
    moment_of_inertia: float, angular_drag: float, angular_velocity_world0, quat_wxyz0, times
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Body with isotropic inertia I E under the drag torque -c omega.

    L = I omega keeps its direction, so omega(t) = omega0 e^{-ct/I} about a fixed world
    axis and the body has turned by the rotation vector omega0 (1 - e^{-ct/I}) I / c.

    Parameters
    ----------
    moment_of_inertia : float
        I [kg m^2], > 0.
    angular_drag : float
        c [N m s], >= 0.
    angular_velocity_world0 : (3,) array_like
        [rad/s].
    quat_wxyz0 : (4,) array_like
        Initial orientation.
    times : (T,) array_like
        [s].

    Returns
    -------
    quat_wxyz : (T, 4) ndarray
    angular_velocity_world : (T, 3) ndarray
        [rad/s].
    angular_velocity_body : (T, 3) ndarray
        [rad/s].
    """
    if not float(moment_of_inertia) > 0:
        raise ValueError(f"moment_of_inertia must be > 0, got {moment_of_inertia}")
    k = _nonnegative(angular_drag, "angular_drag") / float(moment_of_inertia)
    t = _column(times)
    omega0 = _vector(angular_velocity_world0)
    q0 = _unit(quat_wxyz0)
    omega = omega0 * np.exp(-k * t)
    quat = quat_wxyz_multiply(quat_wxyz_from_rotvec(omega0 * t * exprel(-k * t)), q0)
    return quat, omega, _body_from_world(quat, omega)


def _principal_moments(inertia_principal) -> np.ndarray:
    inertia = _vector(inertia_principal)
    if not np.all(inertia > 0):
        raise ValueError(f"principal moments must be > 0, got {inertia.tolist()}")
    return inertia


def torque_free_axisymmetric(
    inertia_principal, angular_velocity_body0, quat_wxyz0, times
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Torque-free symmetric top (I1 == I2): steady precession, closed form.

    The body axes are the principal axes, body z the symmetry axis. With
    lambda = (I3 - I1) / I1 * omega3, the body angular velocity turns about body z,
    omega_body(t) = Rz(lambda t) omega_body0, and the orientation is
    R(t) = exp(t [L_world / I1]x) R0 exp(-lambda t [e_z]x): precession about the constant
    L_world at |L| / I1, and spin -lambda relative to the precessing frame.

    Parameters
    ----------
    inertia_principal : (3,) array_like
        (I1, I2, I3) [kg m^2], I1 == I2 (to 1e-12 relative).
    angular_velocity_body0 : (3,) array_like
        [rad/s] in body (principal) axes.
    quat_wxyz0 : (4,) array_like
        Initial orientation.
    times : (T,) array_like
        [s].

    Returns
    -------
    quat_wxyz : (T, 4) ndarray
    angular_velocity_world : (T, 3) ndarray
        [rad/s].
    angular_velocity_body : (T, 3) ndarray
        [rad/s].
    """
    inertia = _principal_moments(inertia_principal)
    if abs(inertia[0] - inertia[1]) > _EXACT_INPUT_RTOL * inertia[:2].max():
        raise ValueError(f"torque_free_axisymmetric needs I1 == I2, got {inertia.tolist()}")
    t = _column(times)
    omega0 = _vector(angular_velocity_body0)
    q0 = _unit(quat_wxyz0)
    rate = (inertia[2] - inertia[0]) / inertia[0] * omega0[2]
    angle = rate * t[:, 0]
    c, s = np.cos(angle), np.sin(angle)
    omega_body = np.stack(
        [c * omega0[0] - s * omega0[1], s * omega0[0] + c * omega0[1], np.full_like(angle, omega0[2])],
        axis=-1,
    )
    l_world = quat_wxyz_to_matrix(q0) @ (inertia * omega0)
    spin = quat_wxyz_from_rotvec(-rate * t * np.array([0.0, 0.0, 1.0]))
    quat = quat_wxyz_multiply(quat_wxyz_from_rotvec(t * l_world / inertia[0]), quat_wxyz_multiply(q0, spin))
    return quat, _world_from_body(quat, omega_body), omega_body


class _Elliptic(NamedTuple):
    """Euler's equations solved in "primed" principal axes (1, 2, 3) = (c, b, a).

    omega' = to_primed @ omega_body = (A1 cn u, A2 sn u, A3 dn u), u = rate t + phase0,
    parameter m and m1 = 1 - m (each from its own cancellation-free formula), quarter
    period K of sn in u, and the AGM ladder (a_i, c_i) that evaluates sn, cn, dn. Axis 3
    is the one whose component never changes sign.
    """

    to_primed: np.ndarray
    inertia: np.ndarray
    amplitude: np.ndarray
    rate: float
    m: float
    m1: float
    ladder: tuple[np.ndarray, np.ndarray]
    quarter: float
    phase0: float
    momentum: float


def _elliptic(inertia: np.ndarray, omega: np.ndarray) -> _Elliptic | None:
    """The elliptic-function solution, or None for a spin about one principal axis (or rest)."""
    if np.count_nonzero(omega) <= 1:
        return None
    i_min, i_mid, i_max = np.argsort(inertia)
    e = np.eye(3)
    # L^2 - 2 E I_mid as a sum without cancellation: > 0 near the major axis, < 0 near the minor.
    d = sum(inertia[i] * omega[i] ** 2 * (inertia[i] - inertia[i_mid]) for i in (i_min, i_max))
    a, c = (i_max, i_min) if d >= 0 else (i_min, i_max)
    row1 = np.copysign(1.0, omega[c]) * e[c]
    row3 = np.copysign(1.0, omega[a]) * e[a]
    to_primed = np.stack([row1, np.cross(row3, row1), row3])  # proper rotation, w1', w3' >= 0
    i1, i2, i3 = inertia[[c, i_mid, a]]
    w1, w2, w3 = to_primed @ omega
    # 2 E I3 - L^2, L^2 - 2 E I1, L^2 - 2 E I2 as sums of same-sign terms.
    p = i1 * (i3 - i1) * w1**2 + i2 * (i3 - i2) * w2**2
    q = i2 * (i2 - i1) * w2**2 + i3 * (i3 - i1) * w3**2
    r = i1 * (i1 - i2) * w1**2 + i3 * (i3 - i2) * w3**2
    amplitude = np.sqrt([p / (i1 * (i3 - i1)), p / (i2 * (i3 - i2)), q / (i3 * (i3 - i1))])
    m, m1 = (i2 - i1) * p / ((i3 - i2) * q), (i3 - i1) * r / ((i3 - i2) * q)
    ladder = _landen_ladder(m, m1)
    sol = _Elliptic(
        to_primed=to_primed,
        inertia=np.array([i1, i2, i3]),
        amplitude=amplitude,
        rate=np.sign(i3 - i2) * np.sqrt((i3 - i2) * q / (i1 * i2 * i3)),
        m=m,
        m1=m1,
        ladder=ladder,
        quarter=np.inf if m1 == 0 else 0.5 * np.pi / ladder[0][-1],
        phase0=0.0,
        momentum=np.sqrt(np.sum((inertia * omega) ** 2)),
    )
    return sol._replace(phase0=_phase(sol, w1 / amplitude[0], w2 / amplitude[1]))


def _landen_ladder(m: float, m1: float) -> tuple[np.ndarray, np.ndarray]:
    """AGM ladder a_i, c_i from (a0, b0, c0) = (1, sqrt(m1), sqrt(m)) until c_i < eps a_i.

    Started from sqrt(m1) itself, not sqrt(1 - m): SciPy's ellipj does the latter and so
    loses 1 - m near the separatrix (it switches to an expansion in 1 - m for m > 1 - 1e-9
    that is wrong by O(1) beyond u ~ K). c_{i+1} = c_i^2 / (4 a_{i+1}) avoids cancellation.
    Empty ladder (a = [1]) when m = 0; not used when m1 = 0 (K infinite).
    """
    a, c, b = [1.0], [np.sqrt(m)], np.sqrt(m1)
    while m1 > 0 and c[-1] > np.finfo(float).eps * a[-1]:
        a_next = 0.5 * (a[-1] + b)
        c.append(0.25 * c[-1] ** 2 / a_next)
        b = np.sqrt(a[-1] * b)
        a.append(a_next)
    return np.array(a), np.array(c)


def _jacobi_reduced(sol: _Elliptic, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """sn, cn, dn, am of z in [0, K/2] by the backward AGM recurrence (Abramowitz & Stegun 16.4)."""
    a, c = sol.ladder
    phi = 2.0 ** (len(a) - 1) * a[-1] * z
    for i in range(len(a) - 1, 0, -1):
        phi = 0.5 * (np.arcsin(c[i] / a[i] * np.sin(phi)) + phi)
    sn, cn = np.sin(phi), np.cos(phi)
    return sn, cn, np.sqrt(cn * cn + sol.m1 * sn * sn), phi


def _jacobi(sol: _Elliptic, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """sn, cn, dn and the continuous am of u (any shape).

    Reduced to [0, K/2] by the period 2K (sn, cn change sign, am gains pi) and the
    reflection u -> K - u (sn = cd, cn = sqrt(m1) sd, dn = sqrt(m1) nd), which keeps dn
    accurate to full relative precision near u = K. On the separatrix (m1 = 0):
    sn = tanh, cn = dn = sech, am = gd.
    """
    if sol.m1 == 0:
        decay = np.exp(-np.abs(u))
        sech = 2 * decay / (1 + decay * decay)
        return np.tanh(u), sech, sech, 2 * np.arctan(np.tanh(0.5 * u))
    k = sol.quarter
    n = np.round(u / (2 * k))
    x = u - 2 * k * n
    y = np.abs(x)
    reflect = y > k / 2
    sn_z, cn_z, dn_z, _ = _jacobi_reduced(sol, np.where(reflect, k - y, y))
    root = np.sqrt(sol.m1)
    sn = np.where(reflect, cn_z / dn_z, sn_z)
    cn = np.where(reflect, root * sn_z / dn_z, cn_z)
    dn = np.where(reflect, root / dn_z, dn_z)
    sign, parity = np.where(x < 0, -1.0, 1.0), 1.0 - 2.0 * (n % 2)
    return parity * sign * sn, parity * cn, dn, sign * np.arctan2(sn, cn) + np.pi * n


def _phase(sol: _Elliptic, cn0: float, sn0: float) -> float:
    """u0 with cn(u0) = cn0, sn(u0) = sn0 (and dn > 0): the inverse of :func:`_jacobi`.

    am0 = n pi + beta, |beta| <= pi/2; u0 = 2 K n + sign(beta) y with am(y) = |beta|. y is
    found in [0, K/2], directly or through the reflection (am(K - y) = atan2(cn, sqrt(m1) sn)),
    by Newton's method on am (d am / du = dn) from SciPy's F(phi | m).
    """
    am0 = np.arctan2(sn0, cn0)
    n = np.round(am0 / np.pi)
    beta = am0 - n * np.pi
    c, s = abs(np.cos(beta)), abs(np.sin(beta))
    if sol.m1 == 0:
        return float(np.sign(beta) * np.arctanh(s))
    # am(K/2) = atan(m1^(-1/4)): beyond it, solve for K - y instead.
    reflect = s * sol.m1**0.25 > c
    target = np.arctan2(c, np.sqrt(sol.m1) * s) if reflect else abs(beta)
    z = ellipkinc(target, sol.m)
    for _ in range(_NEWTON_MAX_STEPS):
        _, _, dn, am = _jacobi_reduced(sol, z)
        step = (am - target) / dn
        z -= step
        if abs(step) <= 4 * np.finfo(float).eps * max(z, 1.0):
            break
    y = sol.quarter - z if reflect else z
    return float(2 * sol.quarter * n + np.sign(beta) * y)


def _gauss_legendre(f, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Integral of the vectorised f over [lo, hi], elementwise over the arrays lo, hi."""
    half = 0.5 * (hi - lo)
    nodes = (0.5 * (hi + lo))[..., None] + half[..., None] * _GL_NODES
    return half * (f(nodes) @ _GL_WEIGHTS)


def _precession_integral(sol: _Elliptic, u: np.ndarray) -> np.ndarray:
    """Integral from 0 to u of dpsi/du * rate = |L| (a + b sn^2) / (I1 a + I3 b sn^2).

    a = I3 - I2, b = I2 - I1. Quadrature over one period 2K of sn^2 on panels, the whole
    periods added; closed form on the separatrix (m1 = 0, sn = tanh).
    """
    i1, i2, i3 = sol.inertia
    a, b = i3 - i2, i2 - i1
    kappa = np.sqrt(i3 * b / (i1 * a))
    if sol.m1 == 0:
        return sol.momentum * (u / i2 + a / (i2 * i3) * kappa * np.arctan(kappa * np.tanh(u)))

    def integrand(x: np.ndarray) -> np.ndarray:
        sn2 = _jacobi(sol, x)[0] ** 2
        return sol.momentum * (a + b * sn2) / (i1 * a + i3 * b * sn2)

    period = 2 * sol.quarter
    # Poles of the integrand sit at Im u = +-F(atan(1 / kappa) | m1), Re u = 0 mod 2K.
    pole = ellipkinc(np.arctan(1 / kappa), sol.m1)
    n_panels = int(np.ceil(period / min(pole, _MAX_PANEL_WIDTH)))
    edges = np.linspace(0.0, period, n_panels + 1)
    cumulative = np.concatenate([[0.0], np.cumsum(_gauss_legendre(integrand, edges[:-1], edges[1:]))])
    cycles = np.floor(u / period)
    x = u - cycles * period
    j = np.clip(np.floor(x / (period / n_panels)).astype(int), 0, n_panels - 1)
    return cycles * cumulative[-1] + cumulative[j] + _gauss_legendre(integrand, edges[j], x)


def _quat_zxz(psi: np.ndarray, theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Quaternion of Rz(psi) Rx(theta) Rz(phi). (T,) x 3 -> (T, 4)."""
    ex, ez = np.eye(3)[0], np.eye(3)[2]
    nutation_spin = quat_wxyz_multiply(
        quat_wxyz_from_rotvec(theta[:, None] * ex), quat_wxyz_from_rotvec(phi[:, None] * ez)
    )
    return quat_wxyz_multiply(quat_wxyz_from_rotvec(psi[:, None] * ez), nutation_spin)


def _nutation_and_spin(
    sol: _Elliptic, omega_primed: np.ndarray, am: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Euler angles theta, phi of L in primed body axes: L' / |L| = (s_th s_ph, s_th c_ph, c_th).

    tan phi = I1 w1 / (I2 w2) = cos(am) / (k sin(am)), k = sqrt(I2 (I3 - I1) / (I1 (I3 - I2)));
    phi = pi/2 - beta with tan beta = k tan(am), beta unwrapped to follow am continuously.
    """
    i1, i2, i3 = sol.inertia
    lw = sol.inertia * omega_primed
    theta = np.arctan2(np.hypot(lw[:, 0], lw[:, 1]), lw[:, 2])
    k = np.sqrt(i2 * (i3 - i1) / (i1 * (i3 - i2)))
    s, c = np.sin(am), np.cos(am)
    beta = am + np.arctan2((k - 1) * s * c, c * c + k * s * s)
    return theta, 0.5 * np.pi - beta


def torque_free_asymmetric(
    inertia_principal, angular_velocity_body0, quat_wxyz0, times
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Torque-free asymmetric body: Jacobi elliptic functions + quadrature.

    Angular velocity (Euler's equations, Landau & Lifshitz section 37): in principal axes
    relabelled (1, 2, 3) = (c, b, a) by a proper signed permutation, with b the
    intermediate axis, a the major axis when L^2 > 2 E I_b (rotation near the major axis)
    and the minor axis when L^2 < 2 E I_b (near the minor axis),
    omega' = (A1 cn u, A2 sn u, A3 dn u), u = rate t + u0, with the phase u0 inverted from
    (cn, sn) = (w1/A1, w2/A2) so that the initial condition is reproduced for any signs.
    sn, cn, dn are evaluated by an AGM started from 1 - m itself (not SciPy's ellipj, which
    fails near m = 1). On the separatrix
    (L^2 = 2 E I_b exactly) m = 1 and the same formulas give the homoclinic solution
    (sn = tanh, cn = dn = sech): omega approaches the unstable intermediate axis without
    flipping. A spin about one principal axis (or rest) is returned as a steady rotation.

    Orientation: L_world is constant, so R^T L_world = I omega_body fixes the nutation and
    spin angles theta, phi of R' = B Rz(psi) Rx(theta) Rz(phi) (B a fixed frame with
    B e_z = L_world / |L|); the precession angle obeys
    dpsi/dt = |L| (I1 w1^2 + I2 w2^2) / (I1^2 w1^2 + I2^2 w2^2) > 0 (primed axes),
    integrated by panelled Gauss-Legendre quadrature of its elliptic-function form.

    Near the separatrix the motion itself is ill-conditioned (rounding omega0 by 1e-16
    moves the flips by ~1e-16 / (1 - m) of a period); the evaluation adds no more than that.

    Parameters
    ----------
    inertia_principal : (3,) array_like
        Principal moments [kg m^2], > 0 and pairwise distinct (else use
        :func:`torque_free_axisymmetric`); any order.
    angular_velocity_body0 : (3,) array_like
        [rad/s] in body (principal) axes.
    quat_wxyz0 : (4,) array_like
        Initial orientation.
    times : (T,) array_like
        [s].

    Returns
    -------
    quat_wxyz : (T, 4) ndarray
        Continuous in t (no sign jumps).
    angular_velocity_world : (T, 3) ndarray
        [rad/s].
    angular_velocity_body : (T, 3) ndarray
        [rad/s].
    """
    inertia = _distinct(inertia_principal)
    t = _column(times)[:, 0]
    omega0 = _vector(angular_velocity_body0)
    q0 = _unit(quat_wxyz0)
    sol = _elliptic(inertia, omega0)
    if sol is None:
        quat = quat_wxyz_multiply(q0, quat_wxyz_from_rotvec(t[:, None] * omega0))
        omega_body = np.broadcast_to(omega0, (len(t), 3)).copy()
        return quat, _world_from_body(quat, omega_body), omega_body
    u = np.concatenate([[sol.phase0], sol.rate * t + sol.phase0])
    sn, cn, dn, am = _jacobi(sol, u)
    omega_primed = sol.amplitude * np.stack([cn, sn, dn], axis=-1)
    precession = _precession_integral(sol, u)
    psi = (precession - precession[0]) / sol.rate
    theta, phi = _nutation_and_spin(sol, omega_primed, am)
    q_primed = matrix_to_quat_wxyz(sol.to_primed)
    # B = R0 Q^T (Rx(theta0) Rz(phi0))^T, so that R(0) = B Rx(theta0) Rz(phi0) Q = R0.
    start = _quat_zxz(np.zeros(1), theta[:1], phi[:1])[0]
    frame = quat_wxyz_multiply(
        quat_wxyz_multiply(q0, quat_wxyz_conjugate(q_primed)), quat_wxyz_conjugate(start)
    )
    quat = quat_wxyz_multiply(quat_wxyz_multiply(frame, _quat_zxz(psi[1:], theta[1:], phi[1:])), q_primed)
    omega_body = omega_primed[1:] @ sol.to_primed
    return quat, _world_from_body(quat, omega_body), omega_body


def _distinct(inertia_principal) -> np.ndarray:
    inertia = _principal_moments(inertia_principal)
    if len(np.unique(inertia)) < 3:
        raise ValueError(
            f"torque_free_asymmetric needs distinct principal moments, got {inertia.tolist()} "
            "(use torque_free_axisymmetric)"
        )
    return inertia


def intermediate_axis_flip_period(inertia_principal, angular_velocity_body0) -> float:
    """Period [s] of omega_body in torque-free motion: 4 K(m) / |rate|.

    The intermediate-axis component reverses sign twice per period (the Dzhanibekov
    flips are half a period apart). ``inf`` on the separatrix and for a spin about one
    principal axis (or rest), where nothing is periodic.

    Parameters
    ----------
    inertia_principal : (3,) array_like
        Distinct principal moments [kg m^2].
    angular_velocity_body0 : (3,) array_like
        [rad/s] in principal axes.
    """
    sol = _elliptic(_distinct(inertia_principal), _vector(angular_velocity_body0))
    return np.inf if sol is None else float(4 * sol.quarter / abs(sol.rate))
