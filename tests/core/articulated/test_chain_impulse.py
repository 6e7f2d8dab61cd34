"""Core's rigid contact of a chain (:mod:`core.articulated.chain_impulse`): the spheres' normal kinematics against
finite differences, Newton's impulse through the contact-space inverse inertia (checked with CRBA's M, not the ABA
the impulse uses), time backed up to the instant of contact, the resting force of a pendulum lying on the plane in
closed form, and two spheres touching at once refused."""

from __future__ import annotations

import tomllib
from dataclasses import replace

import numpy as np
import pytest

from simparity.comparisons.scenes.loading.scene_file import parse_scene
from simparity.core.articulated.chain_arrays import chain_arrays
from simparity.core.articulated.chain_contact import ChainContactForces
from simparity.core.articulated.chain_impulse import FREE, RigidContact
from simparity.core.articulated.motion import CoreJointMotion
from simparity.core.articulated.recursive import Recursive
from simparity.core.model.errors import ContactError, SimparityError
from simparity.core.model.scenes.chain_contact import ChainContact, ContactSphere
from simparity.core.model.scenes.contact import Plane
from simparity.comparisons.scenes.library import builtin_paths
from tests.helpers import builtin, random_chain, with_key

FD_STEP = 1e-6
"""[s along the joint rates] Central differences: truncation ~ step^2 |x'''| ~ 1e-12, rounding ~ eps / step ~ 1e-10."""
FD_TOLERANCE = 1e-8
"""[m/s or m/s^2] Agreement with the central differences (both errors above, for rates and lengths of order 1)."""
IMPULSE_RTOL = 1e-12
"""[1] Newton's law and the energy taken, relative: rounding of one ABA, one CRBA and a linear solve (~1e-15) on a
two-link arm, with margin."""
RESTITUTION = 0.5
REMOVED_RATE = 1e-16
"""[m/s] A plastic rebound's normal velocity after the impulse: rounding of Newton's law on ~1 mm/s."""
BACKED_UP = 1e-12
"""[m] The deepest a backed-up sphere ends a step: Brent's xtol 1e-13 of the step at ~1 m/s, where a step past the
impact would leave it ~v dt ~ 2 mm inside."""
RESTING_FORCE_RTOL = 1e-12
"""[1] The resting force against m g l_c / L: rounding of one ABA and one normal Jacobian."""
RETURN_FOUND = 1e-8
"""[m] A bounced sphere coming back within a step: nothing deeper than RK4's drift of a resting sphere (~1e-7 of the
3 cm radius), where a missed return sank it by centimetres."""
HELD_SHARE = 1e-3
"""[1 of the radius] Semi-implicit Euler's resting sphere put back on the plane each step: what is left is the
stages' drift within one step (4e-7 of the radius measured); without it it sank 1.5 radii in 2 s."""


def _arm(**contact) -> object:
    """arm-strike-press with a rigid contact (restitution 0.5 unless given) and ``contact``'s keys set."""
    with open(builtin_paths()["arm-strike-press"], "rb") as f:
        data = tomllib.load(f)
    for key in ("penalty_stiffness", "penalty_damping", "rest_after"):
        data = with_key(data, f"contact.{key}", None)
    data = with_key(data, "contact.restitution", RESTITUTION)
    for key, value in contact.items():
        data = with_key(data, key, value)
    return parse_scene(data, "arm-strike-press")


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_normal_rows_and_bias_are_the_derivatives_of_the_gaps(seed):
    rng = np.random.default_rng(seed)
    chain = random_chain(rng, 5)
    spheres = tuple(ContactSphere(f, rng.uniform(-0.1, 0.1, 3), 0.02) for f in ("j1", "j3", chain.end_effector_name))
    normal = rng.normal(size=3)
    contact = ChainContact(Plane(normal / np.linalg.norm(normal), 0.3), spheres, None, None, restitution=0.5)
    model = ChainContactForces(chain, contact)
    q, qdot = rng.uniform(-1, 1, (chain.nq, 2)), rng.uniform(-1, 1, (chain.nv, 2))
    rows, bias = model.normal_kinematics(q, qdot)
    np.testing.assert_array_equal(rows, model.normal_jacobians(q))

    def gaps(x):
        return contact.gaps(model.centres_world(x))

    def normal_velocity(x):
        return np.einsum("bsn,nb->bs", model.normal_jacobians(x), qdot)
    rate = (gaps(q + FD_STEP * qdot) - gaps(q - FD_STEP * qdot)) / (2 * FD_STEP)
    acceleration = (normal_velocity(q + FD_STEP * qdot) - normal_velocity(q - FD_STEP * qdot)) / (2 * FD_STEP)
    np.testing.assert_allclose(np.einsum("bsn,nb->bs", rows, qdot), rate, atol=FD_TOLERANCE)
    np.testing.assert_allclose(bias, acceleration, atol=FD_TOLERANCE)
    assert np.abs(bias).max() > 1e3 * FD_TOLERANCE  # the case must turn the rows


