"""Issue #26: what a step costs, compared fairly across engines. Every built-in engine declares its force evaluations
per step (``Engine.stages``), and steps copies of a scene together where it can (``Simulation.batched``); the runner
turns both into rows (tests/comparisons/execute/test_runner.py)."""

from dataclasses import replace

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes.profiles import quick
from simparity.core.dynamics.forces import make_wrench
from simparity.core.dynamics.integrators import ORIENTATION_UPDATES, STAGES, make_step
from simparity.core.dynamics.rigid_body import MassProperties, initial_state
from simparity.core.model.errors import NotBatchedError
from tests.helpers import builtin

DECLARED = {
    "core": {"explicit_euler": 1, "semi_implicit_euler": 1, "engine_euler": 1, "midpoint": 2, "average_velocity": 2,
             "rk4": 4, "rk4+expmap": 4, "midpoint+matrix": 2, "taylor2": 1, "constant_velocity": 1, "backup": 4,
             "act_after": 4, "penalty_rk4": 4, "penalty_midpoint": 2, "penalty_semi_implicit_euler": 1},
    "mujoco": {"euler": 1, "implicit": 1, "implicitfast": 1, "rk4": 4},
    "pybullet": {"euler": 1},
    "pinocchio": {"euler": 1, "rk4": 4},
}
"""Force evaluations per step of each built-in engine's integrators (RK4 4, every Euler 1)."""

COPY_RTOL = 1e-12
"""Copies stepped together match the scene stepped alone to a few ulp: vectorised arithmetic may group a sum
differently at another batch size, and nothing else differs."""

STEPS = 40
"""Steps the batched runs take here (milliseconds): every force acts, and grazing-impact's box hits its plane three
times (at steps 7, 20 and 31 of its coarsest dt)."""


@pytest.mark.parametrize("engine", DECLARED)
def test_every_built_in_engine_declares_its_force_evaluations_per_step(engine):
    built = make_engine(engine)
    assert {name: built.stages(name) for name in DECLARED[engine]} == DECLARED[engine]
    assert all(isinstance(built.stages(name), int) for name in built.integrators())  # every integrator it offers
    assert built.stages("no-such-integrator") is None


def test_a_truth_declares_no_stage_count():
    """A closed form or an adaptive solve has no fixed count per step: unknown, the interface's default."""
    for name in ("analytic", "tight"):
        engine = make_engine(name)
        assert all(engine.stages(integrator) is None for integrator in engine.integrators())


@pytest.mark.parametrize("orientation", ORIENTATION_UPDATES)
@pytest.mark.parametrize("scheme", sorted(STAGES))
def test_core_s_stage_count_is_the_wrench_calls_of_one_step(scheme, orientation):
    """Counted, not assumed: one step of each scheme, with every orientation update, calls the wrench STAGES times."""
    scene = builtin("dzhanibekov")
    props = MassProperties.of(scene.bodies)
    wrench, calls = make_wrench(scene.forces, props), []

    def counted(*args):
        calls.append(args[0])
        return wrench(*args)

    packed = orientation == "quaternion" or scheme == "engine_euler"
    make_step(scheme, orientation, props, counted)(0.0, initial_state(scene.bodies, props, quaternion=packed), 0.01)
    assert len(calls) == STAGES[scheme]


def test_a_replicated_scene_is_its_copies_side_by_side():
    scene = builtin("point-force-torque")
    n, copies = len(scene.bodies), scene.replicated(3)
    assert copies.bodies == scene.bodies * 3
    assert [a.body for a in copies.forces.applied] == [a.body + c * n for c in range(3) for a in scene.forces.applied]
    contact = builtin("box-edge-drop")
    assert contact.replicated(2).contact.shapes == contact.contact.shapes * 2


@pytest.mark.parametrize("scene, integrator", [("point-force-torque", "rk4"), ("point-force-torque", "rk4+matrix"),
                                               ("lecture-projectile", "taylor2"), ("grazing-impact", "backup"),
                                               ("grazing-impact", "act_after"), ("grazing-impact", "penalty_rk4")])
def test_core_steps_copies_together_as_it_steps_the_scene(scene, integrator):
    """Each copy of a batch moves as the scene does alone, applied forces and impacts included."""
    scene = quick(builtin(scene))
    sim = make_engine("core").build_dynamics(scene, integrator, scene.dts[0])
    alone, together, n = sim.run(STEPS), sim.batched(3)(STEPS), len(scene.bodies)
    for c in range(3):
        np.testing.assert_allclose(together.position_world[:, c * n:(c + 1) * n], alone.position_world,
                                   rtol=COPY_RTOL, atol=COPY_RTOL)
        np.testing.assert_allclose(together.angular_velocity_world[:, c * n:(c + 1) * n],
                                   alone.angular_velocity_world, rtol=COPY_RTOL, atol=COPY_RTOL)


def test_mujoco_rolls_copies_out_with_the_case_s_model():
    scene = builtin("dzhanibekov")
    sim = make_engine("mujoco").build_dynamics(scene, "rk4", scene.dts[0])
    states = sim.batched(4)(STEPS)
    assert states.shape[:2] == (4, STEPS) and np.all(np.isfinite(states))
    np.testing.assert_array_equal(states, np.broadcast_to(states[:1], states.shape))  # one model, one start
    position = sim.run(STEPS).position_world[1:, 0]  # the case's own run: the same rollout of one copy
    assert any(np.array_equal(states[0, :, k:k + 3], position) for k in range(states.shape[2] - 2))


def _quadratic_drag():
    """falling-linear-drag with its drag made quadratic (same coefficients), which MuJoCo does not model."""
    scene = builtin("falling-linear-drag")
    return replace(scene, forces=replace(scene.forces, linear_drag=None, quadratic_drag=scene.forces.linear_drag))


@pytest.mark.parametrize("scene, forces", [(lambda: builtin("point-force-torque"), "applied forces (mj_applyFT)"),
                                           (_quadratic_drag, "quadratic drag (xfrc_applied)")])
def test_mujoco_refuses_a_batch_of_forces_it_sets_from_python(scene, forces):
    """A rollout cannot apply what the adapter computes each step from Python: n/a, never another model's time."""
    loaded = scene()
    sim = make_engine("mujoco").build_dynamics(loaded, "rk4", loaded.dts[0])
    with pytest.raises(NotBatchedError) as refused:
        sim.batched(4)
    assert str(refused.value).startswith(f"the adapter sets {forces} from Python at every step")


@pytest.mark.parametrize("engine, reason", [("pybullet", "pybullet steps one world per stepSimulation call"),
                                            ("pinocchio", "aba one body at a time from Python")])
def test_engines_without_a_batch_api_say_why(engine, reason):
    scene = builtin("dzhanibekov")
    with pytest.raises(NotBatchedError, match=reason):
        make_engine(engine).build_dynamics(scene, "euler", scene.dts[0]).batched(4)
