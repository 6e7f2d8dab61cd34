"""Featherstone's recursions index ``parents``: a chain's parents are i - 1, and a branched tree's CRBA, RNEA and
ABA agree with a dense computation written here (M = sum J_i^T I_i J_i over the bodies' Jacobians, h from the
Lagrangian by central differences of M and of the potential energy)."""

import dataclasses

import numpy as np
import pytest

from simparity.core.articulated.chain_arrays import ChainArrays, chain_arrays
from simparity.core.articulated.recursive import Recursive
from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia

ROUNDING = 1e-12
"""Two orders of float64 arithmetic on O(1) masses, lengths and velocities."""

DIFFERENCE_STEP = 1e-5
"""[rad or m] Central differences of M and V: truncation ~step^2 = 1e-10, rounding ~1e-16 / step = 1e-11."""

DIFFERENCED = 1e-7
"""h from differences of M and V against the recursions (both errors above, times the O(1-10) terms)."""

GRAVITY = np.array([0.0, -9.81, 1.5])


def _joints(rng: np.random.Generator, types: str) -> Chain:
    joints = []
    for n, kind in enumerate(types):
        axis = rng.normal(size=3)
        inertia = rng.normal(size=(3, 3))
        link = LinkInertia(float(rng.uniform(0.5, 2.0)), rng.normal(scale=0.3, size=3),
                           inertia @ inertia.T * 0.1 + 0.05 * np.eye(3))
        rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        rotation *= np.sign(np.linalg.det(rotation))
        joints.append(Joint(f"j{n}", "revolute" if kind == "r" else "prismatic", axis / np.linalg.norm(axis),
                            rng.normal(scale=0.4, size=3), rotation, link=link, damping=0.3 * n, armature=0.1 * n))
    return Chain("tree", tuple(joints), end_effector_xyz=np.zeros(3))


def _motion_transforms(arrays: ChainArrays, q: np.ndarray) -> list[np.ndarray]:
    """X_0i (6, 6): base motion vectors in body i's axes, composed along the parents (dense, one state)."""
    out: list[np.ndarray] = []
    for i, parent in enumerate(arrays.parents):
        c, s = np.cos(q[i]), np.sin(q[i])
        joint = np.eye(6)
        if arrays.revolute[i]:
            e = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])  # coordinates turned by -q about z
            joint[:3, :3] = joint[3:, 3:] = e
        else:
            joint[3:, :3] = -np.array([[0.0, -q[i], 0.0], [q[i], 0.0, 0.0], [0.0, 0.0, 0.0]])  # -(q e_z) x
        x = joint @ arrays.tree_transform[i]
        out.append(x if parent < 0 else x @ out[parent])
    return out


def _ancestors(parents: np.ndarray, i: int) -> list[int]:
    chain = [i]
    while parents[chain[-1]] >= 0:
        chain.append(int(parents[chain[-1]]))
    return chain


def _dense_mass_matrix(arrays: ChainArrays, q: np.ndarray) -> np.ndarray:
    transforms = _motion_transforms(arrays, q)
    mass = np.diag(arrays.armature).astype(float)
    for i, x_i in enumerate(transforms):
        jacobian = np.zeros((6, arrays.n))
        for j in _ancestors(arrays.parents, i):
            jacobian[:, j] = (x_i @ np.linalg.inv(transforms[j]))[:, arrays.subspace[j]]
        mass += jacobian.T @ arrays.inertia[i] @ jacobian
    return mass


def _potential(arrays: ChainArrays, q: np.ndarray) -> float:
    energy = 0.0
    for i, x in enumerate(_motion_transforms(arrays, q)):
        e = x[:3, :3]  # base axes -> body axes
        r_cross = -e.T @ x[3:, :3]
        origin = np.array([r_cross[2, 1], r_cross[0, 2], r_cross[1, 0]])
        energy -= arrays.mass[i] * GRAVITY @ (origin + e.T @ arrays.com_body[i])
    return energy