def _touching(q: np.ndarray, sphere: int):
    """The rigid arm with its plane moved so that sphere ``sphere`` just touches it at q (2,)."""
    scene = _arm()
    probe = RigidContact(scene, "rk4")
    gap = probe.gaps(q[:, None])[0, sphere]
    plane = scene.contact.plane
    moved = Plane(plane.normal_world, plane.offset - gap, plane.name)
    return replace(scene, contact=replace(scene.contact, plane=moved))


def test_an_impulse_reverses_the_normal_velocity_through_the_inverse_inertia():
    q, qdot = np.array([0.4, -0.7]), np.array([2.0, -1.5])
    scene = _touching(q, 1)
    contact = RigidContact(scene, "rk4")
    contact.start(1)
    normal_before = contact.normal_velocities(q[:, None], qdot[:, None])[0, 1]
    assert normal_before < -0.1  # the tip approaches
    after = contact._respond(q[:, None], qdot[:, None], np.array([False, True]), 1, 0)[:, 0]
    normal_after = contact.normal_velocities(q[:, None], after[:, None])[0, 1]
    assert normal_after == pytest.approx(-RESTITUTION * normal_before, rel=IMPULSE_RTOL)
    mass = Recursive(chain_arrays(scene.chain), np.zeros(3)).mass_matrix(q[:, None])[:, :, 0]  # CRBA, not ABA
    j = ChainContactForces(scene.chain, scene.contact).normal_jacobians(q[:, None])[0, 1]
    impulse = mass @ (after - qdot)
    np.testing.assert_allclose(impulse, (impulse @ j) / (j @ j) * j, rtol=IMPULSE_RTOL, atol=1e-15)  # along j
    lost = 0.5 * qdot @ mass @ qdot - 0.5 * after @ mass @ after
    effective_mass = 1.0 / (j @ np.linalg.solve(mass, j))
    assert lost == pytest.approx(0.5 * (1 - RESTITUTION**2) * effective_mass * normal_before**2, rel=IMPULSE_RTOL)


def test_a_slow_rebound_is_plastic_and_the_sphere_rests():
    q, qdot = np.array([0.4, -0.7]), np.array([2.0, -1.5])
    scene = _touching(q, 1)
    contact = RigidContact(scene, "rk4")
    contact.start(1)
    slow = 1e-3 * qdot  # a rebound of 0.5 of ~1 mm/s: below the default rest speed (1 mm/s)
    after = contact._respond(q[:, None], slow[:, None], np.array([False, True]), 1, 0)
    assert contact.normal_velocities(q[:, None], after)[0, 1] == pytest.approx(0.0, abs=REMOVED_RATE)
    assert contact.resting[0] == 1


def _bounce():
    return builtin("pendulum-bounce")


