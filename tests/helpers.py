"""Scene builders and run helpers shared by the tests (seeded generators take an explicit rng)."""

from __future__ import annotations

import dataclasses
import io
import math
import os
import signal
import subprocess
import time

import numpy as np

import pybullet_data

from simparity.core.model.ik_result import LIMIT_TOLERANCE
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes.library import builtin_paths
from simparity.comparisons.scenes.profiles import apply_profile
from simparity.comparisons.execute.runner import run_group
from simparity.comparisons.scenes.loading.scene_file import load_scene
from simparity.core.ik.jacobian_solvers import IKOptions
from simparity.core.ik.reach import reach_upper_bound
from simparity.core.kinematics import forward_kinematics
from simparity.core.rotations import quat_wxyz_normalize, quat_wxyz_to_matrix, rpy_to_matrix, so3_exp
from simparity.core.model.scenes.bodies import Forces, RigidBody
from simparity.core.model.scenes.chain import Chain, Joint
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.model.scenes.ik import IKScene
from simparity.core.model.scenes.kinematics import KinematicsScene
from simparity.core.urdf import chain_from_urdf


def builtin(name: str):
    """A built-in scene, loaded through the same loader users go through."""
    return load_scene(builtin_paths()[name])


def random_chain(rng: np.random.Generator, n_joints: int, prismatic_every: int = 3) -> Chain:
    """A spatial chain with random axes, origins (up to 0.5 m) and rotations; every k-th joint prismatic."""
    joints = []
    for i in range(n_joints):
        prismatic = prismatic_every and i % prismatic_every == prismatic_every - 1
        joints.append(Joint(
            name=f"j{i}", type="prismatic" if prismatic else "revolute",
            axis=rng.normal(size=3), origin_xyz=rng.uniform(-0.5, 0.5, size=3),
            origin_rotation=rpy_to_matrix(rng.uniform(-np.pi, np.pi, size=3)),
            lower=-2.0 if prismatic else -np.pi, upper=2.0 if prismatic else np.pi,
        ))
    return Chain(f"random{n_joints}", tuple(joints), "tool", rng.uniform(-0.3, 0.3, size=3),
                 rpy_to_matrix(rng.uniform(-np.pi, np.pi, size=3)))


def tumbling_box(inertia_body=np.diag([0.1, 0.2, 0.3]), quat_wxyz=(0.9, 0.1, -0.3, 0.2),
                 gravity=(0.0, 0.0, -9.81), duration=2.5, dt=1 / 240) -> DynamicsScene:
    """The notes' tumbling, falling box: m = 2 kg, omega0 = (.1, 3, .1) rad/s in body axes."""
    q = quat_wxyz_normalize(np.array(quat_wxyz, dtype=float))
    body = RigidBody("box", 2.0, inertia_body, [0.0, 0.0, 1.0], q, [0.5, -0.2, 1.0],
                     quat_wxyz_to_matrix(q) @ np.array([0.1, 3.0, 0.1]))
    forces = Forces(None if gravity is None else np.array(gravity))
    return DynamicsScene("tumbling-box", "test scene", "core", (body,), forces, duration, (dt,))


