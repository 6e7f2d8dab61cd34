"""The truth of a time step's Jacobian (issue #44, references/derivatives/step_truth.py): by complex step through each
scheme's formula it matches central differences of its own step to their truncation, and semi-implicit Euler's on
Spong's elbow arm by hand (M and the partials of τ written out); implicit_velocity is refused saying why. Against it:
core's Jacobians carried analytically through every scheme, to rounding over κ(M); MuJoCo's mjd_transitionFD to its
differences, declared centred, its RK4 n/a in MuJoCo's words."""

from __future__ import annotations

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes import library
from simparity.references.derivatives import step_truth
from simparity.references.derivatives.complex_step import mass_and_bias, tree_from_chain
from simparity.references.mujoco.joint_motion import SCHEMES as MUJOCO_SCHEMES
from tests.helpers import SPONG, SPONG_GRAVITY, spong_chain, spong_partials

FD_STEP, FD_AGREEMENT = 1e-6, 1e-7
"""Central differences of the step at 1e-6: truncation ~1e-12, rounding ~eps kappa / h ~1e-9 of the step's scale on
these arms; 1e-7 is far below a wrong stage or term."""
ROUNDING = 1e-13
"""Two evaluations of the same products of O(1) numbers (measured <= 2e-15 on the elbow arm)."""
ANALYTIC = 1e-14
"""The shipped bound on an analytic step Jacobian, relative and over kappa_1(M) (step_jacobian_error_max)."""
TRANSITION_FD = 1e-5
"""MuJoCo's centred differences at eps 1e-6: rounding eps_machine kappa / eps (measured <= 1e-6 on chain-20)."""
DT = 0.01
PANDA_EFFORT = 87.0
"""[N m] The largest <limit effort> of the Panda's URDF (its first four joints)."""


def _case(name: str):
    scene = library.load([name])[0]
    q, qd = np.asarray(scene.q0, dtype=float), np.asarray(scene.qdot0, dtype=float)
    tau = np.broadcast_to(np.asarray(scene.torque, dtype=float), q.shape) + 0.3
    return scene, tree_from_chain(scene.chain, scene.gravity_world), (q, qd, tau)


@pytest.fixture(scope="module", params=["driven-arm", "double-pendulum", pytest.param("chain-20", marks=pytest.mark.slow)])
def case(request):
    return _case(request.param)


def _relative(found, truth) -> float:
    return max(float(np.max(np.abs(getattr(found, b) - getattr(truth, b))) / np.max(np.abs(getattr(truth, b))))
               for b in ("by_state", "by_force"))


@pytest.mark.parametrize("scheme", step_truth.SCHEMES)
def test_it_matches_central_differences_of_its_own_step(scheme):
    scene, tree, (q, qd, tau) = _case("driven-arm")
    n = q.shape[1]
    truth = step_truth.step_jacobian(tree, scheme, DT, q, qd, tau)
    x = np.concatenate([q, qd, tau], axis=1)
    columns = []
    for e in np.eye(3 * n):
        moved = [x + FD_STEP * e, x - FD_STEP * e]
        up, down = (step_truth.step(tree, scheme, DT, y[:, :n], y[:, n:2 * n], y[:, 2 * n:]).real for y in moved)
        columns.append((up - down) / (2 * FD_STEP))
    fd = np.stack(columns, axis=-1)
    full = np.concatenate([truth.by_state, truth.by_force], axis=2)
    assert np.max(np.abs(fd - full)) <= FD_AGREEMENT * np.max(np.abs(full))


