"""The truth of the dynamics' derivatives (issue #44): an RNEA of the references' own, written to run on complex
numbers, differentiated by complex step.

Complex-step differentiation: for f analytic and real on real inputs, df/dx = Im f(x + i h) / h + O(h^2) with no
subtraction, so h = :data:`STEP` (1e-30) leaves the derivative exact to the rounding of f itself. The RNEA here is
complex-safe: only +, -, *, sin, cos and matrix products (no ``abs``, ``np.linalg.norm``, ``cholesky``, ``vdot`` or
conjugation; no comparison on a perturbed value; nothing assigned into a float array), and it runs with
``ComplexWarning`` as an error (:func:`rnea`).

The model is NOT core's: it is the kinematic tree Pinocchio's URDF parser compiled from the file every engine reads
(:func:`references.pinocchio.joint_dynamics.chain_model`: joint placements, motion subspaces, spatial inertias with
fixed and held links merged, armature), read here as numbers, and every algorithm below is this module's own
(Featherstone's RNEA, spatial vectors (angular, linear) in body coordinates). Damping D q̇ is added to τ.

From it, batched over states and over the 3n complex directions at once:
∂τ/∂q, ∂τ/∂q̇ (damping included), M = ∂τ/∂q̈ (exact: τ is linear in q̈), and forward dynamics' derivatives by
∂q̈/∂x = -M⁻¹ ∂τ/∂x at q̈ = M⁻¹ (τ - h), ∂q̈/∂τ = M⁻¹.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from simparity.core.model.derivatives import DynamicsDerivatives
from simparity.core.model.scenes.chain import Chain
from simparity.references.common.scene_inputs import own_chain
from simparity.references.pinocchio.joint_dynamics import chain_model

STEP = 1e-30
"""The complex step h: far below any rounding of q, so h^2 terms vanish; Im f(x + i h) / h has no cancellation."""


@dataclass(frozen=True)
class Tree:
    """A kinematic tree as arrays (body i's parent numbered before it), read from Pinocchio's compiled model.

    Attributes
    ----------
    parents : list of int
        -1 for a body on the fixed base.
    rotation, translation : (N, 3, 3), (N, 3) ndarray
        Each joint frame's placement in its parent body's frame (Pinocchio's ``jointPlacements``).
    axis : (N, 3) ndarray
        The joint's unit axis in its own frame.
    revolute : (N,) bool ndarray
    inertia : (N, 6, 6) ndarray
        Each body's spatial inertia about its origin, body axes, (angular, linear) order.
    armature, damping : (N,) ndarray
    gravity : (3,) ndarray
        [m/s^2] in the base frame (a floating base's: in the world).
    columns : (N,) int ndarray
        The chain joint each body is (its velocity index among the chain's joints).
    base_inertia : (6, 6) ndarray or None
        A floating base's spatial inertia about its origin, base axes, (angular, linear); None for a fixed base.
    """

    parents: list[int]
    rotation: np.ndarray
    translation: np.ndarray
    axis: np.ndarray
    revolute: np.ndarray
    inertia: np.ndarray
    armature: np.ndarray
    damping: np.ndarray
    gravity: np.ndarray
    columns: np.ndarray
    base_inertia: np.ndarray | None = None


def _skew(v: np.ndarray) -> np.ndarray:
    """(..., 3, 3) [v]x of (..., 3), complex-safe."""
    zero = np.zeros_like(v[..., 0])
    return np.stack([np.stack([zero, -v[..., 2], v[..., 1]], -1), np.stack([v[..., 2], zero, -v[..., 0]], -1),
                     np.stack([-v[..., 1], v[..., 0], zero], -1)], -2)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b for (..., 3), written out (complex-safe)."""
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1], a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], -1)


def tree_from_chain(chain: Chain, gravity_world: np.ndarray | None) -> Tree:
    """The chain's tree as Pinocchio's parser compiled it; a floating base's free flyer (Pinocchio's joint 1) read as
    the base body (its inertia) and not as a joint."""
    built = chain_model(own_chain(chain), gravity_world)  # the scene's numbers as given, never core's derivations
    model = built.model
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    first = 2 if chain.floating_base else 1  # Pinocchio's joint 0 is the universe, 1 the free flyer if any
    bodies = range(first, model.njoints)
    axes, revolute = [], []
    for i in bodies:
        joint = model.joints[i]
        joint_data = joint.createData()
        joint.calc(joint_data, pin.neutral(model))
        subspace = np.asarray(joint_data.S).reshape(6, -1)[:, 0]  # Pinocchio's order: (linear, angular)
        turns = bool(np.any(subspace[3:] != 0))
        axes.append(subspace[3:] if turns else subspace[:3])
        revolute.append(turns)
    inertia = np.array([_spatial(model.inertias[i]) for i in bodies])
    column_of = {int(j): k for k, j in enumerate(built.joint_ids)}
    return Tree(parents=[int(model.parents[i]) - first for i in bodies],
                rotation=np.array([model.jointPlacements[i].rotation for i in bodies]),
                translation=np.array([model.jointPlacements[i].translation for i in bodies]),
                axis=np.array(axes), revolute=np.array(revolute), inertia=inertia,
                armature=np.array([model.armature[model.joints[i].idx_v] for i in bodies]),
                damping=np.array([built.damping[column_of[i]] for i in bodies]),
                gravity=np.zeros(3) if gravity_world is None else np.asarray(gravity_world, dtype=float),
                columns=np.array([column_of[i] for i in bodies]),
                base_inertia=_spatial(model.inertias[1]) if chain.floating_base else None)


def _spatial(inertia) -> np.ndarray:
    """(6, 6) spatial inertia about the body origin, (angular, linear), from Pinocchio's (mass, lever, I about the
    centre of mass)."""
    mass, lever = float(inertia.mass), np.asarray(inertia.lever, dtype=float)
    c = _skew(lever)
    out = np.zeros((6, 6))
    out[:3, :3] = np.asarray(inertia.inertia) - mass * c @ c
    out[:3, 3:], out[3:, :3], out[3:, 3:] = mass * c, -mass * c, mass * np.eye(3)
    return out


def _joint(tree: Tree, i: int, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(R (K, 3, 3), p (K, 3)): body i's axes and origin in its parent's frame at joint values q (K,) (complex)."""
    base_rotation, base_translation, axis = tree.rotation[i], tree.translation[i], tree.axis[i]
    if tree.revolute[i]:
        k = _skew(axis)
        turn = (np.eye(3) + np.sin(q)[:, None, None] * k + (1 - np.cos(q))[:, None, None] * (k @ k))
        return base_rotation @ turn, np.broadcast_to(base_translation, (len(q), 3)) + 0 * q[:, None]
    slide = q[:, None] * (base_rotation @ axis)
    return np.broadcast_to(base_rotation, (len(q), 3, 3)) + 0 * q[:, None, None], base_translation + slide


def _to_child(rotation: np.ndarray, position: np.ndarray, motion: np.ndarray) -> np.ndarray:
    """A motion vector (K, 6) of the parent in the child's coordinates: (R^T w, R^T (v - p x w))."""
    w, v = motion[:, :3], motion[:, 3:]
    return np.concatenate([np.einsum("kji,kj->ki", rotation, w),
                           np.einsum("kji,kj->ki", rotation, v - _cross(position, w))], axis=1)


def _to_parent(rotation: np.ndarray, position: np.ndarray, force: np.ndarray) -> np.ndarray:
    """A force (K, 6) of the child in the parent's coordinates: (R n + p x R f, R f)."""
    turned_force = np.einsum("kij,kj->ki", rotation, force[:, 3:])
    return np.concatenate([np.einsum("kij,kj->ki", rotation, force[:, :3]) + _cross(position, turned_force),
                           turned_force], axis=1)


def _motion_cross(v: np.ndarray, m: np.ndarray) -> np.ndarray:
    """v x m for motion vectors (K, 6): (w x mw, w x mv + v x mw)."""
    return np.concatenate([_cross(v[:, :3], m[:, :3]), _cross(v[:, :3], m[:, 3:]) + _cross(v[:, 3:], m[:, :3])], 1)


def _force_cross(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    """v x* f: (w x n + v x f, w x f)."""
    return np.concatenate([_cross(v[:, :3], f[:, :3]) + _cross(v[:, 3:], f[:, 3:]), _cross(v[:, :3], f[:, 3:])], 1)


def rnea(tree: Tree, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
    """τ = M q̈ + h + D q̇ at K states (real or complex), ComplexWarning an error: (K, n) of the chain's joints on a
    fixed base; on a floating base q (K, 7 + n) = (position, quat_wxyz, joints), q̇, q̈ and τ (K, 6 + n) in the
    project's convention (world axes, the base origin's velocity; :func:`floating_rnea`)."""
    if tree.base_inertia is not None:
        return floating_rnea(tree, np.asarray(_rotation(q[:, 3:7].real)), q[:, 7:], qdot, qddot)
    count = len(q)
    root_acceleration = np.zeros((count, 6), dtype=np.result_type(q, qdot, qddot, float))
    root_acceleration[:, 3:] = -tree.gravity
    tau, _ = _bodies(tree, q, qdot, qddot, np.zeros_like(root_acceleration), root_acceleration)
    return tau


def floating_rnea(tree: Tree, rotation: np.ndarray, joints: np.ndarray, qdot: np.ndarray,
                  qddot: np.ndarray) -> np.ndarray:
    """A floating base's τ (K, 6 + n) = (force, torque about the base origin, world axes; joint forces) at base
    orientations R (K, 3, 3) (complex: turned by a complex-safe exponential), joint values (K, n), q̇ and q̈ (K, 6 + n)
    = (linear, angular in world axes; joints). The root in base coordinates: V = (Rᵀ ω, Rᵀ v), A = d V/dt - (0, Rᵀ g)
    = (Rᵀ ω̇, Rᵀ (a - ω x v - g)); its wrench I A + V x* I V plus the bodies' is turned back by R."""
    assert tree.base_inertia is not None
    omega, velocity = qdot[:, 3:6], qdot[:, :3]
    linear = qddot[:, :3] - _cross(omega, velocity) - tree.gravity

    def back(x: np.ndarray) -> np.ndarray:
        return np.einsum("kji,kj->ki", rotation, x)

    root_velocity = np.concatenate([back(omega), back(velocity)], axis=1)
    root_acceleration = np.concatenate([back(qddot[:, 3:6]), back(linear)], axis=1)
    tau, on_root = _bodies(tree, joints, qdot[:, 6:], qddot[:, 6:], root_velocity, root_acceleration)
    momentum = np.einsum("ij,kj->ki", tree.base_inertia, root_velocity)
    wrench = (np.einsum("ij,kj->ki", tree.base_inertia, root_acceleration) + _force_cross(root_velocity, momentum)
              + on_root)
    turned = [np.einsum("kij,kj->ki", rotation, part) for part in (wrench[:, 3:], wrench[:, :3])]
    return np.concatenate([*turned, tau], axis=1)


def _rotation(quat_wxyz: np.ndarray) -> np.ndarray:
    """R (K, 3, 3) of real quaternions (K, 4), normalised first."""
    w, x, y, z = (quat_wxyz / np.sqrt(np.sum(quat_wxyz**2, axis=1, keepdims=True))).T
    return np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                     2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                     2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1).reshape(-1, 3, 3)


EXP_TERMS = 10
"""Terms of the series of sin(θ)/θ and (1 - cos θ)/θ² in :func:`exp_so3`: the remainder is below θ^20 / 20!, rounding
for any |θ| <= 1 (a complex step's θ is 1e-30)."""


def exp_so3(delta: np.ndarray) -> np.ndarray:
    """exp([δ]x) (K, 3, 3) of rotation vectors δ (K, 3), complex-safe (Rodrigues' formula with sin θ / θ and
    (1 - cos θ) / θ² as power series in θ² = δ·δ: no norm, no square root, no division by θ, no comparison; exact
    to rounding for |θ| <= 1, so for any complex step)."""
    theta2 = np.sum(delta * delta, axis=1)
    sine, versine, term = np.zeros_like(theta2), np.zeros_like(theta2), np.ones_like(theta2)
    for k in range(EXP_TERMS):  # term = (-θ²)^k
        sine = sine + term / math.factorial(2 * k + 1)
        versine = versine + term / math.factorial(2 * k + 2)
        term = -term * theta2
    k_matrix = _skew(delta)
    return np.eye(3) + sine[:, None, None] * k_matrix + versine[:, None, None] * (k_matrix @ k_matrix)


def _bodies(tree: Tree, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray, root_velocity: np.ndarray,
            root_acceleration: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Featherstone's RNEA over the tree's bodies on a root moving at ``root_velocity`` with ``root_acceleration``
    (K, 6) (base coordinates, (angular, linear), gravity as its fictitious acceleration): (τ (K, n) of the chain's
    joints (q, q̇, q̈ (K, n)), the wrench the bodies put on the root (K, 6))."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", np.exceptions.ComplexWarning)
        n = len(tree.parents)
        body_q, body_qd, body_qdd = (x[:, tree.columns] for x in (q, qdot, qddot))
        dtype = np.result_type(q, qdot, qddot, root_velocity, root_acceleration, float)
        count = len(q)
        frames: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        velocities: list[tuple[np.ndarray, np.ndarray]] = []
        forces: list[np.ndarray] = []
        for i in range(n):
            rotation, position = _joint(tree, i, body_q[:, i])
            subspace = np.zeros(6)
            subspace[:3 if tree.revolute[i] else 6][-3:] = tree.axis[i]
            parent = tree.parents[i]
            parent_velocity = root_velocity if parent < 0 else velocities[parent][0]
            parent_acceleration = root_acceleration if parent < 0 else velocities[parent][1]
            moving = subspace[None, :] * body_qd[:, i, None]
            v = _to_child(rotation, position, parent_velocity) + moving
            a = (_to_child(rotation, position, parent_acceleration) + subspace[None, :] * body_qdd[:, i, None]
                 + _motion_cross(v, moving))
            inertia_v = np.einsum("ij,kj->ki", tree.inertia[i], v)
            forces.append(np.einsum("ij,kj->ki", tree.inertia[i], a) + _force_cross(v, inertia_v))
            frames.append((rotation, position, subspace))
            velocities.append((v, a))
        tau = np.zeros((count, n), dtype=dtype)
        on_root = np.zeros((count, 6), dtype=dtype)
        for i in reversed(range(n)):
            rotation, position, subspace = frames[i]
            tau[:, tree.columns[i]] = (forces[i] @ subspace + tree.armature[i] * body_qdd[:, i]
                                       + tree.damping[i] * body_qd[:, i])
            carried = _to_parent(rotation, position, forces[i])
            if tree.parents[i] >= 0:
                forces[tree.parents[i]] = forces[tree.parents[i]] + carried
            else:
                on_root = on_root + carried
        return tau, on_root


def derivatives(tree: Tree, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray,
                qddot: np.ndarray | None = None) -> DynamicsDerivatives:
    """The truth at B states (B, n): RNEA's derivatives at q̈ = the model's forward dynamics of ``tau`` (or at
    ``qddot`` when given: an engine's own q̈ of τ, so that its forward solve's rounding, ~ε κ(M), is not counted in
    its derivatives), and forward dynamics' (the module docstring), every partial (B, n, n), column j the derivative
    by joint j's variable."""
    if qddot is None:
        qddot = forward_dynamics(tree, q, qdot, tau)
    if tree.base_inertia is not None:
        return _floating_derivatives(tree, q, qdot, qddot)
    count, n = q.shape
    slopes = (rnea(tree, *complex_directions(q, qdot, qddot)).imag / STEP).reshape(count, 3, n, n).transpose(0, 1, 3, 2)  # [b, x, i, j]
    return _partials(slopes[:, 0], slopes[:, 1], slopes[:, 2])


def complex_directions(*parts: np.ndarray) -> list[np.ndarray]:
    """The P inputs (each (B, n)) repeated for P n complex directions per state, in order: entry j of part 0, ..., then
    entry j of part P - 1, each perturbed by i :data:`STEP` ((B P n, n) complex each)."""
    count, n = parts[0].shape
    directions = len(parts) * n
    stacked = [np.repeat(x, directions, axis=0).astype(complex) for x in parts]
    for part in range(len(parts)):
        offsets = np.zeros((directions, n))
        offsets[part * n:(part + 1) * n] = np.eye(n)
        stacked[part] = stacked[part] + 1j * STEP * np.tile(offsets, (count, 1))
    return stacked


def _partials(dtau_dq: np.ndarray, dtau_dqdot: np.ndarray, exact_mass: np.ndarray) -> DynamicsDerivatives:
    """Every partial from RNEA's (B, n, n): forward dynamics' by -M⁻¹ ∂τ/∂x, M⁻¹."""
    inverse = np.linalg.inv(exact_mass)
    return DynamicsDerivatives(dtau_dq=dtau_dq, dtau_dqdot=dtau_dqdot, dqddot_dq=-inverse @ dtau_dq,
                               dqddot_dqdot=-inverse @ dtau_dqdot, dqddot_dtau=inverse)


def _floating_derivatives(tree: Tree, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> DynamicsDerivatives:
    """A floating base's truth, every partial (B, 6 + n, 6 + n): q's tangent (δp, δθ, δq_joints) with the base moved
    and turned in world axes (R' = exp([δθ]x) R by :func:`exp_so3`), then q̇ and q̈ entry by entry, 3 (6 + n)
    complex directions per state. Position does not enter (gravity is uniform): its columns are 0."""
    count, nv = qdot.shape
    directions = 3 * nv
    rotation = np.repeat(_rotation(q[:, 3:7]), directions, axis=0).astype(complex)
    joints = np.repeat(q[:, 7:], directions, axis=0).astype(complex)
    rates, accelerations = (np.repeat(x, directions, axis=0).astype(complex) for x in (qdot, qddot))
    part = np.tile(np.repeat(np.arange(3), nv), count)  # 0: q's tangent, 1: q̇, 2: q̈, per stacked row
    entry = np.tile(np.arange(nv), 3 * count)
    turn = np.zeros((len(part), 3), dtype=complex)
    tangent = part == 0
    turned = tangent & (entry >= 3) & (entry < 6)
    turn[turned, entry[turned] - 3] = 1j * STEP
    rotation = exp_so3(turn) @ rotation
    moved = tangent & (entry >= 6)
    joints[moved, entry[moved] - 6] += 1j * STEP
    for which, values in ((1, rates), (2, accelerations)):
        rows = part == which
        values[rows, entry[rows]] += 1j * STEP
    slopes = (floating_rnea(tree, rotation, joints, rates, accelerations).imag / STEP)
    slopes = slopes.reshape(count, 3, nv, nv).transpose(0, 1, 3, 2)  # [b, part, i, j]
    return _partials(slopes[:, 0], slopes[:, 1], slopes[:, 2])


def forward_dynamics(tree: Tree, q: np.ndarray, qdot: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """q̈ = M⁻¹ (τ - h - D q̇) at B states (B, n) [rad/s² or m/s²], M and h from the real RNEA."""
    mass, bias = mass_and_bias(tree, q, qdot)
    return np.linalg.solve(mass, (tau - bias)[:, :, None])[:, :, 0]


def inverse_dynamics(tree: Tree, q: np.ndarray, qdot: np.ndarray, qddot: np.ndarray) -> np.ndarray:
    """τ (K, n) [N m or N] of the real RNEA at K states: the function whose differences a declared finite-difference
    scheme is held to."""
    return np.asarray(rnea(tree, q, qdot, qddot).real, dtype=float)


def mass_and_bias(tree: Tree, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(M (B, nv, nv), h + D q̇ (B, nv)) from the real RNEA: h at q̈ = 0, M's columns at q̈ = e_j without velocity."""
    mass, bias = complex_mass_and_bias(tree, q, qdot)
    return mass.real, bias.real


def complex_mass_and_bias(tree: Tree, q: np.ndarray, qdot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`mass_and_bias` at real or complex states (a fixed base's), complex-safe: M's columns are RNEA at
    q̈ = e_j without velocity less RNEA at rest, h + D q̇ RNEA at q̈ = 0."""
    count, n = qdot.shape
    bias = rnea(tree, q, qdot, np.zeros_like(qdot))
    gravity = rnea(tree, q, np.zeros_like(qdot), np.zeros_like(qdot))
    columns = rnea(tree, np.repeat(q, n, axis=0), np.zeros((count * n, n)), np.tile(np.eye(n), (count, 1)))
    return columns.reshape(count, n, n).transpose(0, 2, 1) - gravity[:, :, None], bias
