"""The quaternion-orientation integrators of :mod:`core.dynamics.integrators`, component-major for speed.

The state of B bodies is one (13, B) array, rows ``x (3) | q_wxyz (4) | P (3) | L (3)``: every
row is a contiguous run of B floats, so each term of the lecture's dS/dt = (v, 1/2 (0, omega) q,
F, tau) is a handful of element-wise operations over the batch instead of stacked 3 x 3 matrix
products (4-10x faster at B >= 100; see BENCHMARKS.md). The mathematics is that of
:mod:`core.dynamics.integrators`:

- explicit Runge-Kutta (``explicit_euler``, ``average_velocity``, ``midpoint``, ``rk4``): additive
  quaternion stages, normalised after the step;
- ``semi_implicit_euler``: P, L first with the forces at the step's start, then x and q with the
  new velocities (omega from the start's rotation), q normalised;
- ``engine_euler``: linear and body-frame angular velocity first with the explicit gyroscopic term,
  then x += dt v and q <- q exp(dt omega_body) (the exponential map), sign fixed to w >= 0.

The scene's wrench (:data:`core.dynamics.rigid_body.Wrench`) is called with transposed views, so forces keep
their (B, 3) interface.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from simparity.core.dynamics.rigid_body import MassProperties, State, Wrench
from simparity.core.dynamics.tableau import TABLEAUX
from simparity.core.rotations import quat_wxyz_from_rotvec, quat_wxyz_multiply, quat_wxyz_normalize

X, Q, P, L = slice(0, 3), slice(3, 7), slice(7, 10), slice(10, 13)
"""Rows of the packed state."""

ROWS = 13

CHUNK_ELEMENTS = 1 << 15
"""Samples x bodies per chunk of :meth:`PackedBodies.samples`: 256 KiB per row, in L2 cache."""

PackedStep = Callable[[float, np.ndarray, float | np.ndarray], np.ndarray]
"""step(t, packed (13, B), dt) -> packed (13, B) at t + dt; dt [s] a float or (B,), one per body."""


def pack(state: State) -> np.ndarray:
    """(13, B) packed copy of a quaternion State."""
    return np.concatenate([state.position_world.T, state.orientation.T, state.momentum_world.T,
                           state.angular_momentum_world.T])


def unpack(packed: np.ndarray) -> State:
    """State of a (13, B) packed array (copies, body-major)."""
    s = np.ascontiguousarray(packed.T)
    return State(s[:, X], s[:, Q], s[:, P], s[:, L])


def rotation_rows(q: np.ndarray) -> np.ndarray:
    """Row-major rotation matrices of quaternions, normalised first. (4, ...) -> (3, 3, ...)."""
    w, x, y, z = q
    s = 2.0 / (w * w + x * x + y * y + z * z)
    xs, ys, zs = x * s, y * s, z * s
    wx, wy, wz = w * xs, w * ys, w * zs
    xx, xy, xz = x * xs, x * ys, x * zs
    yy, yz, zz = y * ys, y * zs, z * zs
    r = np.empty((3, 3) + w.shape)  # filled entry by entry: np.array of nested arrays is ~10x slower
    r[0, 0], r[0, 1], r[0, 2] = 1 - (yy + zz), xy - wz, xz + wy
    r[1, 0], r[1, 1], r[1, 2] = xy + wz, 1 - (xx + zz), yz - wx
    r[2, 0], r[2, 1], r[2, 2] = xz - wy, yz + wx, 1 - (xx + yy)
    return r


def _matvec(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(3, 3, ...) x (3, ...) -> (3, ...)."""
    return m[:, 0] * v[0] + m[:, 1] * v[1] + m[:, 2] * v[2]


def _tmatvec(m: np.ndarray, v: np.ndarray) -> np.ndarray:
    """m^T v: (3, 3, ...) x (3, ...) -> (3, ...)."""
    return m[0] * v[0] + m[1] * v[1] + m[2] * v[2]