def test_semi_implicit_euler_on_the_elbow_arm_by_hand():
    """q̇' = q̇ + h q̈, q' = q + h q̇' with q̈_x = -M⁻¹ ∂τ/∂x (Spong's partials) and q̈_τ = M⁻¹, M written out."""
    tree = tree_from_chain(spong_chain(), np.array([0.0, -SPONG_GRAVITY, 0.0]))
    rng = np.random.default_rng(46)
    q, qd, tau = (rng.uniform(-2, 2, (4, 2)) for _ in range(3))
    m1, m2, l1, lc1, lc2, i1, i2 = (SPONG[k] for k in ("m1", "m2", "l1", "lc1", "lc2", "i1", "i2"))
    c2 = np.cos(q[:, 1])
    mass = np.empty((4, 2, 2))
    mass[:, 0, 0] = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + i1 + i2
    mass[:, 0, 1] = mass[:, 1, 0] = m2 * (lc2**2 + l1 * lc2 * c2) + i2
    mass[:, 1, 1] = m2 * lc2**2 + i2
    _, bias = mass_and_bias(tree, q, qd)
    qdd = np.linalg.solve(mass, (tau - bias)[:, :, None])[:, :, 0]
    by_q, by_qd = spong_partials(q, qd, qdd)
    inverse = np.linalg.inv(mass)
    rates = np.concatenate([-DT * inverse @ by_q, np.eye(2) - DT * inverse @ by_qd], axis=2)  # dq̇'/d(q, q̇)
    positions = np.concatenate([np.eye(2)[None].repeat(4, 0), np.zeros((4, 2, 2))], axis=2) + DT * rates
    truth = step_truth.step_jacobian(tree, "semi_implicit_euler", DT, q, qd, tau)
    expected_state = np.concatenate([positions, rates], axis=1)
    expected_force = np.concatenate([DT * DT * inverse, DT * inverse], axis=1)
    assert np.max(np.abs(truth.by_state - expected_state)) <= ROUNDING * np.max(np.abs(expected_state))
    assert np.max(np.abs(truth.by_force - expected_force)) <= ROUNDING * np.max(np.abs(expected_force))


def test_implicit_velocity_and_unknown_schemes_are_refused_saying_why():
    _, tree, (q, qd, tau) = _case("driven-arm")
    with pytest.raises(ValueError, match="implicit_velocity.*dh/dqdot"):
        step_truth.step(tree, "implicit_velocity", DT, q, qd, tau)
    with pytest.raises(ValueError, match="no truth for the scheme 'leapfrog' \\(allowed: explicit_euler"):
        step_truth.step(tree, "leapfrog", DT, q, qd, tau)


def test_core_s_step_jacobians_match_the_truth_for_every_scheme(case):
    scene, tree, (q, qd, tau) = case
    conditioning = float(np.max(np.linalg.cond(mass_and_bias(tree, q, qd)[0], 1)))
    core = make_engine("core")
    for scheme in core.joint_motion_integrators():
        found = core.build_joint_motion(scene, scheme, DT).step_jacobian(q, qd, tau)
        assert found.differences is None
        assert _relative(found, step_truth.step_jacobian(tree, scheme, DT, q, qd, tau)) <= ANALYTIC * conditioning, \
            scheme


def test_mujoco_s_transition_differences_match_the_truth(case):
    scene, tree, (q, qd, tau) = case
    mujoco = make_engine("mujoco")
    for integrator in mujoco.joint_motion_integrators():
        sim = mujoco.build_joint_motion(scene, integrator, DT)
        if MUJOCO_SCHEMES[integrator] == "rk4":
            with pytest.raises(NotImplementedError, match="RK4 integrator is not supported"):
                sim.step_jacobian(q, qd, tau)
            continue
        if MUJOCO_SCHEMES[integrator] not in step_truth.SCHEMES:
            continue  # implicit: no truth
        found = sim.step_jacobian(q, qd, tau)
        assert found.differences is not None and found.differences.centred
        truth = step_truth.step_jacobian(tree, MUJOCO_SCHEMES[integrator], DT, q, qd, tau)
        assert _relative(found, truth) <= TRANSITION_FD, integrator


def test_mujoco_s_motors_are_not_clamped_by_the_urdf_s_effort_limits():
    """MuJoCo's URDF importer turns <limit effort> into a joint's actuatorfrcrange, which clamps the motors added for
    mjd_transitionFD's control block: switched off (found by the articulated suite: the Panda's 87 N m clamped forces of
    170 N m, its step Jacobian 2e-3 off), and the Jacobian agrees with the truth at forces beyond the effort limits."""
    from simparity.comparisons.execute.step_jacobian_runner import jacobian_states
    from simparity.references.mujoco.joint_dynamics import ChainModel

    scene, tree, _ = _case("panda-falling")
    motors = ChainModel(scene.chain, scene.gravity_world, motors=True).model
    assert not np.any(motors.jnt_actfrclimited)
    assert motors.nu == scene.chain.n_joints and not np.any(motors.actuator_ctrllimited)
    assert not np.any(motors.actuator_forcelimited) and np.all(motors.actuator_gear[:, 0] == 1.0)
    q, qd, tau = jacobian_states(scene)
    assert np.max(np.abs(tau)) > PANDA_EFFORT
    found = make_engine("mujoco").build_joint_motion(scene, "euler_explicit_damping", DT).step_jacobian(q, qd, tau)
    assert _relative(found, step_truth.step_jacobian(tree, "semi_implicit_euler", DT, q, qd, tau)) <= TRANSITION_FD