def _dense_bias(arrays: ChainArrays, q: np.ndarray, qdot: np.ndarray) -> np.ndarray:
    """h = Mdot qdot - 1/2 d/dq (qdot^T M qdot) + dV/dq, each derivative a central difference."""
    n = arrays.n
    h = np.zeros(n)
    for j in range(n):
        step = np.zeros(n)
        step[j] = DIFFERENCE_STEP
        dm = (_dense_mass_matrix(arrays, q + step) - _dense_mass_matrix(arrays, q - step)) / (2 * DIFFERENCE_STEP)
        h += dm @ qdot * qdot[j]
        h[j] += -0.5 * qdot @ dm @ qdot
        h[j] += (_potential(arrays, q + step) - _potential(arrays, q - step)) / (2 * DIFFERENCE_STEP)
    return h


def test_a_chain_hangs_each_body_from_the_one_before():
    arrays = chain_arrays(_joints(np.random.default_rng(1), "rrpr"))
    assert arrays.parents.tolist() == [-1, 0, 1, 2]


@pytest.mark.parametrize("types, parents", [("rrpr", (-1, 0, 1, 2)),  # the chain itself
                                            ("rrpr", (-1, 0, 0, 2)),  # two branches off the first body
                                            ("rprrr", (-1, -1, 1, 0, 1))])  # two roots, branching again
def test_the_recursions_agree_with_the_dense_lagrangian_of_a_tree(types, parents):
    rng = np.random.default_rng(40)
    arrays = dataclasses.replace(chain_arrays(_joints(rng, types)), parents=np.array(parents))
    recursive = Recursive(arrays, GRAVITY)
    batch = 3
    q, qdot, qddot = (rng.normal(size=(arrays.n, batch)) for _ in range(3))
    masses = recursive.mass_matrix(q)
    tau = recursive.inverse_dynamics(q, qdot, qddot, damped=True)
    accelerations = recursive.forward_dynamics(q, qdot, tau)
    for b in range(batch):
        dense = _dense_mass_matrix(arrays, q[:, b])
        assert np.allclose(masses[:, :, b], dense, rtol=0.0, atol=ROUNDING * np.abs(dense).max())
        expected = dense @ qddot[:, b] + _dense_bias(arrays, q[:, b], qdot[:, b]) + arrays.damping * qdot[:, b]
        assert np.allclose(tau[:, b], expected, rtol=0.0, atol=DIFFERENCED * np.abs(expected).max())
    assert np.allclose(accelerations, qddot, rtol=0.0, atol=ROUNDING * 1e3)  # ABA inverts RNEA (cond(M) ~ 1e2)


def test_parents_numbered_after_their_children_are_refused():
    arrays = chain_arrays(_joints(np.random.default_rng(2), "rr"))
    with pytest.raises(ValueError, match="parents"):
        Recursive(dataclasses.replace(arrays, parents=np.array([1, -1])), GRAVITY)


WIDE_PATH_ULPS = 64
"""The wide batch's per-entry loops and the narrow batch's gathered operations sum the same products in other
orders (BLAS may fuse them): q-ddot agrees to a few ulp of its largest entry, times cond(M) ~ 1e2 at most."""


@pytest.mark.parametrize("types, parents", [("rrpr", (-1, 0, 1, 2)), ("rprrr", (-1, -1, 1, 0, 1))])
def test_aba_of_a_wide_batch_works_in_place_without_touching_its_inputs_or_constants(types, parents):
    """ABA above WIDE_BATCH reuses the children's arrays in place: the same state gives the same q-ddot twice (the
    model's inertias are not summed into), inputs stay as they were, and the narrow path agrees state by state."""
    from simparity.core.articulated.recursive import WIDE_BATCH

    rng = np.random.default_rng(41)
    arrays = dataclasses.replace(chain_arrays(_joints(rng, types)), parents=np.array(parents))
    recursive = Recursive(arrays, GRAVITY)
    q, qdot, tau = (rng.normal(size=(arrays.n, WIDE_BATCH)) for _ in range(3))
    given = [x.copy() for x in (q, qdot, tau)]
    first = recursive.forward_dynamics(q, qdot, tau)
    assert np.array_equal(recursive.forward_dynamics(q, qdot, tau), first)
    assert all(np.array_equal(x, y) for x, y in zip((q, qdot, tau), given))
    narrow = recursive.forward_dynamics(q[:, :8], qdot[:, :8], tau[:, :8])
    ulp = np.spacing(np.abs(narrow).max(axis=0))
    assert np.all(np.abs(first[:, :8] - narrow) <= WIDE_PATH_ULPS * ulp)
