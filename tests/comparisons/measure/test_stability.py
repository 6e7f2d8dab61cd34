"""The penalty method's measured stability limit against the linear damped oscillator's (computed here)."""

import numpy as np
import pytest

from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.measure.stability import stable_dt_max
from simparity.core.model.scenes.bodies import Forces, RigidBody
from simparity.core.model.scenes.contact import Contact, Material, Plane, Shape
from simparity.core.model.scenes.dynamics import DynamicsScene

STIFFNESS, MASS = 1.0e4, 1.0  # omega = 100 rad/s
LINEAR_FACTOR = 2.0
"""The contact spring acts for half a period per impact, so the measured limit may differ from the linear
oscillator's spectral one, but by less than this factor (a wrong scheme is off by 4x and more)."""


def _scene(damping: float) -> DynamicsScene:
    body = RigidBody("particle", MASS, np.eye(3) * 1e-3, np.array([0.0, 0.0, 0.2]), np.array([1.0, 0, 0, 0]),
                     np.zeros(3), np.zeros(3))
    contact = Contact((Plane((0, 0, 1), 0.0),), (Shape("point"),), ((Material(0.5),),), methods=("penalty",),
                      rest_speed=0.01, penalty_stiffness=STIFFNESS, penalty_damping=damping)
    return DynamicsScene("drop", "-", "analytic", (body,), Forces(gravity_world=np.array([0.0, 0.0, -9.81])), 0.6,
                         (0.005, 0.01, 0.02), contact=contact)


def _linear_limit(zeta: float) -> float:
    """[s] Where the spectral radius of semi-implicit Euler on x'' = -omega^2 x - 2 zeta omega x' crosses 1:
    v += dt (-omega^2 x - 2 zeta omega v), then x += dt v."""
    omega = np.sqrt(STIFFNESS / MASS)
    dts = np.geomspace(1e-4, 1e-1, 4000)
    for dt in dts:
        step = np.array([[1 - (dt * omega) ** 2, dt * (1 - 2 * zeta * omega * dt)],
                         [-dt * omega**2, 1 - 2 * zeta * omega * dt]])
        if np.abs(np.linalg.eigvals(step)).max() > 1 + 1e-12:
            return float(dt)
    raise AssertionError("no limit in range")


@pytest.mark.slow
def test_semi_implicit_euler_limit_is_near_the_linear_one():
    zeta = 0.2155  # restitution 0.5 of the linear spring-damper
    damping = 2 * zeta * np.sqrt(STIFFNESS * MASS)
    measured = stable_dt_max(_scene(damping), make_engine("core"), "penalty_semi_implicit_euler")
    theory = _linear_limit(zeta)
    assert not measured.unmeasurable, measured.unmeasurable
    assert theory / LINEAR_FACTOR <= measured.value <= theory * LINEAR_FACTOR, (measured.value, theory)
    assert "stable at" in measured.note and "unstable at" in measured.note


def test_undamped_explicit_euler_has_no_stable_step():
    """Explicit Euler on an undamped spring grows at every step size: no limit, and the row says why."""
    measured = stable_dt_max(_scene(0.0), make_engine("core"), "penalty_explicit_euler")
    assert measured.unmeasurable.startswith("unstable at every step tried")
