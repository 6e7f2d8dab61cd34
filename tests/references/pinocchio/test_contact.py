"""Pinocchio's contact on a plane (``references/pinocchio/contact.py``, issue #46): each step's impulses solve the
frictionless contact problem, checked by the spheres' own motion (central differences of Pinocchio's placements along
the new velocity, no Jacobian of the code's) and by virtual power; the polish and the answer check; Solo-12 standing
on the plane carries its weight; Pinocchio's own PGS miss on a frictionless cone (docs/examples)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from simparity.comparisons.api import load_scene
from simparity.core.model.errors import DivergedError
from simparity.references.pinocchio.adapter import PinocchioEngine
from simparity.references.pinocchio.contact import NCP_RESIDUAL, PlaneContact, _check_answer, ncp_residual, polished
from simparity.references.pinocchio.floating import PinocchioFloatingDynamics
from simparity.references.pinocchio.joint_dynamics import PinocchioJointDynamics

FD_STEP = 1e-6
"""Central differences of the centres along a velocity: truncation ~ step^2 |v|^2 / reach, rounding ~ eps / step."""
STOPPED = 1e-8
"""[m/s] A pushed sphere's normal velocity after the step, by those differences: 0 up to their error (~1e-10) and the
solver's (polished: rounding); a sign or frame mistake in the constraint leaves O(|v|) ~ 0.1-1 m/s."""
AGREEMENT = 1e-7
"""Relative agreement of the velocity change's virtual power M dv . w with the impulses' on the centres' motion along
w (differences as above)."""
WEIGHT = 1e-6
"""Relative: at rest the plane's total force is m g (measured 1.7e-9 on Solo-12; a missing sphere is off by ~1/4)."""
EXACT_RESIDUAL = 1e-15
"""The natural map's residual where Coulomb's law (or Signorini's) holds exactly, on hand-made impulses and velocities
that are short binary fractions: rounding only, while a violated law leaves O(0.01-1)."""
EXAMPLES = Path(__file__).resolve().parents[3] / "docs" / "examples"


def _moved(model: pin.Model, configuration: np.ndarray, v: np.ndarray, contact: PlaneContact) -> np.ndarray:
    """(S, 3) [m/s] the spheres' velocities along Pinocchio velocity v: central differences of their placements."""
    ahead = contact.centres(pin.integrate(model, configuration, FD_STEP * v))
    behind = contact.centres(pin.integrate(model, configuration, -FD_STEP * v))
    return (ahead - behind) / (2 * FD_STEP)


def _problems(seed: int):
    """(model, contact, configuration, v_free, the scene's contact) of random pressed states: Solo-12 sunk ~3 mm with a
    tilted base and a random front-left leg, and the pressed pendulum turned into its plane, each with a random
    downward v."""
    rng = np.random.default_rng(seed)
    out = []
    for name, floating in (("solo12-drop-stand", True), ("pendulum-press", False)):
        scene = load_scene(name)
        dynamics = (PinocchioFloatingDynamics(scene.chain, scene.gravity_world) if floating
                    else PinocchioJointDynamics(scene.chain, scene.gravity_world))
        contact = PlaneContact(dynamics.model, scene.chain, scene.contact)
        for _ in range(4):
            q = np.array(scene.q0[0], dtype=float)
            if floating:
                q[2] = 0.337 + rng.uniform(-0.001, 0.001)  # at rest: 0.3396
                tilt = rng.normal(scale=0.03, size=3)
                q[3:7] = np.r_[1.0, 0.5 * tilt] / np.linalg.norm(np.r_[1.0, 0.5 * tilt])
                q[7:] += rng.normal(scale=0.1, size=len(q) - 7)
                configuration = dynamics.configuration(q)
            else:
                q += rng.uniform(0.0, 0.02)  # further into the plane
                configuration = dynamics._configuration(q)
            v_free = rng.normal(scale=0.3, size=dynamics.model.nv)
            if floating:
                v_free[2] -= 0.5  # the base's local z, near the world's: down
            else:
                v_free[0] = abs(v_free[0]) + 0.1  # a growing angle presses the tip down
            out.append((dynamics.model, contact, configuration, v_free, scene.contact))
    return out


@pytest.mark.parametrize("seed", [46, 4601])
def test_the_step_stops_every_pushed_sphere_and_pulls_none(seed):
    for model, contact, configuration, v_free, plane_contact in _problems(seed):
        impulses, change = contact.solve(configuration, v_free)
        velocity = _moved(model, configuration, v_free + change, contact)
        normal = velocity[:, 2]  # the built-in planes' normal is +z
        pushed = impulses[:, 2] > 0
        assert pushed.any()
        assert np.all(impulses[:, 2] >= 0) and np.all(impulses[:, :2] == 0)  # frictionless: along the normal only
        assert np.all(np.abs(normal[pushed]) < STOPPED), normal
        plane = plane_contact.plane
        gaps = (contact.centres(configuration) @ plane.normal_world + plane.offset
                - np.array([sphere.radius for sphere in plane_contact.spheres]))
        assert np.all(normal[(gaps <= 0) & ~pushed] > -STOPPED)  # touching and not pushed: leaving


@pytest.mark.parametrize("seed", [46])
def test_the_velocity_change_is_the_impulses_virtual_power(seed):
    """M dv . w = sum_s lambda_s . (d centre_s / d w): the change is M^-1 J^T lambda for Pinocchio's J of the centres."""
    rng = np.random.default_rng(seed)
    for model, contact, configuration, v_free, _ in _problems(seed):
        impulses, change = contact.solve(configuration, v_free)
        data = model.createData()
        upper = np.triu(pin.crba(model, data, configuration))
        mass = upper + np.triu(upper, 1).T
        w = rng.normal(size=model.nv)
        power = float(np.sum(impulses * _moved(model, configuration, w, contact)))
        assert abs(change @ mass @ w - power) <= AGREEMENT * max(1.0, abs(power))


