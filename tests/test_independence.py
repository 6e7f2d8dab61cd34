"""A bug planted in core's forces shows up as a disagreement, never as agreement.

The references compute what they need themselves (engine APIs, references/external_forces,
the tight solve's own right-hand side), so corrupting core's wrench at run time changes
core's trajectories and nothing else's.
"""

import dataclasses

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.core.dynamics import forces as core_forces
from simparity.core.model.scene import Forces
from tests.helpers import builtin

REFERENCES = [("mujoco", "euler"), ("mujoco", "rk4"), ("pybullet", "euler"), ("pinocchio", "euler"),
              ("pinocchio", "rk4"), ("tight", "dop853")]
STEPS = 200
DISAGREEMENT = 1e-3  # [rad/s]: the planted sign error moved core's spin by 1.4 rad/s over 0.5 s; rounding is ~1e-15


def _flipped_torque(make_wrench):
    """core's make_wrench with the torque of the applied forces negated (a sign error in (R p) x f)."""

    def make(forces, props):
        right = make_wrench(forces, props)
        without_applied = make_wrench(dataclasses.replace(forces, applied=()), props)

        def wrench(t, x, rotation, v, omega):
            force, torque = right(t, x, rotation, v, omega)
            _, base = without_applied(t, x, rotation, v, omega)
            return force, base - (torque - base)

        return wrench

    return make


def _run(engine: str, integrator: str, scene):
    return make_engine(engine).build_dynamics(scene, integrator, scene.dts[0]).run(STEPS)


@pytest.fixture(scope="module")
def scene():
    """The built-in point-force scene plus drag, wind and angular drag, so every force path is covered."""
    base = builtin("point-force-torque")
    forces = dataclasses.replace(base.forces, air_velocity_world=np.array([1.0, -0.5, 0.0]),
                                 quadratic_drag=np.array([0.05]), angular_quadratic_drag=np.array([0.01]))
    assert isinstance(forces, Forces)
    return dataclasses.replace(base, forces=forces, dts=(0.0025,))


def test_a_torque_sign_error_in_core_moves_core_only(scene, monkeypatch):
    """With core's torque sign flipped, every reference's trajectory is bit-for-bit unchanged and core's is not."""
    before = {key: _run(*key, scene) for key in REFERENCES + [("core", "rk4")]}
    monkeypatch.setattr(core_forces, "make_wrench", _flipped_torque(core_forces.make_wrench))
    monkeypatch.setattr("simparity.core.inhouse.make_wrench", core_forces.make_wrench)
    for key in REFERENCES:
        after = _run(*key, scene)
        np.testing.assert_array_equal(after.angular_velocity_world, before[key].angular_velocity_world, err_msg=str(key))
    broken = _run("core", "rk4", scene)
    moved = np.abs(broken.angular_velocity_world - before[("core", "rk4")].angular_velocity_world).max()
    assert moved > DISAGREEMENT
