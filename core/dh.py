"""Serial chains from Denavit-Hartenberg tables, and the direct DH product to check them.

Two conventions, row i = 1..n of the table:

- ``"standard"`` (Denavit-Hartenberg, Spong): T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i);
  joint i moves about / along z_{i-1}.
- ``"modified"`` (Craig): T_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i); row i of the
  arrays holds alpha_{i-1} and a_{i-1}, so ``a[0]`` and ``alpha[0]`` place joint 1 in the base
  frame. Joint i moves about / along z_i.

The base-to-flange transform is T_1 T_2 ... T_n. For a revolute joint theta_i =
theta_offset_i + q_i and d_i is constant; for a prismatic joint d_i = d_i + q_i and
theta_i = theta_offset_i is constant. So the chain's q = 0 is exactly the table's
theta = theta_offset, d = d.

As a :class:`~core.scene.Chain` (URDF semantics), joint i's frame is the frame reached
before Rz(q_i) / Tz(q_i): joint i's origin is the fixed part of the previous row
(standard: Tx(a_{i-1}) Rx(alpha_{i-1}); modified: Rx(alpha_{i-1}) Tx(a_{i-1})) followed by
Rz(theta_offset_i) Tz(d_i), and its axis is z. Rz(q) and Tz(d) commute, so moving Tz(d_i)
before the joint motion changes nothing. The end-effector transform is Tx(a_n) Rx(alpha_n)
(standard) or the identity (modified).
"""

from __future__ import annotations

from types import MappingProxyType

import numpy as np

from simparity.core.model.errors import SceneError
from simparity.core.model.scenes.chain import Chain, Joint

CONVENTIONS = ("standard", "modified")
JOINT_TYPES = ("revolute", "prismatic")