def test_a_claimed_convergence_that_is_wrong_is_caught():
    """An answer that leaves a pushed sphere sinking (Pinocchio's PGS on a frictionless cone) is O(1) off."""
    delassus = np.diag([1.0, 1.0, 2.0])
    free = np.array([0.0, 0.0, -0.5])
    assert ncp_residual(delassus, free, np.zeros(3)) >= 1.0 > NCP_RESIDUAL
    assert ncp_residual(delassus, free, np.array([0.0, 0.0, 0.25])) <= EXACT_RESIDUAL
    assert ncp_residual(delassus, free, np.array([0.0, 0.0, -0.1])) > NCP_RESIDUAL  # a pull
    with pytest.raises(DivergedError, match="do not solve the step"):
        _check_answer(delassus, free, np.zeros(3), 0.0)


def test_polish_solves_the_pushed_contacts_exactly():
    """ADMM's answer off by its tolerance on the contacts it pushes: the polish leaves rounding."""
    rng = np.random.default_rng(7)
    jacobian = rng.normal(size=(6, 8))
    root = rng.normal(size=(8, 8))
    delassus = jacobian @ np.linalg.solve(root @ root.T + np.eye(8), jacobian.T)
    exact = np.zeros(6)
    exact[[2, 5]] = [0.3, 0.2]
    free = -delassus @ exact  # both contacts pushed, both stopped
    rough = exact + np.r_[0, 0, 1e-9, 0, 0, -1e-9]
    assert ncp_residual(delassus, free, rough) > 1e-10
    assert ncp_residual(delassus, free, polished(delassus, free, rough)) < 1e-13


def test_solo12_stands_on_the_plane_and_it_carries_the_weight():
    scene = load_scene("solo12-drop-stand")
    sim = PinocchioEngine().build_joint_motion(scene, "semi_implicit_euler", 0.002)
    traj = sim.run(150)  # 0.3 s: landed at 0.07 s, at rest by 0.1 s
    forces = sim.contact_forces(traj.q[-1], traj.qdot[-1], traj.times[-1:])[0]
    weight = scene.chain.mass * 9.81
    assert abs(forces[:, 2].sum() - weight) < WEIGHT * weight
    gaps = sim.contact_centres(traj.q[-1])[0][:, 2] - 0.02
    assert np.all(gaps < 0) and np.all(gaps > -0.002)  # all four feet down, sunk no more than one step's approach


def test_pinocchio_s_pgs_miss_is_reproduced_standalone():
    """docs/examples/pinocchio_frictionless_solvers.py: PGS (friction 0) leaves a pushed corner sinking at O(0.1) m/s
    while claiming convergence; ADMM stops every corner. If Pinocchio fixes PGS this fails: update the docs."""
    out = subprocess.run([sys.executable, str(EXAMPLES / "pinocchio_frictionless_solvers.py")], capture_output=True,
                         text=True, check=True, timeout=60).stdout
    slowest = {line.split(":")[0]: float(line.split("slowest normal velocity after = ")[1].split()[0])
               for line in out.splitlines() if "slowest" in line}
    assert slowest["PGS, friction 0"] < -0.1
    assert slowest["ADMM, friction 0"] > -STOPPED
    assert abs(slowest["exact (active sets)"]) < STOPPED


@pytest.mark.parametrize("impulse, velocity, solves", [
    ([0.0, 0.0, 0.0], [0.3, -0.2, 0.1], True),  # off and leaving
    ([0.1, -0.05, 1.0], [0.0, 0.0, 0.0], True),  # sticking inside the cone
    ([-0.3, -0.4, 1.0], [0.6, 0.8, 0.0], True),  # sliding on the cone (mu 0.5) against its slip
    ([0.3, 0.4, 1.0], [0.6, 0.8, 0.0], False),  # on the cone along its slip: friction pushing
    ([-0.6, -0.8, 1.0], [0.6, 0.8, 0.0], False),  # outside the cone (twice mu)
    ([-0.4, -0.3, 1.0], [0.6, 0.8, 0.0], False),  # on the cone, 16 degrees off its slip
    ([0.0, 0.0, 1.0], [0.0, 0.0, -0.1], False),  # pushed and still sinking
])
def test_the_coulomb_residual_is_zero_exactly_where_coulomb_s_law_holds(impulse, velocity, solves):
    """The natural map of Coulomb's problem (De Saxce's form) at mu = 0.5, one contact, G = I: g = sigma - lambda."""
    from simparity.references.pinocchio.contact import ncp_residual

    lam, sigma = np.array(impulse), np.array(velocity)
    residual = ncp_residual(np.eye(3), sigma - lam, lam, 0.5)
    assert (residual <= EXACT_RESIDUAL) == solves, residual


@pytest.mark.slow
@pytest.mark.parametrize("friction", [0.001, 0.01, 0.1, 0.3])
def test_four_feet_landing_at_once_with_friction_are_solved(friction):
    """Solo-12's four feet of a rigid body touching at once make the Delassus operator singular (12 rows of rank 6):
    Pinocchio's ADMM alone stalled there (0.14 of |g| at mu 0.001, 3e-3 at 0.1); its solvers in turn solve every step
    within the check (a DivergedError otherwise)."""
    from dataclasses import replace

    scene = load_scene("solo12-drop-stand")
    scene = replace(scene, contact=replace(scene.contact, friction=friction), duration=0.15)
    sim = PinocchioEngine().build_joint_motion(scene, "semi_implicit_euler", 0.001)
    traj = sim.run(150)
    assert np.all(np.isfinite(np.asarray(traj.q)))
