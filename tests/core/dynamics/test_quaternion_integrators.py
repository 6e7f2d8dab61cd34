"""The packed (component-major) quaternion integrators: layout, per-body time steps, inertia paths."""

import numpy as np
import pytest

from simparity.core.dynamics.forces import make_wrench
from simparity.core.dynamics.quaternion_integrators import (
    PackedBodies,
    engine_euler,
    make_packed_step,
    pack,
    rotation_rows,
    runge_kutta,
    semi_implicit_euler,
    unpack,
)
from simparity.core.dynamics.rigid_body import MassProperties, initial_state
from simparity.core.dynamics.tableau import TABLEAUX
from simparity.core.rotations import quat_wxyz_normalize, quat_wxyz_to_matrix
from simparity.core.model.scenes.bodies import Forces, RigidBody

ROUNDING = 1e-14
"""Agreement of two evaluation orders of the same float64 arithmetic on O(1) values."""


def _bodies(rng, n, inertia=None):
    out = []
    for k in range(n):
        q = quat_wxyz_normalize(rng.normal(size=4))
        out.append(RigidBody(f"b{k}", 1.0 + k, np.diag([0.1, 0.2, 0.3]) if inertia is None else inertia,
                             rng.normal(size=3), q, rng.normal(size=3), rng.normal(size=3)))
    return tuple(out)


def test_pack_and_unpack_round_trip_and_the_rotation_rows_are_the_matrices():
    rng = np.random.default_rng(0)
    bodies = _bodies(rng, 5)
    props = MassProperties.of(bodies)
    state = initial_state(bodies, props, quaternion=True)
    back = unpack(pack(state))
    for a, b in ((back.position_world, state.position_world), (back.orientation, state.orientation),
                 (back.momentum_world, state.momentum_world), (back.angular_momentum_world, state.angular_momentum_world)):
        np.testing.assert_array_equal(a, b)
    q = rng.normal(size=(7, 4))  # not normalised: both normalise first
    np.testing.assert_allclose(rotation_rows(q.T).transpose(2, 0, 1), quat_wxyz_to_matrix(q), atol=ROUNDING)


@pytest.mark.parametrize("scheme", list(TABLEAUX) + ["semi_implicit_euler", "engine_euler"])
def test_a_per_body_time_step_moves_each_body_as_its_own_scalar_step(scheme):
    """dt may be (B,), one per body (core's contact backup flies each body for its own time)."""
    rng = np.random.default_rng(1)
    bodies = _bodies(rng, 3)
    props = MassProperties.of(bodies)
    forces = Forces(np.array([0.0, 0.0, -9.81]), linear_drag=np.array([0.3, 0.1, 0.2]))
    step = make_packed_step(scheme, props, make_wrench(forces, props))
    start = pack(initial_state(bodies, props, quaternion=True))
    dts = np.array([1e-3, 0.0, 0.02])
    together = step(0.0, start, dts)
    for k, dt in enumerate(dts):
        alone = step(0.0, start, float(dt))
        np.testing.assert_allclose(together[:, k], alone[:, k], rtol=0, atol=ROUNDING)
    unmoved, original = together[:, 1].copy(), start[:, 1].copy()
    for column in (unmoved, original):  # engine_euler returns w >= 0: q and -q are one rotation
        column[3:7] *= np.sign(column[3])
    np.testing.assert_allclose(unmoved, original, rtol=0, atol=ROUNDING)


@pytest.mark.parametrize("scheme", list(TABLEAUX) + ["semi_implicit_euler", "engine_euler"])
@pytest.mark.parametrize("inertia", [None, np.array([[0.2, 0.03, 0.0], [0.03, 0.1, -0.02], [0.0, -0.02, 0.3]])])
def test_one_body_without_its_batch_axis_steps_bit_for_bit_as_a_batch_of_one(scheme, inertia):
    """make_packed_step drops a lone body's batch axis for speed: exactly the numbers of the batched step at B = 1
    (diagonal and full inertia, drag of both kinds, a force at a point), over many steps."""
    rng = np.random.default_rng(2)
    bodies = _bodies(rng, 1, inertia)
    props = MassProperties.of(bodies)
    forces = Forces(np.array([0.0, 0.0, -9.81]), np.array([0.5, 0.0, 0.1]), np.array([0.3]), np.array([0.2]),
                    np.array([0.05]), np.array([0.02]))
    wrench = make_wrench(forces, props)
    batched = {"semi_implicit_euler": semi_implicit_euler, "engine_euler": engine_euler}.get(
        scheme, lambda bodies, wrench: runge_kutta(scheme, bodies, wrench))(PackedBodies(props), wrench)
    one = make_packed_step(scheme, props, wrench)
    a = b = pack(initial_state(bodies, props, quaternion=True))
    for i in range(50):
        a, b = batched(i * 0.01, a, 0.01), one(i * 0.01, b, 0.01)
    np.testing.assert_array_equal(a, b)


def test_the_full_and_the_diagonal_inertia_paths_agree():
    """A batch with one non-diagonal tensor takes the full 3 x 3 path; a diagonal body steps the same in it."""
    rng = np.random.default_rng(2)
    r = quat_wxyz_to_matrix(quat_wxyz_normalize(rng.normal(size=4)))
    tilted = r @ np.diag([0.1, 0.2, 0.3]) @ r.T
    diagonal_only, mixed = _bodies(rng, 1), None
    mixed = diagonal_only + _bodies(rng, 1, inertia=tilted)
    results = []
    for bodies in (diagonal_only, mixed):
        props = MassProperties.of(bodies)
        packed = PackedBodies(props)
        results.append((packed.inertia_body_inv.ndim,
                        make_packed_step("rk4", props, make_wrench(Forces(), props))(
                            0.0, pack(initial_state(bodies, props, quaternion=True)), 0.01)[:, 0]))
    assert results[0][0] == 2 and results[1][0] == 3
    np.testing.assert_allclose(results[0][1], results[1][1], rtol=0, atol=ROUNDING)
