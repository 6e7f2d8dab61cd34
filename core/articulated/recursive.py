"""Featherstone's recursive algorithms (Rigid Body Dynamics Algorithms, 2008): RNEA, CRBA and ABA, batched.

Component-major for speed, like :mod:`core.dynamics.quaternion_integrators`: a spatial vector of B states is a
(6, B) array, a symmetric 6 x 6 inertia a (21, B) array of its packed entries
(:data:`core.articulated.chain_arrays.SYMMETRIC_PAIRS`), so every term is an element-wise operation over
contiguous runs of B floats and the loops run over joints only. Each body's frame has z along its joint axis
(:mod:`core.articulated.chain_arrays`), so a joint's transform is the constant tree part X_T, applied as one
small matrix product (BLAS) over the batch, and a rotation about z (or a slide along it), a few element-wise
operations on the rows it turns. Joint positions, velocities, accelerations and forces are (n, B).

The equation of motion is M qddot + h + D qdot = tau with the armature on M's diagonal, D the joints' damping,
and gravity entered as the base's acceleration -g (Featherstone, section 5.3).
"""

from __future__ import annotations

import numpy as np
from simparity.core.articulated.chain_arrays import PACKED, SYMMETRIC_PAIRS, ChainArrays

WIDE_BATCH = 1024
"""Below this batch, the per-entry loops of ABA run as a few gathered operations over all entries at once: fewer
NumPy calls, which dominate small batches; above it, the loops win by touching fewer elements (at B = 10,000 the
gathered form took ~12 % longer on the iiwa, at B = 1 and 100 the loops ~2x and ~1.6x longer)."""

_PAIR_ROWS = np.array([r for r, _ in SYMMETRIC_PAIRS])
_PAIR_COLUMNS = np.array([c for _, c in SYMMETRIC_PAIRS])


def turn(x: np.ndarray, y: np.ndarray, c: np.ndarray, s: np.ndarray) -> None:
    """x, y <- c x - s y, s x + c y in place: rows x, y (views of one shape) turned by the angle of (c, s)."""
    sy, sx = s * y, s * x
    x *= c
    x -= sy
    y *= c
    y += sx


def turn_inertia(packed: np.ndarray, c: np.ndarray, s: np.ndarray) -> None:
    """R I R^T in place for packed symmetric 6 x 6 matrices (21, B) and R = diag(Rz, Rz), Rz the rotation about
    z by the angle of (c, s): rows paired with z turn once, the 2 x 2 blocks [[a, b], [e, d]] of x and y rows
    keep their trace and antisymmetric part and turn their symmetric traceless part by twice the angle."""
    turn(packed[0:4], packed[4:8], c, s)
    a, d, b, e = packed[8:11], packed[11:14], packed[14:17], packed[17]
    half_cos2, half_sin2 = 0.5 * (c - s) * (c + s), c * s
    mean = (a + d) * 0.5
    m2, n2 = a - d, b + b
    np.add(b[2], e, out=n2[2])
    anti = (b[2] - e) * 0.5
    m_new = m2 * half_cos2 - n2 * half_sin2
    n_new = m2 * half_sin2 + n2 * half_cos2
    np.add(mean, m_new, out=a)
    np.subtract(mean, m_new, out=d)
    b[:] = n_new
    b[2] += anti
    np.subtract(n_new[2], anti, out=e)


def slide_inertia(packed: np.ndarray, q: np.ndarray) -> np.ndarray:
    """X_J^T I X_J for a slide q (B,) [m] along z, X_J = 1 + q N (N: the linear part's -e_z x): packed (21, B) ->
    new packed (21, B). I + q (N^T I + I N) + q^2 N^T I N, entry by entry."""
    full = [[packed[PACKED[i, j]] for j in range(6)] for i in range(6)]

    def i_n(i: int, j: int) -> np.ndarray | float:  # (I N)[i, j]: N's only entries are N[3, 1] = 1, N[4, 0] = -1
        return full[i][3] if j == 1 else -full[i][4] if j == 0 else 0.0

    n_i_n = {(0, 0): full[4][4], (1, 1): full[3][3], (0, 1): -full[3][4]}
    out = np.empty_like(packed)
    for row, (i, j) in enumerate(SYMMETRIC_PAIRS):
        out[row] = full[i][j] + q * (i_n(i, j) + i_n(j, i)) + q * q * n_i_n.get((i, j), 0.0)
    return out


