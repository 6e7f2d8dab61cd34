"""The lecture's joint-space dynamics: M and h summed over the links' centre-of-mass Jacobians, O(n^3).

With the world-frame Jacobians of link i's centre of mass, linear Jv_i and angular Jw_i (3, n) (column j zero
for joints beyond i), its mass m_i and its inertia about the centre of mass in world axes
I_i^world = R_i I_i R_i^T:

    M(q)      = sum_i m_i Jv_i^T Jv_i + Jw_i^T I_i^world Jw_i   (+ the armature on the diagonal)
    h(q, qd)  = sum_i Jv_i^T m_i (dJv_i qd - g) + Jw_i^T (I_i^world dJw_i qd + w_i x I_i^world w_i)

with w_i = Jw_i qd. The Jacobians' time derivatives are in closed form: a joint axis a_j turns with its link,
da_j/dt = w_j x a_j, so a revolute column (a_j x (p_i - P_j), a_j) has the derivative
(da_j x (p_i - P_j) + a_j x (v_i - v_Pj), da_j), and a prismatic column (a_j, 0) has (da_j, 0), where p_i, v_i are
the centre of mass's position and velocity and P_j, v_Pj joint j's. Frames come from :mod:`core.kinematics`.
Arrays are batch-major: (B, links, 3, joints).
"""

from __future__ import annotations

import numpy as np
from simparity.core.kinematics import joint_frames
from simparity.core.model.scenes.chain import Chain


class JacobianSum:
    """The lecture's M, h and link energies of one chain under one gravity.

    Parameters
    ----------
    chain : Chain
        With mass properties on every link.
    gravity_world : (3,) ndarray
        [m/s^2] in the base frame (zeros for none).
    """

    def __init__(self, chain: Chain, gravity_world: np.ndarray) -> None:
        links = [j.link for j in chain.joints]
        if any(link is None for link in links):
            raise ValueError(f"chain '{chain.name}': {chain.dynamics_problem()}")
        self._chain = chain
        self._gravity = np.asarray(gravity_world, dtype=float)
        self._mass = np.array([link.mass for link in links if link is not None])
        self._com = np.array([link.com_xyz for link in links if link is not None]).reshape(-1, 3)
        self._inertia = np.array([link.inertia_com for link in links if link is not None]).reshape(-1, 3, 3)
        self._revolute = np.array([j.type == "revolute" for j in chain.joints], dtype=bool)
        self._armature = np.array([j.armature for j in chain.joints])
        n = chain.n_joints
        self._moved_by = np.tril(np.ones((n, n)))  # [link i, joint j]: 1 when joint j moves link i (j <= i)

    def _kinematics(self, q: np.ndarray, qdot: np.ndarray | None) -> dict[str, np.ndarray]:
        """Centre-of-mass Jacobians (B, n, 3, n), world inertias (B, n, 3, 3) and, given qdot, the velocities
        and the Jacobians' time derivatives."""
        positions, rotations, axes = joint_frames(self._chain, q)
        origins, rotations = positions[:, :-1], rotations[:, :-1]  # joint positions P_j, link rotations R_i
        com = origins + np.einsum("bikl,il->bik", rotations, self._com)
        inertia_world = rotations @ self._inertia @ np.swapaxes(rotations, -1, -2)
        jv = self._point_jacobian(com, origins, axes)
        jw = np.where(self._revolute[None, None, :, None], axes[:, None], 0.0) * self._moved_by[None, :, :, None]
        jw = np.swapaxes(jw, -1, -2)
        out = {"jv": jv, "jw": jw, "inertia_world": inertia_world}
        if qdot is None:
            return out
        v_com = jv @ qdot[:, None, :, None]
        w = (jw @ qdot[:, None, :, None])[..., 0]
        v_origin = (self._point_jacobian(origins, origins, axes) @ qdot[:, None, :, None])[..., 0]
        axis_rate = np.cross(w, axes)  # da_j/dt = w_j x a_j, (B, n, 3)
        lever = com[:, :, None, :] - origins[:, None, :, :]  # p_i - P_j, (B, i, j, 3)
        lever_rate = v_com[..., 0][:, :, None, :] - v_origin[:, None, :, :]
        revolute_rate = (np.cross(axis_rate[:, None], lever) + np.cross(axes[:, None], lever_rate))
        djv = np.where(self._revolute[None, None, :, None], revolute_rate, axis_rate[:, None])
        djw = np.where(self._revolute[None, None, :, None], axis_rate[:, None], 0.0)
        moved = self._moved_by[None, :, :, None]
        out.update(v_com=v_com[..., 0], w=w, djv=np.swapaxes(djv * moved, -1, -2),
                   djw=np.swapaxes(djw * moved, -1, -2))
        return out

    def _point_jacobian(self, points: np.ndarray, origins: np.ndarray, axes: np.ndarray) -> np.ndarray:
        """Linear Jacobians (B, n, 3, n) of one point per link (B, n, 3): column j is a_j x (point - P_j)
        (revolute) or a_j (prismatic) for joints j <= i, zero beyond."""
        lever = points[:, :, None, :] - origins[:, None, :, :]
        columns = np.where(self._revolute[None, None, :, None], np.cross(axes[:, None], lever), axes[:, None])
        return np.swapaxes(columns * self._moved_by[None, :, :, None], -1, -2)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """M (B, n, n), armature included."""
        k = self._kinematics(q, None)
        jv, jw = k["jv"], k["jw"]
        translational = np.einsum("i,bikm,bikn->bmn", self._mass, jv, jv)
        rotational = np.einsum("bikm,bikl,biln->bmn", jw, k["inertia_world"], jw)
        return translational + rotational + np.diag(self._armature)

    def bias_forces(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """h = C qdot + g (B, n)."""
        k = self._kinematics(q, qdot)
        com_acceleration = (k["djv"] @ qdot[:, None, :, None])[..., 0] - self._gravity
        linear = np.einsum("bikm,i,bik->bm", k["jv"], self._mass, com_acceleration)
        inertia, w = k["inertia_world"], k["w"]
        spin = (inertia @ w[..., None])[..., 0]
        moment = (inertia @ (k["djw"] @ qdot[:, None, :, None]))[..., 0] + np.cross(w, spin)
        return linear + np.einsum("bikm,bik->bm", k["jw"], moment)

    def kinetic_energy(self, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
        """(B,) [J]: sum of 1/2 m |v_c|^2 + 1/2 w^T I w over the links, velocities from the Jacobians."""
        k = self._kinematics(q, qdot)
        v, w = k["v_com"], k["w"]
        spin = (k["inertia_world"] @ w[..., None])[..., 0]
        return 0.5 * (np.einsum("i,bik,bik->b", self._mass, v, v) + np.einsum("bik,bik->b", w, spin))
