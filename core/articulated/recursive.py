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

The tree is Featherstone's: body i's parent is ``parents[i]`` (:attr:`ChainArrays.parents`, -1 for the base,
every parent numbered before its children; a chain's is i - 1), and every recursion indexes it, so a branched
tree runs as a chain does. The key to the names (Featherstone's symbols, chapters 5-7):

- ``parents[i]``: lambda(i), the parent body (-1: the fixed base);
- ``_to_child(i, m)``: X_i m = X_J(q_i) X_T,i m, a motion vector of the parent in body i's axes
  (:meth:`Recursive._from_parent`: the parent's acceleration, the base's for a root);
- ``_to_parent(i, f)``: X_i^T f, a force of body i in the parent's axes; ``_inertia_to_parent``: X_i^T I X_i;
- ``subspace[i]`` = k: S_i = e_k, the joint's motion subspace (:data:`core.articulated.chain_arrays.ANGULAR_Z`,
  :data:`~core.articulated.chain_arrays.LINEAR_Z`); ``_columns[i]``: the packed rows of I e_k;
- ``velocities[i]``: v_i; ``_bias_acceleration``: c_i = v_i x S_i qdot_i; ``inertia[i]``: I_i;
- CRBA: ``composite``: I^c_i, the composite inertia of i's subtree; ``columns``: I^c_j S_j of the bodies j of
  that subtree, in body i's axes (M_ij = S_i^T X I^c_j S_j);
- ABA: ``articulated``: I^A_i; ``bias_forces[i]``: p^A_i (v_i x* I_i v_i, then the children's share);
  ``U[i]``: U_i = I^A_i S_i; ``inverse_D[i]``: D_i^-1 = (S_i^T U_i + armature_i)^-1; ``u[i]``: u_i = tau_i -
  damping_i qdot_i - S_i^T p^A_i; ``reduced``: I^a_i = I^A_i - U_i D_i^-1 U_i^T; ``force``: p^a_i = p^A_i +
  I^a_i c_i + U_i D_i^-1 u_i; ``carried[i]``: the sum over i's children j of X_j^T I^a_j X_j, in i's axes.
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
    mean = a + d
    mean *= 0.5
    m2, n2 = a - d, b + b
    np.add(b[2], e, out=n2[2])
    anti = b[2] - e
    anti *= 0.5
    m_new, scratch = m2 * half_cos2, n2 * half_sin2
    m_new -= scratch
    np.multiply(m2, half_sin2, out=b)  # b <- n_new = m2 sin2 + n2 cos2 (m2, n2 are copies)
    np.multiply(n2, half_cos2, out=scratch)
    b += scratch
    np.add(mean, m_new, out=a)
    np.subtract(mean, m_new, out=d)
    np.subtract(b[2], anti, out=e)
    b[2] += anti


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
    scratch = np.empty_like(f[0])
    # each row's products summed left to right, as written: out[0] = w1 n2 - w2 n1 + v1 f2 - v2 f1, ...
    for row, terms in ((0, ((w1, n2), (w2, n1), (v1, f2), (v2, f1))), (1, ((w2, n0), (w0, n2), (v2, f0), (v0, f2))),
                       (2, ((w0, n1), (w1, n0), (v0, f1), (v1, f0))), (3, ((w1, f2), (w2, f1))),
                       (4, ((w2, f0), (w0, f2))), (5, ((w0, f1), (w1, f0)))):
        np.multiply(*terms[0], out=out[row])
        for sign, (a, b) in zip((-1, 1, -1), terms[1:]):
            np.multiply(a, b, out=scratch)
            if sign < 0:
                out[row] -= scratch
            else:
                out[row] += scratch
    return out


def _span(bodies: list[int]) -> slice | list[int]:
    """The bodies as a slice when they are consecutive (a chain's, a depth-first tree's subtrees), else as they
    are: a slice copies rows faster than an index list."""
    first = bodies[0]
    return slice(first, first + len(bodies)) if bodies == list(range(first, first + len(bodies))) else bodies


def unpack_symmetric(packed: np.ndarray) -> np.ndarray:
    """(21, B) packed symmetric 6 x 6 matrices -> (B, 6, 6)."""
    return np.ascontiguousarray(packed[PACKED].transpose(2, 0, 1))


class FloatingBase:
    """The base body of ABA's floating-base pass: its velocity, its own inertia and the wrench applied to it, and
    what its children carry into it (Featherstone, section 9.3: I^A_0 = I_0 + sum X^T I^a_i X, p^A_0 = v_0 x* I_0
    v_0 - f_0 + sum X^T p^a_i; then a_0 = -(I^A_0)^-1 p^A_0).

    Parameters
    ----------
    velocity : (6, B) ndarray
        v_0 in base coordinates.
    inertia_packed : (21,) ndarray
        I_0, the base body's spatial inertia about its origin in base coordinates, packed.
    inertia : (6, 6) ndarray
        The same, unpacked.
    applied : (6, B) ndarray
        f_0, the wrench applied to the base (torque about its origin, force), in base coordinates.
    """

    def __init__(self, velocity: np.ndarray, inertia_packed: np.ndarray, inertia: np.ndarray,
                 applied: np.ndarray) -> None:
        self.velocity = velocity
        self.articulated = np.repeat(np.asarray(inertia_packed, dtype=float)[:, None], velocity.shape[1], axis=1)
        self.bias = cross_force(velocity, inertia @ velocity) - applied

    def solve(self) -> np.ndarray:
        """a_0 (6, B) in base coordinates, gravity's -g included (the fictitious base acceleration): contiguous."""
        return np.ascontiguousarray(-np.linalg.solve(unpack_symmetric(self.articulated),
                                                     self.bias.T[:, :, None])[:, :, 0].T)


class Recursive:
    """RNEA, CRBA and ABA of one kinematic tree (a chain today) under one gravity.

    Parameters
    ----------
    arrays : ChainArrays
        Its :attr:`~ChainArrays.parents` number every parent before its children.
    gravity_world : (3,) ndarray
        [m/s^2] in the base frame (zeros for none).
    """

    def __init__(self, arrays: ChainArrays, gravity_world: np.ndarray) -> None:
        self.arrays = arrays
        self.parents = [int(p) for p in arrays.parents]
        if any(not -1 <= p < i for i, p in enumerate(self.parents)):
            raise ValueError(f"parents {self.parents} do not number each parent (or -1, the base) before its child")
        self._is_chain = self.parents == list(range(-1, arrays.n - 1))
        # The last child of each body: after it, the forward passes let the body's acceleration go (a chain keeps
        # one live (6, B) array, as large batches need: memory that stays in cache).
        self._last_child = {parent: i for i, parent in enumerate(self.parents) if parent >= 0}
        self._base_acceleration = np.concatenate([np.zeros(3), -np.asarray(gravity_world, dtype=float)])
        self._inertia_packed = [np.ascontiguousarray(row[:, None]) for row in arrays.inertia_packed]
        self._columns = [PACKED[:, k] for k in arrays.subspace]

    # -- the joint transforms --------------------------------------------------------------------------------

    def _to_child(self, i: int, parent: np.ndarray, cos: np.ndarray, sin: np.ndarray, q: np.ndarray) -> np.ndarray:
        """X_i m: a motion vector (6, B) of the parent body (the base for a root) in body i's coordinates."""
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

    def _velocities(self, q: np.ndarray, qdot: np.ndarray, cos: np.ndarray, sin: np.ndarray,
                    base_velocity: np.ndarray | None = None) -> list[np.ndarray]:
        """Each body's spatial velocity v_i (6, B) in body coordinates: v_i = X_i v_lambda(i) + S_i qdot_i, the base's
        ``base_velocity`` (6, B) in base coordinates (None: the base does not move)."""
        out: list[np.ndarray] = []
        for i, (k, parent) in enumerate(zip(self.arrays.subspace, self.parents)):
            if parent < 0 and base_velocity is not None:
                v = self._to_child(i, base_velocity, cos, sin, q)
                v[k] += qdot[i]
            elif parent < 0:  # the base does not move
                v = np.zeros((6, q.shape[1]))
                v[k] = qdot[i]
            else:
                v = self._to_child(i, out[parent], cos, sin, q)
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

    def _from_parent(self, i: int, accelerations: list[np.ndarray | None], base: np.ndarray, cos: np.ndarray,
                     sin: np.ndarray, q: np.ndarray) -> np.ndarray:
        """X_i a_lambda(i): the parent's acceleration (the base's for a root) in body i's coordinates, a new array;
        the parent's is let go after its last child."""
        parent = self.parents[i]
        if parent < 0:
            return self._to_child(i, base, cos, sin, q)
        held = accelerations[parent]
        assert held is not None, "a parent is numbered before its children"
        if self._last_child[parent] == i:
            accelerations[parent] = None
        return self._to_child(i, held, cos, sin, q)

    @staticmethod
    def _take(carried: list[np.ndarray | None], i: int) -> np.ndarray | None:
        """carried[i], let go in the list (the backward passes use it once)."""
        held, carried[i] = carried[i], None
        return held

    @staticmethod
    def _add_to(carried: list[np.ndarray | None], parent: int, value: np.ndarray) -> None:
        """carried[parent] += value, the first child's value itself (a chain's parent has one child: no sum)."""
        held = carried[parent]
        carried[parent] = value if held is None else held + value

    def _base(self, batch: int) -> np.ndarray:
        """The base's acceleration for each of ``batch`` states (6, B), contiguous: a BLAS product takes it as it is
        (a broadcast view of one column would be copied, or multiplied ~8x slower)."""
        return np.repeat(self._base_acceleration[:, None], batch, axis=1)

    @staticmethod
    def _trig(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return np.cos(q), np.sin(q)

    # -- the algorithms ---------------------------------------------------------------------------------------

    def inverse_dynamics(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray, damped: bool) -> np.ndarray:
        """RNEA: tau (n, B) = M qddot + h (+ D qdot when ``damped``), armature included in M."""
        return self.rnea(q, qdot, qddot, damped, self._base(q.shape[1]))[0]

    def rnea(self, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray, damped: bool, base: np.ndarray,
             base_velocity: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """RNEA with the base at acceleration ``base`` (6, B) (gravity's -g included) and velocity ``base_velocity``
        (6, B) (None: at rest), both in base coordinates: (tau (n, B), the force (6, B) the root bodies exert on the
        base, in base coordinates: sum over roots of X_i^T f_i)."""
        arrays = self.arrays
        cos, sin = self._trig(q)
        velocities = self._velocities(q, qdot, cos, sin, base_velocity)
        forces: list[np.ndarray] = []
        accelerations: list[np.ndarray | None] = []
        on_base = np.zeros((6, q.shape[1]))
        for i, (k, v) in enumerate(zip(arrays.subspace, velocities)):
            acceleration = self._from_parent(i, accelerations, base, cos, sin, q)
            acceleration[k] += qddot[i]
            for row, value in self._bias_acceleration(i, v, qdot):
                acceleration[row] += value
            accelerations.append(acceleration)
            inertia = arrays.inertia[i]
            forces.append(inertia @ acceleration + cross_force(v, inertia @ v))
        tau = np.empty_like(q)
        for i in reversed(range(arrays.n)):
            tau[i] = forces[i][arrays.subspace[i]] + arrays.armature[i] * qddot[i]
            if damped:
                tau[i] += arrays.damping[i] * qdot[i]
            parent = self.parents[i]
            if parent >= 0:
                forces[parent] += self._to_parent(i, forces[i], cos, sin, q)
            elif base_velocity is not None:
                on_base += self._to_parent(i, forces[i], cos, sin, q)
        return tau, on_base

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """CRBA: M (n, n, B), armature included. Entries of two bodies on different branches are 0."""
        return self.crba(q, False)[0]

    def crba(self, q: np.ndarray, floating: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """CRBA: (M (n, n, B) of the joints, armature included; for a ``floating`` base also the composite inertia
        of every body on it (21, B) packed and the columns X^T I^c_j S_j of every joint j (6, n, B), both in base
        coordinates: the base's rows of the floating-base M; empty arrays otherwise)."""
        arrays, n, batch = self.arrays, self.arrays.n, q.shape[1]
        on_base = np.zeros((21, batch)) if floating else np.empty(0)
        base_columns = np.zeros((6, n, batch)) if floating else np.empty(0)
        cos, sin = self._trig(q)
        out = np.empty((n, n, batch)) if self._is_chain else np.zeros((n, n, batch))  # a chain fills every entry
        carried: list[np.ndarray | None] = [None] * n  # the children's composite inertias, in body i's coordinates
        # I^c_j S_j of every body j of the subtrees of body i's children, in body i's coordinates, and those j
        beyond: list[list[np.ndarray]] = [[] for _ in range(n)]
        beyond_bodies: list[list[int]] = [[] for _ in range(n)]
        for i in reversed(range(n)):
            held = self._take(carried, i)
            composite = (self._inertia_packed[i] + held if held is not None
                         else np.repeat(self._inertia_packed[i], batch, axis=1))
            column = composite[self._columns[i]][:, None]
            columns = np.concatenate([column] + beyond[i], axis=1) if beyond[i] else column  # (6, subtree, B)
            beyond[i] = []
            subtree = [i] + beyond_bodies[i]
            bodies = _span(subtree)
            out[i, bodies] = columns[arrays.subspace[i]]
            out[bodies, i] = out[i, bodies]  # rewrites (i, i) with itself
            out[i, i] += arrays.armature[i]
            parent = self.parents[i]
            if parent >= 0:
                self._add_to(carried, parent, self._inertia_to_parent(i, composite, cos, sin, q))
                beyond[parent].append(self._to_parent(i, columns, cos, sin, q))
                beyond_bodies[parent] += subtree
            elif floating:
                on_base += self._inertia_to_parent(i, composite, cos, sin, q)
                base_columns[:, subtree] = self._to_parent(i, columns, cos, sin, q)
        return out, on_base, base_columns

    def forward_dynamics(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
        """ABA: qddot (n, B) = M^-1 (tau - h - D qdot)."""
        return self.aba(q, qdot, tau)[0]

    def aba(self, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray, floating: FloatingBase | None = None
            ) -> tuple[np.ndarray, np.ndarray]:
        """ABA: (qddot (n, B), the base's acceleration (6, B) in base coordinates, gravity's -g included: the fixed
        base's, or for a ``floating`` base its solution (Featherstone, section 9.3))."""
        arrays, n, batch = self.arrays, self.arrays.n, q.shape[1]
        cos, sin = self._trig(q)
        velocities = self._velocities(q, qdot, cos, sin, None if floating is None else floating.velocity)
        biases = [self._bias_acceleration(i, v, qdot) for i, v in enumerate(velocities)]
        bias_forces = [cross_force(v, arrays.inertia[i] @ v) for i, v in enumerate(velocities)]  # p^A_i
        u = tau - arrays.damping[:, None] * qdot
        U: list[np.ndarray] = [np.empty(0)] * n
        inverse_D: list[np.ndarray] = [np.empty(0)] * n
        carried: list[np.ndarray | None] = [None] * n  # the children's I^a, in body i's coordinates
        for i in reversed(range(n)):
            k = arrays.subspace[i]
            held = self._take(carried, i)
            if held is None:
                articulated = self._inertia_packed[i] + 0.0  # I^A_i, (21, 1) until it meets the batch
            else:
                articulated = held
                articulated += self._inertia_packed[i]  # I^A_i in place: the children's sum is this body's own
            U_i = articulated[self._columns[i]]
            if U_i.shape[1] != batch:
                U_i = np.array(np.broadcast_to(U_i, (6, batch)))
            inverse_D[i] = 1.0 / (U_i[k] + arrays.armature[i])
            u[i] -= bias_forces[i][k]
            U[i] = U_i
            parent = self.parents[i]
            if parent < 0 and floating is None:
                continue
            scaled = U_i * inverse_D[i]
            force = bias_forces[i]
            force += scaled * u[i]
            if batch < WIDE_BATCH:
                reduced = articulated - U_i[_PAIR_ROWS] * scaled[_PAIR_COLUMNS]
                for m, value in biases[i]:
                    force += reduced[PACKED[:, m]] * value
            else:
                # I^a_i in place of I^A_i (U_i is a copy), through one (B,) scratch row: no (21, B) temporary
                reduced = articulated if articulated.shape[1] == batch else np.repeat(articulated, batch, axis=1)
                scratch = np.empty(batch)
                for row, (r, c) in enumerate(SYMMETRIC_PAIRS):
                    np.multiply(U_i[r], scaled[c], out=scratch)
                    reduced[row] -= scratch
                for r in range(6):
                    for m, value in biases[i]:
                        np.multiply(reduced[PACKED[r, m]], value, out=scratch)
                        force[r] += scratch
            if parent < 0:
                assert floating is not None
                floating.articulated += self._inertia_to_parent(i, reduced, cos, sin, q)
                floating.bias += self._to_parent(i, force, cos, sin, q)
                continue
            self._add_to(carried, parent, self._inertia_to_parent(i, reduced, cos, sin, q))
            bias_forces[parent] += self._to_parent(i, force, cos, sin, q)
        qddot = np.empty_like(q)
        accelerations: list[np.ndarray | None] = []
        base = self._base(batch) if floating is None else floating.solve()
        for i, k in enumerate(arrays.subspace):
            acceleration = self._from_parent(i, accelerations, base, cos, sin, q)  # a'_i before S_i qddot_i
            for row, value in biases[i]:
                acceleration[row] += value
            if batch < WIDE_BATCH:
                dot = np.einsum("rb,rb->b", U[i], acceleration)
            else:
                dot = U[i][0] * acceleration[0]
                for r in range(1, 6):
                    dot += U[i][r] * acceleration[r]
            np.multiply(u[i] - dot, inverse_D[i], out=qddot[i])
            acceleration[k] += qddot[i]
            accelerations.append(acceleration)
        return qddot, base

    def momentum(self, q: np.ndarray, qdot: np.ndarray, base_velocity: np.ndarray | None = None) -> np.ndarray:
        """(6, B): the bodies' spatial momenta I_i v_i, each carried to the base (X_i^T) and summed: the chain's
        momentum (angular about the base origin, linear) in base coordinates, the base's own not included."""
        cos, sin = self._trig(q)
        momenta = [self.arrays.inertia[i] @ v for i, v in enumerate(self._velocities(q, qdot, cos, sin, base_velocity))]
        total = np.zeros((6, q.shape[1]))
        for i in reversed(range(self.arrays.n)):
            parent = self.parents[i]
            carried = self._to_parent(i, momenta[i], cos, sin, q)
            if parent >= 0:
                momenta[parent] += carried
            else:
                total += carried
        return total

    def kinetic_energy(self, q: np.ndarray, qdot: np.ndarray, base_velocity: np.ndarray | None = None) -> np.ndarray:
        """(B,) [J]: sum over bodies of 1/2 m |v_c|^2 + 1/2 omega^T I_c omega from the forward pass's body
        velocities (v_c = v_o + omega x c in body coordinates); the base moving at ``base_velocity`` (6, B) (None: at
        rest; its own energy is not included)."""
        arrays = self.arrays
        cos, sin = self._trig(q)
        energy = np.zeros(q.shape[1])
        for i, v in enumerate(self._velocities(q, qdot, cos, sin, base_velocity)):
            w, c = v[:3], arrays.com_body[i]
            v_com = v[3:] + np.stack([w[1] * c[2] - w[2] * c[1], w[2] * c[0] - w[0] * c[2],
                                      w[0] * c[1] - w[1] * c[0]])
            spin = arrays.inertia_com_body[i] @ w
            energy += 0.5 * (arrays.mass[i] * np.sum(v_com * v_com, axis=0) + np.sum(w * spin, axis=0))
        return energy