UR5_DH = MappingProxyType({
    "name": "ur5",
    "a": (0.0, -0.425, -0.39225, 0.0, 0.0, 0.0),
    "alpha": (np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0),
    "d": (0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823),
    "theta_offset": (0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    "convention": "standard",
})
"""Universal Robots' published standard DH parameters of the UR5 [m, rad]; use as
``chain_from_dh(**UR5_DH)``."""

_SOURCE = "<code>"


def _rot_x(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros(np.shape(angle) + (4, 4))
    out[..., 0, 0] = out[..., 3, 3] = 1.0
    out[..., 1, 1], out[..., 1, 2], out[..., 2, 1], out[..., 2, 2] = c, -s, s, c
    return out


def _rot_z(angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros(np.shape(angle) + (4, 4))
    out[..., 2, 2] = out[..., 3, 3] = 1.0
    out[..., 0, 0], out[..., 0, 1], out[..., 1, 0], out[..., 1, 1] = c, -s, s, c
    return out


def _trans(axis: int, distance: np.ndarray) -> np.ndarray:
    out = np.zeros(np.shape(distance) + (4, 4))
    out[..., [0, 1, 2, 3], [0, 1, 2, 3]] = 1.0
    out[..., axis, 3] = distance
    return out


def dh_forward(a, alpha, d, theta, convention: str = "standard") -> np.ndarray:
    """Base-to-flange transform as the plain product of the DH matrices T_1 ... T_n.

    Parameters
    ----------
    a, alpha : (n,) array_like
        Link lengths [m] and twists [rad] (modified: row i holds a_{i-1}, alpha_{i-1}).
    d, theta : (..., n) array_like
        Link offsets [m] and joint angles [rad] of each configuration, the joint
        variables already added (broadcast against each other).
    convention : {"standard", "modified"}

    Returns
    -------
    (..., 4, 4) ndarray
        Homogeneous transform, flange frame to base frame.
    """
    _check_convention(convention)
    a, alpha = np.asarray(a, dtype=float), np.asarray(alpha, dtype=float)
    d, theta = np.broadcast_arrays(np.asarray(d, dtype=float), np.asarray(theta, dtype=float))
    out = np.broadcast_to(np.eye(4), d.shape[:-1] + (4, 4))
    for i in range(a.shape[0]):
        if convention == "standard":
            row = _rot_z(theta[..., i]) @ _trans(2, d[..., i]) @ _trans(0, a[i]) @ _rot_x(alpha[i])
        else:
            row = _rot_x(alpha[i]) @ _trans(0, a[i]) @ _rot_z(theta[..., i]) @ _trans(2, d[..., i])
        out = out @ row
    return out


def chain_from_dh(
    name: str,
    a,
    alpha,
    d,
    theta_offset,
    convention: str = "standard",
    joint_types=None,
    limits=None,
) -> Chain:
    """Build the :class:`~core.scene.Chain` of a DH table (see the module docstring).

    Parameters
    ----------
    name : str
    a, alpha, d, theta_offset : (n,) array_like
        The table [m, rad, m, rad]; values at q = 0.
    convention : {"standard", "modified"}
    joint_types : sequence of {"revolute", "prismatic"}, optional
        Default: all revolute.
    limits : (n, 2) array_like, optional
        (lower, upper) of each joint variable q_i [rad or m]; default unlimited.

    Returns
    -------
    Chain
        Joints ``joint_1`` ... ``joint_n``, end effector ``flange``.

    Raises
    ------
    SceneError
        For arrays of different lengths or non-finite values, an unknown convention or
        joint type, or limits with lower > upper.
    """
    _check_convention(convention)
    table = {}
    for key, values in (("a", a), ("alpha", alpha), ("d", d), ("theta_offset", theta_offset)):
        values = np.asarray(values, dtype=float)
        if values.ndim != 1 or not np.all(np.isfinite(values)):
            raise SceneError(_SOURCE, key, f"got {values!r}", "a 1-D array of finite numbers")
        table[key] = values
    n = table["a"].shape[0]
    if any(v.shape != (n,) for v in table.values()) or n == 0:
        raise SceneError(_SOURCE, "a, alpha, d, theta_offset", "the arrays differ in length or are empty",
                         "four arrays of the same length n >= 1")
    joint_types = ("revolute",) * n if joint_types is None else tuple(joint_types)
    if len(joint_types) != n or any(t not in JOINT_TYPES for t in joint_types):
        raise SceneError(_SOURCE, "joint_types", f"got {joint_types!r}", f"{n} of {', '.join(JOINT_TYPES)}")
    limits = np.tile([-np.inf, np.inf], (n, 1)) if limits is None else np.asarray(limits, dtype=float)
    if limits.shape != (n, 2) or np.any(np.isnan(limits)) or np.any(limits[:, 0] > limits[:, 1]):
        raise SceneError(_SOURCE, "limits", f"got {limits!r}", f"({n}, 2) rows of lower <= upper")

    joints = []
    before = np.eye(4)  # fixed transform of the previous row still to be placed
    for i in range(n):
        if convention == "modified":
            before = before @ _rot_x(table["alpha"][i]) @ _trans(0, table["a"][i])
        origin = before @ _rot_z(table["theta_offset"][i]) @ _trans(2, table["d"][i])
        joints.append(Joint(
            name=f"joint_{i + 1}", type=joint_types[i], axis=np.array([0.0, 0.0, 1.0]),
            origin_xyz=origin[:3, 3], origin_rotation=origin[:3, :3],
            lower=limits[i, 0], upper=limits[i, 1],
        ))
        before = (_trans(0, table["a"][i]) @ _rot_x(table["alpha"][i]) if convention == "standard"
                  else np.eye(4))
    return Chain(name, tuple(joints), end_effector_name="flange",
                 end_effector_xyz=before[:3, 3], end_effector_rotation=before[:3, :3])


def _check_convention(convention: str) -> None:
    if convention not in CONVENTIONS:
        raise SceneError(_SOURCE, "convention", f"unknown DH convention {convention!r}", ", ".join(CONVENTIONS))