@pytest.mark.slow  # over 1.5 s of CPU on a 2-core CI-class machine (tests/conftest.py)
@pytest.mark.parametrize("scheme", ["rk4", "semi_implicit_euler"])
def test_time_is_backed_up_so_no_sphere_ends_a_step_inside(scheme):
    scene = _bounce()
    sim = CoreJointMotion(scene, scheme, 0.002)
    traj = sim.run(scene.n_steps(0.002))
    contact = RigidContact(scene, scheme)
    gaps = contact.gaps(np.ascontiguousarray(traj.q[:, 0].T))
    assert gaps.min() > -BACKED_UP
    assert np.count_nonzero(np.diff(np.sign(traj.qdot[:, 0, 0])) < 0) >= 5  # it bounced


@pytest.mark.slow  # over 1.5 s of CPU on a 2-core CI-class machine (tests/conftest.py)
def test_a_resting_pendulum_is_held_by_the_force_that_balances_gravity():
    scene = _bounce()
    sim = CoreJointMotion(scene, "rk4", 0.002)
    traj = sim.run(scene.n_steps(0.002))
    force = sim.contact_forces(traj.q[-1:, 0], traj.qdot[-1:, 0], traj.times[-1:])[0, 0]
    # Moments about the hinge of a link lying at angle theta: m g l_c cos(theta) = f L cos(theta) (a vertical force
    # at the tip, L = 0.5 m, the centre of mass at l_c = 0.25 m, m = 1 kg): f = m g l_c / L.
    np.testing.assert_allclose(force, [0.0, 0.0, 1.0 * 9.81 * 0.25 / 0.5], rtol=RESTING_FORCE_RTOL, atol=RESTING_FORCE_RTOL)
    first = sim.contact_forces(traj.q[:1, 0], traj.qdot[:1, 0], traj.times[:1])
    assert not first.any()  # released in the air: no force


def test_two_spheres_touching_at_once_are_refused():
    scene = _arm(**{"initial.q": [0.0, 0.0], "initial.qdot": [0.0, 0.0], "drive.torque": [0.0, 0.0],
                    "plane.0.coefficients": [0.0, 0.0, 1.0, 0.0300001]})
    sim = CoreJointMotion(scene, "rk4", 0.001)
    with pytest.raises(ContactError, match="resolve one contact at a time"):
        sim.run(200)


def test_a_floating_base_or_soft_contact_is_not_a_rigid_contact():
    with pytest.raises(ValueError, match="fixed-base scene with a rigid contact"):
        RigidContact(builtin("arm-strike-press"), "rk4")
    assert FREE == -1


def test_the_runner_says_n_a_where_two_spheres_touch_at_once():
    """Found only as it steps: core's rows are n/a with the reason, not a failure."""
    from simparity.comparisons.engines.registry import make_engine
    from simparity.comparisons.execute.in_process import run_in_process
    from simparity.core.model.results import NOT_AVAILABLE

    scene = _arm(**{"initial.q": [0.0, 0.0], "initial.qdot": [0.0, 0.0], "drive.torque": [0.0, 0.0],
                    "plane.0.coefficients": [0.0, 0.0, 1.0, 0.0300001], "simulation.duration": 0.2,
                    "simulation.dt": [0.002], "simulation.integrators": ["rk4"], "scene.reference": "core"})
    rows = [r for r in run_in_process(scene, [make_engine("core")], make_engine, repeats=1) if r.engine == "core"
            and r.metric == "joint_angle_error_max"]
    assert rows and all(r.status == NOT_AVAILABLE and "resolve one contact at a time" in r.detail for r in rows), rows


def _tip_only(restitution: float):
    """The rigid arm with its tip sphere only: its elbow folds on after the tip strikes, so a bounced tip comes back
    within a step and a resting one is pressed by a moving arm."""
    scene = _arm(**{"contact.restitution": restitution})
    return replace(scene, contact=replace(scene.contact, spheres=scene.contact.spheres[1:]))


def test_a_sphere_that_bounces_and_comes_back_within_a_step_is_caught():
    scene = replace(_tip_only(0.5), duration=0.4)  # the tip strikes at 0.04 s, bounces back within steps and rests
    dt = 0.002
    sim = CoreJointMotion(scene, "rk4", dt)
    traj = sim.run(scene.n_steps(dt))
    gaps = RigidContact(scene, "rk4").gaps(np.ascontiguousarray(traj.q[:, 0].T))
    assert gaps.min() > -RETURN_FOUND
    assert sim._rigid_run[1][-1, 0] == 0  # it ends resting on its one sphere