def exact_projectile(scene: DynamicsScene, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closed-form position and velocity (T, B, 3) of the scene's bodies under its gravity."""
    g = scene.forces.gravity_world
    x0 = np.stack([b.position_world for b in scene.bodies])
    v0 = np.stack([b.velocity_world for b in scene.bodies])
    t = times[:, None, None]
    return x0 + v0 * t + 0.5 * g * t * t, v0 + g * t


def unlimited(chain: Chain) -> Chain:
    """The same chain with every joint unlimited (URDF continuous joints)."""
    return dataclasses.replace(chain, joints=tuple(
        dataclasses.replace(j, lower=-np.inf, upper=np.inf) for j in chain.joints))


IIWA = chain_from_urdf(os.path.join(pybullet_data.getDataPath(), "kuka_iiwa/model.urdf"))
"""The KUKA iiwa of pybullet_data, read by core's URDF loader (engines get the adapters' export)."""
REVOLUTE7 = random_chain(np.random.default_rng(5), 7, prismatic_every=0)
"""A spatial 7R chain (no prismatic joint: engine IK ignores limits, so a prismatic joint
would reach targets beyond the reach bound)."""
MIXED6 = random_chain(np.random.default_rng(31), 6)
"""Every third joint prismatic, to pin conventions on both joint types."""
CONTINUOUS7 = unlimited(REVOLUTE7)
"""The 7R chain with every joint unlimited: URDF continuous, nq = 2 in Pinocchio."""


def reachable_targets(chain: Chain, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """End-effector positions (n, 3) and rotations (n, 3, 3) of seeded configurations within the limits."""
    lower = np.where(np.isfinite(chain.lower), chain.lower, -np.pi)
    upper = np.where(np.isfinite(chain.upper), chain.upper, np.pi)
    frames = forward_kinematics(chain, np.random.default_rng(seed).uniform(lower, upper, (n, chain.n_joints)))
    return frames.position_world[:, -1], frames.rotation_world[:, -1]


def far_targets(chain: Chain, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Targets at three times the reach bound from the first joint, random orientations."""
    rng = np.random.default_rng(seed)
    center, radius = reach_upper_bound(chain)
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    return center + 3 * radius * direction, so3_exp(rng.normal(size=(n, 3)))


def build_ik(engine: str, chain: Chain, solver: str, options: IKOptions):
    """An engine's IK solver, built the way the runner builds it."""
    return make_engine(engine).build_ik(chain, solver, options)


HAND_WRENCH = dict(
    # One body, m = 2 kg, turned a quarter turn about z (body x -> world y), moving at
    # v = (3, 0, 4) m/s in a wind w = (1, 0, 0) m/s and spinning at omega = (0, 0, 2) rad/s,
    # under gravity (0, 0, -9.81), linear drag b = 0.5, quadratic drag c = 0.1, angular
    # drags k = 0.03 and k_q = 0.01, and the force f = (1, 0, 0) N at the body point
    # p = (0.5, 0, 0) m.
    mass=2.0, quat_wxyz=(np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)), velocity=(3.0, 0.0, 4.0),
    omega=(0.0, 0.0, 2.0), gravity=(0.0, 0.0, -9.81), wind=(1.0, 0.0, 0.0), linear_drag=0.5,
    quadratic_drag=0.1, angular_linear_drag=0.03, angular_quadratic_drag=0.01,
    force=(1.0, 0.0, 0.0), point_body=(0.5, 0.0, 0.0),
    # By hand: u = v - w = (2, 0, 4), |u| = sqrt(20) = 4.47213595499958.
    #   weight m g = (0, 0, -19.62); -b u = (-1, 0, -2); -c |u| u = (-0.894427190999916, 0, -1.788854381999832)
    #   total force = (1 - 1 - 0.894427190999916, 0, -19.62 - 2 - 1.788854381999832)
    expected_force=(-0.894427190999916, 0.0, -23.408854381999832),
    #   -k omega = (0, 0, -0.06); -k_q |omega| omega = (0, 0, -0.04); lever R p = (0, 0.5, 0),
    #   (0, 0.5, 0) x (1, 0, 0) = (0, 0, -0.5)
    expected_torque=(0.0, 0.0, -0.6),
)
"""A wrench computed by hand, for the tests of core's forces and of the references' own."""


def hand_wrench_forces() -> Forces:
    """The forces of :data:`HAND_WRENCH` as a scene declares them (one body, index 0)."""
    from simparity.core.model.scenes.bodies import AppliedForce

    h = HAND_WRENCH
    return Forces(np.array(h["gravity"]), np.array(h["wind"]), np.array([h["linear_drag"]]),
                  np.array([h["quadratic_drag"]]), np.array([h["angular_linear_drag"]]),
                  np.array([h["angular_quadratic_drag"]]), (AppliedForce(0, h["force"], h["point_body"]),))


def reached_rate(result) -> float:
    """Share of targets reached within both tolerances, inside the joint limits or not: how well an
    engine's solver (which ignores limits by design) converges. ``solve_rate`` counts only the
    solutions inside the limits; the others fail as ``outside_limits``, each truly outside."""
    outside = result.reason == "outside_limits"
    assert np.all(result.limit_violation[outside] > LIMIT_TOLERANCE)
    return float(np.mean(result.success | outside))


RUN_ENGINES = ("core", "analytic", "mujoco", "pybullet", "pinocchio")
MIXED_SCENES = ("lecture-projectile", "ball-bounce-k05", "dzhanibekov", "ur5-kinematics", "lecture-2link-ik")
"""A dynamics scene with an analytic truth, one with contact (stability limits too), one with a tight
reference and observed orders, a kinematics scene and an IK scene with hard targets."""

TIMING_PREFIX = "time_"
"""Metrics that are wall times: they differ between any two runs; every other value must not."""


SMOKE_STEPS = 100
"""Steps at the coarsest time step of a smoke scene: every code path of a case runs, in a fraction of a second."""

SMOKE_TARGETS = 10
"""IK targets (and kinematics configurations) of a smoke scene."""


def smoke(scene):
    """``scene`` in the quick profile, trimmed further for tests of execution (executors, journals, isolation)
    rather than of verdicts: a dynamics scene's two coarsest time steps over at most :data:`SMOKE_STEPS` of the
    coarsest, at most :data:`SMOKE_TARGETS` IK targets or configurations."""
    scene = apply_profile([scene], "quick")[0]
    if isinstance(scene, DynamicsScene):
        dts = sorted(scene.dts, reverse=True)[:2]
        return dataclasses.replace(scene, dts=tuple(sorted(dts)), duration=min(scene.duration, SMOKE_STEPS * dts[0]))
    if isinstance(scene, KinematicsScene):
        return dataclasses.replace(scene, n_configurations=min(scene.n_configurations, SMOKE_TARGETS))
    if isinstance(scene, IKScene):
        return dataclasses.replace(scene, n_targets=min(scene.n_targets, SMOKE_TARGETS))
    return scene


def smoke_scenes(names=MIXED_SCENES):
    """Built-in scenes trimmed to smoke tests of execution (:func:`smoke`)."""
    return [smoke(builtin(n)) for n in names]


LEAN_INTEGRATORS = ("semi_implicit_euler", "rk4", "backup", "act_after", "exact", "euler")
"""The integrators of a dynamics scene in the executor tests that compare how rows come back, not what they say:
every engine still runs a case or two at each time step (core its contact schemes on the ball), 8 cases a time
step instead of 14 (measured on the smoke scenes: core, MuJoCo, PyBullet, Pinocchio and the reference each keep ok
rows where they had them)."""


def built_engines(names=RUN_ENGINES):
    return [make_engine(n) for n in names]


def comparable(results) -> list[tuple]:
    """Every row's non-timing content, floats by their exact bits (repr), and every series point."""
    out = []
    for scene, rows, series in results:
        for r in rows:
            value = "timing" if r.metric.startswith(TIMING_PREFIX) else repr(r.value)
            out.append((r.scene, r.engine, r.integrator, repr(r.dt), r.metric, value, r.unit, r.reference, r.status,
                        r.detail))
        for s in series:
            out.append((s.scene, s.engine, s.integrator, repr(s.dt), s.quantity, s.x.tobytes(), s.value.tobytes()))
    return out


class InProcess:
    """An executor running every group in this process, counting the cases it ran; it can stop (as Ctrl-C
    would) after ``stop_after`` cases."""

    def __init__(self, stop_after: float = math.inf) -> None:
        self.ran, self.stop_after, self.jobs = 0, stop_after, []

    def run(self, jobs):
        self.jobs = list(jobs)
        for job in jobs:
            for index, outcome in run_group(job.group, make_engine, skip=frozenset(job.skip)):
                if self.ran >= self.stop_after:
                    raise KeyboardInterrupt
                self.ran += 1
                yield job.key, index, outcome

    def close(self) -> None:
        return None


THROWN_BALL = """
[scene]
name = "throw"
kind = "dynamics"
reference = "analytic"
[world]
gravity_world = [0.0, 0.0, -9.81]
[[body]]
name = "ball"
mass = 1.0
inertia_body_diagonal = [0.1, 0.1, 0.1]
position_world = [0.0, 0.0, 10.0]
velocity_world = [1.0, 0.0, 0.0]
[simulation]
duration = 1.0
dt = [0.01, 0.005]
integrators = ["rk4"]
"""
"""A ball thrown under gravity for 1 s at two time steps, RK4 only: a scene of milliseconds per case."""


THROWN_INTO_WIND = """
[scene]
name = "toss"
kind = "dynamics"
reference = "analytic"
[world]
gravity_world = [0.0, 0.0, -9.81]
air_velocity_world = [4.0, 1.0, 0.0]
[[body]]
name = "leaf"
mass = 1.0
inertia_body_diagonal = [0.01, 0.01, 0.01]
velocity_world = [1.0, 0.0, 5.0]
linear_drag = 0.5
[simulation]
duration = 1.0
dt = [0.04, 0.02, 0.01]
integrators = ["rk4"]
"""
"""A body thrown into wind with linear drag (closed form: the analytic reference), rk4 only: a few cases."""


LEFTOVER_SECONDS = 10.0
"""How long the processes an engine left running may take to be killed once its cases are back (the worker
kills them right after the case's process ends, which may be just after its last result arrived)."""


def no_leftovers_within(seconds: float = LEFTOVER_SECONDS) -> bool:
    """True once no process :class:`tests.hostile_engines.ForkingEngine` left running is alive, within ``seconds``."""
    from tests.hostile_engines import leftovers

    deadline = time.monotonic() + seconds
    while leftovers():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.1)
    return True


def with_key(data: dict, path: str, value) -> dict:
    """A deep copy of parsed scene ``data`` with the key at ``path`` ("chain.joint.0.mass": a table's key, a list's
    index) set to ``value`` (None: removed), missing tables made on the way."""
    import copy

    data = copy.deepcopy(data)
    *heads, last = path.split(".")
    node = data
    for head in heads:
        node = node[int(head)] if head.isdigit() else node.setdefault(head, {})
    if value is None:
        node.pop(last)
    else:
        node[last] = value
    return data


def killed_and_resumed(command: list[str], killed, total: int, wait_seconds: float,
                       resume_options: tuple[str, ...] = ()) -> int:
    """Start ``simparity run`` (``command``, writing the folder ``killed``), kill it with SIGKILL (its process group: a
    lost node, the OOM killer; no chance to clean up) once half of its ``total`` cases are kept, check that half to all
    but one were kept, and resume it (``simparity run --resume``, with ``resume_options``: ``--no-report``), which must
    say how many it kept and succeed. Returns how many were kept. The resume is ``main`` in this process: what it is
    given is the folder the killed process left, not a process of its own (a command's start: ~2 CPU-s)."""
    from simparity.comparisons.cli.main import main
    from simparity.comparisons.execute.journal import CASES_FOLDER, Journal

    run = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.monotonic() + wait_seconds
    while (not (killed / CASES_FOLDER).is_dir() or len(Journal(killed)) < total // 2) and time.monotonic() < deadline:
        time.sleep(0.05)
    os.killpg(run.pid, signal.SIGKILL)
    run.wait()
    finished = len(Journal(killed))
    assert total // 2 <= finished < total
    printed = io.StringIO()
    assert main(["run", "--resume", str(killed), *resume_options], printed) == 0, printed.getvalue()
    assert f"resuming {finished} finished cases" in printed.getvalue()
    return finished


def floating_states(chain, count: int, seed: int) -> tuple[np.ndarray, ...]:
    """(q (count, 7 + n), v, a, tau (count, 6 + n)) of a floating-base chain: the base's origin and the joints
    uniform in [-1, 1], its orientation uniform over the rotations (SciPy's), velocities, accelerations and forces
    uniform in [-1, 1]; seeded."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(seed)
    turn = Rotation.random(count, random_state=seed).as_quat(scalar_first=True)
    q = np.concatenate([rng.uniform(-1, 1, (count, 3)), turn, rng.uniform(-1, 1, (count, chain.n_joints))], axis=1)
    v, a, tau = (rng.uniform(-1, 1, (count, chain.nv)) for _ in range(3))
    return q, v, a, tau


def solo12_leg():
    """Solo-12 (example-robot-data) from base_link to FL_FOOT with a floating base, the other legs held."""
    from importlib import metadata

    from simparity.comparisons.scenes.loading.chain import EXAMPLE_ROBOT_DATA_ROBOTS
    from simparity.core.urdf import chain_from_urdf

    robots = metadata.distribution("example-robot-data").locate_file(EXAMPLE_ROBOT_DATA_ROBOTS)
    return chain_from_urdf(str(robots / "solo_description/robots/solo12.urdf"), "base_link", "FL_FOOT", dynamics=True,
                           floating_base=True)


PLANTED_ENGINE_FACTORY = '''

def _engine(base, model_class, engine_name):
    """An engine like ``base`` whose joint-dynamics models are ``model_class`` (a planted copy of an adapter's)."""
    class Planted(base):
        name = engine_name

        def build_joint_dynamics(self, chain, method, gravity_world):
            return model_class(chain, gravity_world)

    Planted.__name__ = model_class.__name__ + "Engine"
    return Planted
'''
"""Source for a planted plugin module: ``_engine(base, model_class, name)`` makes its engine classes."""

PLANTED_MOTION_FACTORY = '''

def _engine(base, motion_class, engine_name):
    """An engine like ``base`` whose joint-motion simulations are ``motion_class`` (a planted copy)."""
    class Planted(base):
        name = engine_name

        def build_joint_motion(self, scene, integrator, dt):
            return motion_class(scene, integrator, dt)

    Planted.__name__ = motion_class.__name__ + "Engine"
    return Planted
'''
"""Source for a planted plugin module of joint-motion bugs: ``_engine(base, motion_class, name)``."""


def run_planted(tmp_path, monkeypatch, capsys, module: str, source: str, scene: str, plugin: str,
                engines: str = "core,mujoco,pybullet,pinocchio") -> tuple[int, list[str], str]:
    """``simparity run <scene> --quick --check`` with the plugin ``module:plugin`` (its ``source`` written into
    tmp_path, importable by the workers) beside ``engines``: (exit code, the violation lines, the output)."""
    import sys

    from simparity.comparisons.cli.main import main

    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("PYTHONPATH", f"{tmp_path}:{':'.join(sys.path)}")  # the probes and workers import it
    (tmp_path / f"{module}.py").write_text(source, encoding="utf-8")
    code = main(["run", scene, "--quick", "--check", "--engines", f"{engines},{module}:{plugin}", "--out",
                 str(tmp_path / "run"), "--history", str(tmp_path / "h.db"), "--no-report", "--jobs", "1"])
    out = capsys.readouterr().out
    return code, [line for line in out.splitlines() if line.startswith("violation: ")], out


def assert_caught(result: tuple[int, list[str], str], engine: str, metric: str) -> None:
    """A :func:`run_planted` result is red with violations naming ``engine`` only, ``metric`` among them."""
    code, violations, out = result
    assert code == 1, out[-2000:]
    assert {line.split()[2] for line in violations} == {engine}, violations
    assert any(metric in line for line in violations), violations


SPONG = {"m1": 1.3, "m2": 0.8, "l1": 0.9, "lc1": 0.4, "lc2": 0.35, "i1": 0.07, "i2": 0.03, "d1": 0.2, "d2": 0.1}
"""The planar elbow arm of :func:`spong_chain`: masses [kg], lengths [m], inertias [kg m^2], damping [N m s/rad]."""
SPONG_GRAVITY = 9.81
"""[m/s^2] along -y."""


def spong_chain():
    """Spong's planar elbow arm about z (gravity along -y in the tests): centres of mass on their links' x axes."""
    from simparity.core.model.scenes.chain import Chain, Joint, LinkInertia

    def link(mass, lc, inertia):
        return LinkInertia(mass, np.array([lc, 0.0, 0.0]), np.diag([inertia, inertia, inertia]))

    z = np.array([0.0, 0.0, 1.0])
    return Chain("spong", (
        Joint("q1", "revolute", z, np.zeros(3), np.eye(3), link=link(SPONG["m1"], SPONG["lc1"], SPONG["i1"]),
              damping=SPONG["d1"]),
        Joint("q2", "revolute", z, np.array([SPONG["l1"], 0.0, 0.0]), np.eye(3),
              link=link(SPONG["m2"], SPONG["lc2"], SPONG["i2"]), damping=SPONG["d2"])))


def spong_partials(q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(dtau/dq, dtau/dqdot) (B, 2, 2) of tau = M(q2) qdd + C(q, qd) qd + g(q) + D qd of :func:`spong_chain` under
    gravity -y (Spong, Hutchinson and Vidyasagar, the elbow manipulator), differentiated by hand."""
    m1, m2, l1, lc1, lc2 = (SPONG[k] for k in ("m1", "m2", "l1", "lc1", "lc2"))
    g0 = SPONG_GRAVITY
    b = m2 * l1 * lc2
    s2, c2 = np.sin(q[:, 1]), np.cos(q[:, 1])
    s1, s12 = np.sin(q[:, 0]), np.sin(q[:, 0] + q[:, 1])
    weight1, weight2 = (m1 * lc1 + m2 * l1) * g0, m2 * lc2 * g0
    by_q = np.stack([
        np.stack([-weight1 * s1 - weight2 * s12,
                  -2 * b * s2 * qdd[:, 0] - b * s2 * qdd[:, 1] - b * c2 * (2 * qd[:, 0] * qd[:, 1] + qd[:, 1] ** 2)
                  - weight2 * s12], -1),
        np.stack([-weight2 * s12, -b * s2 * qdd[:, 0] + b * c2 * qd[:, 0] ** 2 - weight2 * s12], -1)], 1)
    by_qd = np.stack([
        np.stack([-2 * b * s2 * qd[:, 1] + SPONG["d1"], -2 * b * s2 * (qd[:, 0] + qd[:, 1])], -1),
        np.stack([2 * b * s2 * qd[:, 0], np.full(len(q), SPONG["d2"])], -1)], 1)
    return by_q, by_qd