def cross_force(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    """v x* f for motion and force vectors (6, B): (omega x n + v_o x f, omega x f)."""
    w0, w1, w2, v0, v1, v2 = v
    n0, n1, n2, f0, f1, f2 = f
    out = np.empty_like(f)
    out[0] = w1 * n2 - w2 * n1 + v1 * f2 - v2 * f1
    out[1] = w2 * n0 - w0 * n2 + v2 * f0 - v0 * f2
    out[2] = w0 * n1 - w1 * n0 + v0 * f1 - v1 * f0
    out[3] = w1 * f2 - w2 * f1
    out[4] = w2 * f0 - w0 * f2
    out[5] = w0 * f1 - w1 * f0
    return out


class Recursive:
    """RNEA, CRBA and ABA of one chain under one gravity.

    Parameters
    ----------
    arrays : ChainArrays
    gravity_world : (3,) ndarray
        [m/s^2] in the base frame (zeros for none).
    """

    def __init__(self, arrays: ChainArrays, gravity_world: np.ndarray) -> None:
        self.arrays = arrays
        self._base_acceleration = np.concatenate([np.zeros(3), -np.asarray(gravity_world, dtype=float)])
        self._inertia_packed = [np.ascontiguousarray(row[:, None]) for row in arrays.inertia_packed]
        self._columns = [PACKED[:, k] for k in arrays.subspace]

    # -- the joint transforms --------------------------------------------------------------------------------

    def _to_child(self, i: int, parent: np.ndarray, cos: np.ndarray, sin: np.ndarray, q: np.ndarray) -> np.ndarray:
        """X_i m: a motion vector (6, B) of the parent body (the base for i = 0) in body i's coordinates."""
        out = self.arrays.tree_transform[i] @ parent
        if self.arrays.revolute[i]:
            turn(out[0::3], out[1::3], cos[i], -sin[i])
        else:
            out[3] += q[i] * out[1]
            out[4] -= q[i] * out[0]
        return out

    def _to_parent(self, i: int, force: np.ndarray, cos: np.ndarray, sin: np.ndarray, q: np.ndarray) -> np.ndarray:
        """X_i^T f: force vectors (6, ...) of body i (changed in place) in the parent's coordinates."""
        if self.arrays.revolute[i]:
            turn(force[0::3], force[1::3], cos[i], sin[i])
        else:
            force[0] -= q[i] * force[4]
            force[1] += q[i] * force[3]
        shape = force.shape
        return (self.arrays.tree_force_transform[i] @ force.reshape(6, -1)).reshape(shape)

    def _inertia_to_parent(self, i: int, packed: np.ndarray, cos: np.ndarray, sin: np.ndarray,
                           q: np.ndarray) -> np.ndarray:
        """X_i^T I X_i: a packed inertia (21, B) of body i (changed in place) in the parent's coordinates."""
        if self.arrays.revolute[i]:
            turn_inertia(packed, cos[i], sin[i])
        else:
            packed = slide_inertia(packed, q[i])
        return self.arrays.tree_congruence[i] @ packed

    def _velocities(self, q: np.ndarray, qdot: np.ndarray, cos: np.ndarray, sin: np.ndarray) -> list[np.ndarray]:
        """Each body's spatial velocity (6, B) in body coordinates."""
        out: list[np.ndarray] = []
        for i, k in enumerate(self.arrays.subspace):
            if i == 0:
                v = np.zeros((6, q.shape[1]))
                v[k] = qdot[0]
            else:
                v = self._to_child(i, out[-1], cos, sin, q)
                v[k] += qdot[i]
            out.append(v)
        return out

    def _bias_acceleration(self, i: int, v: np.ndarray, qdot: np.ndarray) -> list[tuple[int, np.ndarray]]:
        """c_i = v_i x S_i qdot_i as its nonzero rows (row, (B,)): qdot (w_y, -w_x, 0, v_y, -v_x, 0) for a
        revolute joint, qdot (0, 0, 0, w_y, -w_x, 0) for a prismatic one."""
        qd = qdot[i]
        if self.arrays.revolute[i]:
            return [(0, qd * v[1]), (1, -qd * v[0]), (3, qd * v[4]), (4, -qd * v[3])]
        return [(3, qd * v[1]), (4, -qd * v[0])]

    @staticmethod
    def _trig(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return np.cos(q), np.sin(q)

    # -- the algorithms ---------------------------------------------------------------------------------------

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray, damped: bool) -> np.ndarray:
        """RNEA: tau (n, B) = M qddot + h (+ D qdot when ``damped``), armature included in M."""
        arrays = self.arrays
        cos, sin = self._trig(q)
        velocities = self._velocities(q, qdot, cos, sin)
        forces = []
        base = np.broadcast_to(self._base_acceleration[:, None], (6, q.shape[1]))
        acceleration = base
        for i, (k, v) in enumerate(zip(arrays.subspace, velocities)):
            acceleration = self._to_child(i, acceleration, cos, sin, q)
            acceleration[k] += qddot[i]
            for row, value in self._bias_acceleration(i, v, qdot):
                acceleration[row] += value
            inertia = arrays.inertia[i]
            forces.append(inertia @ acceleration + cross_force(v, inertia @ v))
        tau = np.empty_like(q)
        for i in reversed(range(arrays.n)):
            tau[i] = forces[i][arrays.subspace[i]] + arrays.armature[i] * qddot[i]
            if damped:
                tau[i] += arrays.damping[i] * qdot[i]
            if i:
                forces[i - 1] += self._to_parent(i, forces[i], cos, sin, q)
        return tau

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """CRBA: M (n, n, B), armature included."""
        arrays, n = self.arrays, self.arrays.n
        cos, sin = self._trig(q)
        out = np.empty((n, n, q.shape[1]))
        carried: np.ndarray | None = None  # the composite inertia of the bodies beyond, in the current parent's
        columns: np.ndarray | None = None  # (6, n - i, B): I^c_j S_j of bodies j >= i, in body i's coordinates
        for i in reversed(range(n)):
            composite = (self._inertia_packed[i] + carried if carried is not None
                         else np.repeat(self._inertia_packed[i], q.shape[1], axis=1))
            column = composite[self._columns[i]][:, None]
            columns = column if columns is None else np.concatenate([column, columns], axis=1)
            out[i, i:] = columns[arrays.subspace[i]]
            out[i + 1:, i] = out[i, i + 1:]
            out[i, i] += arrays.armature[i]
            if i:
                carried = self._inertia_to_parent(i, composite, cos, sin, q)
                columns = self._to_parent(i, columns, cos, sin, q)
        return out

    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """ABA: qddot (n, B) = M^-1 (tau - h - D qdot)."""
        arrays, n, batch = self.arrays, self.arrays.n, q.shape[1]
        cos, sin = self._trig(q)
        velocities = self._velocities(q, qdot, cos, sin)
        biases = [self._bias_acceleration(i, v, qdot) for i, v in enumerate(velocities)]
        forces = [cross_force(v, arrays.inertia[i] @ v) for i, v in enumerate(velocities)]
        u = tau - arrays.damping[:, None] * qdot
        columns, inverse_d = [], []
        carried: np.ndarray | None = None
        for i in reversed(range(n)):
            k = arrays.subspace[i]
            articulated = self._inertia_packed[i] + (0.0 if carried is None else carried)
            column = articulated[self._columns[i]]
            if column.shape[1] != batch:
                column = np.array(np.broadcast_to(column, (6, batch)))
            inv_d = 1.0 / (column[k] + arrays.armature[i])
            u[i] -= forces[i][k]
            columns.append(column)
            inverse_d.append(inv_d)
            if not i:
                break
            scaled = column * inv_d
            force = forces[i]
            force += scaled * u[i]
            if batch < WIDE_BATCH:
                reduced = articulated - column[_PAIR_ROWS] * scaled[_PAIR_COLUMNS]
                for m, value in biases[i]:
                    force += reduced[PACKED[:, m]] * value
            else:
                reduced = np.empty((21, batch))
                for row, (r, c) in enumerate(SYMMETRIC_PAIRS):
                    np.multiply(column[r], scaled[c], out=reduced[row])
                    np.subtract(articulated[row], reduced[row], out=reduced[row])
                for r in range(6):
                    for m, value in biases[i]:
                        force[r] += reduced[PACKED[r, m]] * value
            carried = self._inertia_to_parent(i, reduced, cos, sin, q)
            forces[i - 1] += self._to_parent(i, force, cos, sin, q)
        columns.reverse()
        inverse_d.reverse()
        qddot = np.empty_like(q)
        acceleration = np.broadcast_to(self._base_acceleration[:, None], (6, batch))
        for i, k in enumerate(arrays.subspace):
            acceleration = self._to_child(i, acceleration, cos, sin, q)
            for row, value in biases[i]:
                acceleration[row] += value
            column = columns[i]
            if batch < WIDE_BATCH:
                dot = np.einsum("rb,rb->b", column, acceleration)
            else:
                dot = column[0] * acceleration[0]
                for r in range(1, 6):
                    dot += column[r] * acceleration[r]
            np.multiply(u[i] - dot, inverse_d[i], out=qddot[i])
            acceleration[k] += qddot[i]
        return qddot

    def kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(B,) [J]: sum over bodies of 1/2 m |v_c|^2 + 1/2 omega^T I_c omega from the forward pass's body
        velocities (v_c = v_o + omega x c in body coordinates)."""
        arrays = self.arrays
        cos, sin = self._trig(q)
        energy = np.zeros(q.shape[1])
        for i, v in enumerate(self._velocities(q, qdot, cos, sin)):
            w, c = v[:3], arrays.com_body[i]
            v_com = v[3:] + np.stack([w[1] * c[2] - w[2] * c[1], w[2] * c[0] - w[0] * c[2],
                                      w[0] * c[1] - w[1] * c[0]])
            spin = arrays.inertia_com_body[i] @ w
            energy += 0.5 * (arrays.mass[i] * np.sum(v_com * v_com, axis=0) + np.sum(w * spin, axis=0))
        return energy

