"""The striking pendulum's closed form (:mod:`references.analytic.pendulum_contact`) against an independent solve: the
pendulum's equation written here from the scene's numbers, integrated by SciPy's DOP853 at a tight tolerance with its
own event location, the rate reversed and scaled by e at each event. No number of the closed form's is used."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from simparity.comparisons.scenes.library import builtin_paths
from simparity.comparisons.scenes.loading.scene_file import parse_scene
from simparity.core.model.engine import Support
from simparity.core.model.errors import SceneError
from simparity.references.analytic.engine import AnalyticEngine
from tests.helpers import with_key

MASS, LENGTH, COM, INERTIA_COM, G = 1.0, 0.5, 0.25, 0.02, 9.81
"""pendulum-bounce's arm: [kg], tip [m], centre of mass [m] along the link, inertia about y [kg m^2], [m/s^2]."""
PLANE_HEIGHT, RADIUS = -0.35, 0.02
"""Its plane z = -0.35 m and its tip sphere's radius [m]."""
SOLVE_RTOL = 1e-12
"""DOP853's relative tolerance (absolute 1e-14): the independent solve's own error, ~1e-11 over 1.5 s."""
AGREEMENT = 1e-8
"""[rad] The closed form's angle and the independent solve's agree to this at every sample (the solve's error compounded
through up to a dozen impacts, each moving the next by the event's error)."""


def _scene(restitution: float):
    with open(builtin_paths()["pendulum-bounce"], "rb") as f:
        data = with_key(tomllib.load(f), "contact.restitution", restitution)
    return parse_scene(data, "pendulum-bounce")


def _independent(restitution: float, rest_speed: float, times: np.ndarray) -> tuple[np.ndarray, list[float]]:
    """q at ``times`` and the impact instants: the arm's angle q about y lowers its tip (0.5 cos q, 0, -0.5 sin q),
    so I q'' = m g l_c cos q with I = I_c + m l_c^2, and the sphere touches where -0.5 sin q - 0.02 = -0.35."""
    inertia = INERTIA_COM + MASS * COM**2

    def rate(t, y):
        return [y[1], MASS * G * COM * np.cos(y[0]) / inertia]

    def touch(t, y):
        return -LENGTH * np.sin(y[0]) - RADIUS - PLANE_HEIGHT
    touch.terminal, touch.direction = True, -1
    q = np.full(len(times), np.nan)
    start, state, impacts = 0.0, [0.0, 0.0], []
    while start < times[-1]:
        solution = solve_ivp(rate, (start, times[-1]), state, method="DOP853", rtol=SOLVE_RTOL, atol=1e-14,
                             events=touch, dense_output=True)
        end = solution.t_events[0][0] if solution.t_events[0].size else times[-1]
        inside = (times >= start) & (times <= end)
        q[inside] = solution.sol(times[inside])[0]
        if not solution.t_events[0].size:
            break
        impacts.append(end)
        hit = solution.y_events[0][0]
        normal_speed = LENGTH * np.cos(hit[0]) * hit[1]  # the tip's downward speed
        if restitution * normal_speed < rest_speed:
            q[times > end] = hit[0]  # gravity presses the tip on the plane: it rests
            break
        start, state = end, [hit[0], -restitution * hit[1]]
    return q, impacts


@pytest.mark.parametrize("restitution", [0.5, 0.8, 0.0])
def test_the_closed_form_bounces_as_an_independent_solve(restitution):
    scene = _scene(restitution)
    dt = 0.001
    times = np.arange(scene.n_steps(dt) + 1) * dt
    traj = AnalyticEngine().build_joint_motion(scene, "closed_form", dt).run(len(times) - 1)
    expected, impacts = _independent(restitution, scene.contact.rest_speed, times)
    np.testing.assert_allclose(traj.q[:, 0, 0], expected, atol=AGREEMENT)
    assert len(impacts) >= (1 if restitution == 0 else 5)


def test_only_a_rigid_one_sphere_contact_on_a_pendulum_has_the_closed_form():
    engine = AnalyticEngine()
    assert engine.supports_joint_motion(_scene(0.5), "closed_form") == Support.yes()
    with open(builtin_paths()["arm-strike-press"], "rb") as f:
        soft = parse_scene(tomllib.load(f), "arm-strike-press")
    assert not engine.supports_joint_motion(soft, "closed_form").ok
    with open(builtin_paths()["pendulum-bounce"], "rb") as f:
        data = tomllib.load(f)
    data = with_key(data, "contact.sphere", data["contact"]["sphere"] * 2)
    with pytest.raises(SceneError, match="no closed form for 2 contact spheres"):
        parse_scene(data, "pendulum-bounce")  # the loader asks the reference
