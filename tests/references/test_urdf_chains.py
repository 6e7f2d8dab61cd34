"""How the engines load a chain's URDF file: the same file from any base link, no geometry,
no inertia needed, nothing printed, names escaped."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.core.kinematics import forward_kinematics, jacobian_world
from simparity.core.rotations import geodesic_angle_matrix
from simparity.core.model.scenes.bodies import Forces, RigidBody
from simparity.core.model.scenes.dynamics import DynamicsScene
from simparity.core.urdf import chain_from_urdf
from simparity.references.mujoco.mjcf import dynamics_mjcf
from simparity.references.common.urdf_export import chain_urdf, movable_joints_above_base
from tests.helpers import builtin

ENGINES = ("mujoco", "pybullet", "pinocchio")
DOUBLE_TOL = 1e-12  # double-precision kinematics of ~1 m chains agree to ~1e-15
# PyBullet's link frames are FLOAT32 (~1e-7); a chain below the root link also gets its base
# pose from getLinkState, so its Jacobian is rotated by a float32 matrix.
FLOAT32_TOL = 2e-6  # [m], [rad], [m/rad]
TOLERANCE = {"mujoco": DOUBLE_TOL, "pinocchio": DOUBLE_TOL, "pybullet": FLOAT32_TOL}
SUBPROCESS_SECONDS = 120  # a generous bound for building three small models; a hang would never end

TWO_LINKS = """<?xml version="1.0"?>
<robot name="two">
  <link name="base">{geometry}</link>
  <link name="upper">{geometry}</link>
  <link name="tip"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <joint name="wrist" type="revolute">
    <parent link="upper"/><child link="tip"/><origin xyz="0.4 0 0.1" rpy="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
</robot>
"""


def _agree(engine, chain, q):
    model = make_engine(engine).build_kinematics(chain)
    poses, ref = model.forward_kinematics(q), forward_kinematics(chain, q)
    tol = TOLERANCE[engine]
    np.testing.assert_allclose(poses.position_world, ref.position_world, atol=tol)
    assert geodesic_angle_matrix(poses.rotation_world, ref.rotation_world).max() <= tol
    np.testing.assert_allclose(model.jacobian_world(q), jacobian_world(chain, q), atol=tol)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_chain_below_the_root_link_is_expressed_in_its_base_link(engine):
    """The iiwa from link 2 to link 6: engines load the whole file and give poses in link 2's frame."""
    chain = chain_from_urdf(builtin("iiwa-kinematics").chain.urdf_path, base_link="lbr_iiwa_link_2",
                            tip_link="lbr_iiwa_link_6")
    assert chain.base_link == "lbr_iiwa_link_2" and chain.urdf_path.endswith("model.urdf")
    assert movable_joints_above_base(chain) == ["lbr_iiwa_joint_1", "lbr_iiwa_joint_2"]
    q = np.random.default_rng(4).uniform(chain.lower, chain.upper, size=(40, chain.n_joints))
    _agree(engine, chain, q)


def test_pybullet_ik_is_not_available_when_joints_above_the_base_would_move():
    """PyBullet's IK moves every joint of the body: below the root it says n/a and why."""
    chain = chain_from_urdf(builtin("iiwa-kinematics").chain.urdf_path, base_link="lbr_iiwa_link_2")
    support = make_engine("pybullet").supports_ik(chain, "calculateInverseKinematics-tuned", False)
    assert not support.ok and "lbr_iiwa_joint_1, lbr_iiwa_joint_2" in support.reason


@pytest.mark.parametrize("engine", ENGINES)
def test_a_kinematics_only_file_without_inertial_loads(engine, tmp_path):
    """No <inertial> anywhere (MuJoCo refuses massless moving bodies unless masses are bounded)."""
    path = tmp_path / "two.urdf"
    path.write_text(TWO_LINKS.format(geometry=""))
    chain = chain_from_urdf(str(path))
    _agree(engine, chain, np.random.default_rng(1).uniform(-2, 2, size=(20, 2)))


@pytest.mark.slow
def test_engines_get_no_geometry_and_never_open_a_mesh(tmp_path):
    """Meshes by package://, a missing file, /proc and a FIFO: stripped, so loading neither fails nor hangs."""
    fifo = tmp_path / "mesh.stl"
    os.mkfifo(fifo)
    geometry = "".join(f'<{tag}><geometry><mesh filename="{name}"/></geometry></{tag}>'
                       for tag, name in (("visual", "package://nowhere/a.dae"), ("visual", "/proc/self/environ"),
                                         ("collision", str(fifo)), ("collision", "../../missing.stl")))
    path = tmp_path / "meshes.urdf"
    path.write_text(TWO_LINKS.format(geometry=geometry))
    chain = chain_from_urdf(str(path))
    assert "mesh" not in chain_urdf(chain) and "<visual" not in chain_urdf(chain)
    script = textwrap.dedent(f"""
        from simparity.comparisons.engines.registry import make_engine
        from simparity.core.urdf import chain_from_urdf
        chain = chain_from_urdf({str(path)!r})
        for engine in {ENGINES!r}:
            make_engine(engine).build_kinematics(chain).forward_kinematics([[0.1, 0.2]])
        print("loaded")
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=SUBPROCESS_SECONDS)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "loaded"  # and nothing else: no engine chatter


def test_loading_prints_nothing(capfd, tmp_path):
    """PyBullet warns on stdout about links without inertia; none of it reaches simparity's output."""
    path = tmp_path / "two.urdf"
    path.write_text(TWO_LINKS.format(geometry=""))
    chain = chain_from_urdf(str(path))
    for engine in ENGINES:
        make_engine(engine).build_kinematics(chain).forward_kinematics(np.zeros((1, 2)))
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_names_are_escaped_in_the_model_text():
    """A body name that tries to close its element and include a file stays a name."""
    name = 'box"/><include file="/etc/hostname"/><body name="x'
    body = RigidBody(name, 1.0, np.eye(3), np.zeros(3), (1.0, 0.0, 0.0, 0.0), np.zeros(3), np.zeros(3))
    scene = DynamicsScene("s", "-", "analytic", (body,), Forces(), 1.0, (0.5,))
    import mujoco

    model = mujoco.MjModel.from_xml_string(dynamics_mjcf(scene, "euler", 0.5))
    assert model.nbody == 2 and model.body(1).name == name


@pytest.mark.parametrize("engine, solver", [("mujoco", "dls"), ("pinocchio", "clik")])
def test_ik_below_the_root_link_moves_only_the_chain(engine, solver):
    """Targets in link 2's frame are reached by the chain's joints alone: the engine's own residual
    equals what core's FK measures at the returned joint values."""
    from simparity.core.model.ik_problem import IKTolerances

    chain = chain_from_urdf(builtin("iiwa-kinematics").chain.urdf_path, base_link="lbr_iiwa_link_2")
    rng = np.random.default_rng(12)
    frames = forward_kinematics(chain, rng.uniform(chain.lower, chain.upper, size=(20, chain.n_joints)))
    target_p, target_r = frames.position_world[:, -1], frames.rotation_world[:, -1]
    result = make_engine(engine).build_ik(chain, solver, IKTolerances(max_iterations=500)).solve(
        target_p, target_r, np.zeros(chain.n_joints))
    reached = forward_kinematics(chain, result.q).position_world[:, -1]
    np.testing.assert_allclose(np.linalg.norm(reached - target_p, axis=1), result.position_residual, atol=DOUBLE_TOL)
    assert result.solve_rate >= 0.5  # a frame or base error fails every target; measured 1.0 for both