def quat_rate(q: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """dq/dt = 1/2 (0, omega) q for world omega. (4, ...) x (3, ...) -> (4, ...)."""
    w, x, y, z = q
    ox, oy, oz = 0.5 * omega
    out = np.empty((4,) + w.shape)
    out[0], out[1] = -ox * x - oy * y - oz * z, ox * w + oy * z - oz * y
    out[2], out[3] = oy * w - ox * z + oz * x, oz * w + ox * y - oy * x
    return out


class PackedBodies:
    """Mass properties of B bodies laid out for the packed state, and their velocities.

    Attributes
    ----------
    inverse_mass : (B,) ndarray  [1/kg]
    inertia_body : (3, 3, B) ndarray  [kg m^2]
    inertia_body_inv : (3, 3, B) ndarray, or (3, B) diagonal when every body's tensor is diagonal
    """

    def __init__(self, props: MassProperties, one_body: bool = False) -> None:
        self.props, self.one_body = props, one_body
        self.inverse_mass = 1.0 / props.mass
        self.inertia_body = np.ascontiguousarray(props.inertia_body.transpose(1, 2, 0))
        inv = props.inertia_body_inv
        diagonal = not np.any(inv - inv * np.eye(3))
        self.inertia_body_inv = (np.ascontiguousarray(np.diagonal(inv, axis1=1, axis2=2).T) if diagonal
                                 else np.ascontiguousarray(inv.transpose(1, 2, 0)))
        if one_body:  # no batch axis: (3, 3), (3,) and scalars
            self.inverse_mass, self.inertia_body, self.inertia_body_inv = (
                self.inverse_mass[0], self.inertia_body[..., 0], self.inertia_body_inv[..., 0])

    def apply_inverse_inertia_body(self, a: np.ndarray) -> np.ndarray:
        """I_body^-1 a. (3, ..., B) -> (3, ..., B); (3,) -> (3,) for one body."""
        inv = self.inertia_body_inv
        if not self.one_body:
            inv = inv.reshape(inv.shape[:-1] + (1,) * (a.ndim - 2) + inv.shape[-1:])  # broadcast over middle axes
        return inv * a if inv.ndim == a.ndim else _matvec(inv, a)

    def omega_world(self, rotation: np.ndarray, angular_momentum: np.ndarray) -> np.ndarray:
        """omega = R I_body^-1 R^T L. (3, 3, ..., B), (3, ..., B) -> (3, ..., B)."""
        return _matvec(rotation, self.apply_inverse_inertia_body(_tmatvec(rotation, angular_momentum)))

    def velocities(self, packed: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(v, omega, R) of a packed state (13, ..., B): (3, ..., B), (3, ..., B), (3, 3, ..., B)."""
        rotation = rotation_rows(packed[Q])
        return packed[P] * self.inverse_mass, self.omega_world(rotation, packed[L]), rotation

    def samples(self, packed: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(x, q_wxyz, v, omega) of packed states (13, T, B), body-major (T, B, 3 or 4), as a Trajectory
        holds them. Computed and transposed a few samples at a time so the temporaries stay in cache
        (several times faster than all T at once when T B ~ 10^6)."""
        steps, batch = packed.shape[1:]
        x, q, v, omega = (np.empty((steps, batch, k)) for k in (3, 4, 3, 3))
        per_chunk = max(1, CHUNK_ELEMENTS // batch)
        for start in range(0, steps, per_chunk):
            chunk = slice(start, start + per_chunk)
            rows = packed[:, chunk]
            vc, oc, _ = self.velocities(rows)
            for out, value in ((x, rows[X]), (q, rows[Q]), (v, vc), (omega, oc)):
                out[chunk] = value.transpose(1, 2, 0)
        return x, q, v, omega


def _wrench(wrench: Wrench, t: float | np.ndarray, packed: np.ndarray, rotation: np.ndarray, v: np.ndarray,
            omega: np.ndarray, step_start: float | np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The scene's wrench at stage time ``t`` of the step starting at ``step_start`` (None: ``t``), called body-major
    on transposed views; returns (F, tau) as (3, B), or (3,) for a packed state of one body without a batch axis
    (13,)."""
    if packed.ndim == 1:
        force, torque = wrench(t, packed[X][None], rotation[None], v[None], omega[None], step_start)
        return force[0], torque[0]
    force, torque = wrench(t, packed[X].T, rotation.transpose(2, 0, 1), v.T, omega.T, step_start)
    return force.T, torque.T


def _derivative(bodies: PackedBodies, wrench: Wrench, t: float | np.ndarray, packed: np.ndarray,
                step_start: float | np.ndarray) -> np.ndarray:
    """dS/dt = (v, 1/2 (0, omega) q, F, tau) of a packed state at stage time ``t`` of the step starting at
    ``step_start``. (13, B) -> (13, B)."""
    v, omega, rotation = bodies.velocities(packed)
    force, torque = _wrench(wrench, t, packed, rotation, v, omega, step_start)
    out = np.empty_like(packed)
    out[X], out[Q], out[P], out[L] = v, quat_rate(packed[Q], omega), force, torque
    return out


def _normalised(packed: np.ndarray) -> np.ndarray:
    q = packed[Q]
    columns = q.reshape(4, -1)  # one body without a batch axis summed as a batch of one: the same rounding
    packed[Q] = q / np.sqrt(np.einsum("ib,ib->b", columns, columns)).reshape(q.shape[1:])
    return packed


def runge_kutta(scheme: str, bodies: PackedBodies, wrench: Wrench) -> PackedStep:
    """One step of an explicit Runge-Kutta scheme (:data:`core.dynamics.tableau.TABLEAUX`) on the packed state
    (quaternion normalised after). Stages and step accumulate onto the state term by term, y + (dt a_ij) k_j and
    y + (dt b_i) k_i in stage order, skipping zero coefficients."""
    tableau = TABLEAUX[scheme]
    a, b, c = tableau.a, tableau.b, tableau.c

    def step(t: float, s: np.ndarray, dt: float | np.ndarray) -> np.ndarray:
        ks: list[np.ndarray] = []
        for i in range(len(b)):
            stage = s
            for aij, k in zip(a[i], ks):
                if aij:
                    stage = stage + (dt * aij) * k
            ks.append(_derivative(bodies, wrench, t + c[i] * dt, stage, t))
        new = s.copy()
        for bi, k in zip(b, ks):
            if bi:
                new += (dt * bi) * k
        return _normalised(new)

    return step


def semi_implicit_euler(bodies: PackedBodies, wrench: Wrench) -> PackedStep:
    """Symplectic Euler on the packed state: P, L first, then x, q with the new v, omega."""

    def step(t: float, s: np.ndarray, dt: float | np.ndarray) -> np.ndarray:
        v, omega, rotation = bodies.velocities(s)
        force, torque = _wrench(wrench, t, s, rotation, v, omega)
        new = np.empty_like(s)
        new[P] = s[P] + dt * force
        new[L] = s[L] + dt * torque
        omega = bodies.omega_world(rotation, new[L])
        new[X] = s[X] + dt * new[P] * bodies.inverse_mass
        new[Q] = s[Q] + dt * quat_rate(s[Q], omega)
        return _normalised(new)

    return step


def _quat_exp_body(q: np.ndarray, rotvec_body: np.ndarray) -> np.ndarray:
    """q exp(rotvec) (a body-frame increment), sign fixed to w >= 0. (4, B) x (3, B) -> (4, B)."""
    out = quat_wxyz_normalize(quat_wxyz_multiply(q.T, quat_wxyz_from_rotvec(rotvec_body.T)))
    return (out * np.where(out[..., :1] < 0, -1.0, 1.0)).T


def engine_euler(bodies: PackedBodies, wrench: Wrench) -> PackedStep:
    """The engines' first-order scheme (``engine_euler`` in :mod:`core.dynamics.integrators`' docstring) on the packed
    state."""

    def step(t: float, s: np.ndarray, dt: float | np.ndarray) -> np.ndarray:
        v, omega, rotation = bodies.velocities(s)
        force, torque = _wrench(wrench, t, s, rotation, v, omega)
        omega_body = _tmatvec(rotation, omega)
        gyro = np.cross(omega_body, _matvec(bodies.inertia_body, omega_body), axis=0)
        omega_body = omega_body + dt * bodies.apply_inverse_inertia_body(_tmatvec(rotation, torque) - gyro)
        v = v + dt * force * bodies.inverse_mass
        new = np.empty_like(s)
        new[X] = s[X] + dt * v
        new[Q] = _quat_exp_body(s[Q], dt * omega_body)
        new[P] = v * bodies.props.mass
        new[L] = _matvec(rotation_rows(new[Q]), _matvec(bodies.inertia_body, omega_body))
        return new

    return step


def make_packed_step(scheme: str, props: MassProperties, wrench: Wrench) -> PackedStep:
    """The packed step of ``scheme`` (a key of :data:`core.dynamics.tableau.TABLEAUX`, ``semi_implicit_euler``
    or ``engine_euler``).

    One body steps without its batch axis: (13,) instead of (13, 1), so that the many scalar products of the
    rotation and the quaternion rate are NumPy scalars (~0.1 us each) instead of one-element arrays (~1 us each),
    several times faster per step with the same operations in the same order (the same numbers, bit for bit)."""
    one_body = len(props.mass) == 1
    bodies = PackedBodies(props, one_body)
    if scheme in TABLEAUX:
        step = runge_kutta(scheme, bodies, wrench)
    elif scheme == "semi_implicit_euler":
        step = semi_implicit_euler(bodies, wrench)
    elif scheme == "engine_euler":
        step = engine_euler(bodies, wrench)
    else:
        raise ValueError(f"unknown scheme '{scheme}'")
    return _with_batch_axis(step) if one_body else step


def _with_batch_axis(step: PackedStep) -> PackedStep:
    """A step of one body's (13,) state as the (13, 1) PackedStep interface."""

    def batched(t: float, s: np.ndarray, dt: float | np.ndarray) -> np.ndarray:
        return step(t, s[:, 0], dt)[:, None]

    return batched


def state_step(scheme: str, props: MassProperties, wrench: Wrench) -> Callable[[float, State, float], State]:
    """The packed step behind the State interface of :data:`core.dynamics.integrators.Step` (quaternion states)."""
    packed_step = make_packed_step(scheme, props, wrench)

    def step(t: float, s: State, dt: float) -> State:
        return unpack(packed_step(t, pack(s), dt))

    return step