@pytest.mark.slow  # over 1.5 s of CPU on a 2-core CI-class machine (tests/conftest.py)
def test_a_resting_sphere_does_not_sink_under_semi_implicit_euler():
    scene = _tip_only(0.0)
    dt = 0.004
    traj = CoreJointMotion(scene, "semi_implicit_euler", dt).run(scene.n_steps(dt))
    gaps = RigidContact(scene, "semi_implicit_euler").gaps(np.ascontiguousarray(traj.q[:, 0].T))
    assert gaps.min() > -HELD_SHARE * scene.contact.spheres[0].radius


@pytest.mark.slow
def test_a_bounce_that_never_ends_fails_the_run():
    scene = _bounce()
    endless = replace(scene, contact=replace(scene.contact, rest_speed=1e-300))
    with pytest.raises(SimparityError, match="more than 100 contact events in one step"):
        CoreJointMotion(endless, "rk4", 0.002).run(scene.n_steps(0.002))


LIFT_RATE = 2.0
"""[N m/s] The lifting torque's growth: -LIFT_RATE t on the hinge of pendulum-bounce's arm resting on its plane."""
LIFT_TRUTH = dict(rtol=1e-13, atol=1e-13)
"""DOP853's tolerances for the truth after liftoff: far below RK4's error at the steps compared (1e-9 and less)."""
LIFTED_ORDER = 3.5
"""RK4 through a liftoff backed up to keeps its order 4 (measured 4.0); released at a step's end, its held force
switched off inside its stages, it fell to order 1-2."""


def _lifting():
    """pendulum-bounce's arm at rest on the plane (its tip sphere touching: 0.5 sin q = 0.35 - 0.02), a torque -2 t
    lifting it: it leaves the plane where that torque meets gravity's, m g l_c cos q."""
    with open(builtin_paths()["pendulum-bounce"], "rb") as f:
        data = tomllib.load(f)
    rest = float(np.arcsin(0.33 / 0.5))
    for key, value in (("initial.q", [rest]), ("simulation.duration", 1.5), ("contact.rest_after", None),
                       ("scene.reference", "core"),
                       ("drive.timed_torque", {"function": "smooth", "polynomial": [[0.0], [-LIFT_RATE]]})):
        data = with_key(data, key, value)
    return parse_scene(data, "pendulum-lift"), rest


@pytest.mark.slow  # two RK4 runs of 1.5 s with back-ups: 2.5-4.9 s of CPU on a 2-core CI-class machine
def test_a_resting_sphere_lifts_off_at_the_instant_its_force_falls_to_zero():
    from scipy.integrate import solve_ivp

    scene, rest = _lifting()
    m, l_c, inertia = 1.0, 0.25, 0.02 + 1.0 * 0.25**2  # the file's link about its hinge
    moment = m * 9.81 * l_c * np.cos(rest)
    lift = moment / LIFT_RATE  # the closed-form instant: -2 t + m g l_c cos q = 0 at rest

    def free(t, y):
        return [y[1], (m * 9.81 * l_c * np.cos(y[0]) - LIFT_RATE * t) / inertia]
    truth = solve_ivp(free, (lift, scene.duration), [rest, 0.0], method="DOP853", **LIFT_TRUTH).y[0, -1]
    errors = []
    for dt in (0.004, 0.002):
        traj = CoreJointMotion(scene, "rk4", dt).run(scene.n_steps(dt))
        before = traj.times < lift - dt
        assert np.all(np.abs(traj.q[before, 0, 0] - rest) < 1e-12)  # held on the plane until then
        errors.append(abs(traj.q[-1, 0, 0] - truth))
    assert truth < rest - 0.1  # it did lift
    assert np.log2(errors[0] / errors[1]) > LIFTED_ORDER, errors
