"""The lecture's point-mass update rules ("Bodies in Free Fall")."""

from fractions import Fraction

import numpy as np
import pytest

from simparity.comparisons.scenes.library import builtin_paths
from simparity.comparisons.scenes.loading.scene_file import LENGTH_UNITS, load_scene
from simparity.core.dynamics import point_mass
from simparity.core.inhouse import InHouseEngine

# The lecture's worked example, in feet and seconds, exactly as printed on the slide.
LECTURE_POSITIONS_FT = {
    1: (Fraction(10, 3), Fraction(746, 225)),
    2: (Fraction(20, 3), Fraction(1484, 225)),
    3: (Fraction(10), Fraction(246, 25)),
}
LECTURE_VELOCITIES_FT = {1: (100, Fraction(1484, 15)), 2: (100, Fraction(1468, 15)), 3: (100, Fraction(484, 5))}

# Float64 run of the scene (converted to metres and back) against the exact fractions:
# a few roundings of values ~10 ft, so a few 1e-15 relative; 1e-13 ft leaves margin.
FLOAT_VS_EXACT_TOL_FT = 1e-13


def _fractions(values):
    return np.array([Fraction(v) for v in values], dtype=object)


def test_average_velocity_rule_reproduces_lecture_exactly():
    """In exact arithmetic the average-velocity rule gives the slide's fractions to the last digit."""
    x, v = _fractions([0, 0]), _fractions([100, 100])
    a, dt = _fractions([0, -32]), Fraction(1, 30)
    for frame in (1, 2, 3):
        x, v = point_mass.average_velocity_step(x, v, a, dt)
        assert tuple(x) == LECTURE_POSITIONS_FT[frame]
        assert tuple(v) == LECTURE_VELOCITIES_FT[frame]


def test_core_engine_on_lecture_scene_matches_the_fractions():
    """The in-house engine on the lecture-projectile scene (SI inside) lands on the slide's positions."""
    scene = load_scene(builtin_paths()["lecture-projectile"])
    dt = scene.dts[0]
    assert dt == pytest.approx(1 / 30, rel=1e-15)
    traj = InHouseEngine().build_dynamics(scene, "average_velocity", dt).run(3)
    feet = traj.position_world[:, 0, :2] / LENGTH_UNITS["ft"]
    for frame, expected in LECTURE_POSITIONS_FT.items():
        np.testing.assert_allclose(feet[frame], [float(e) for e in expected], rtol=0, atol=FLOAT_VS_EXACT_TOL_FT)


@pytest.mark.parametrize(
    "rule, position_error_sign",
    [
        (point_mass.explicit_euler_step, +1),  # uses v(t): lags the parabola's fall, above it
        (point_mass.constant_velocity_step, +1),
        (point_mass.average_velocity_step, 0),
        (point_mass.taylor_step, 0),
    ],
)
def test_rules_under_constant_gravity_have_their_known_error(rule, position_error_sign):
    """Under constant gravity the average and Taylor rules are exact; Euler is above by g t dt / 2."""
    g, dt, n = -9.81, 0.01, 100
    x, v, a = np.zeros(1), np.array([3.0]), np.array([g])
    for _ in range(n):
        x, v = rule(x, v, a, dt)
    t = n * dt
    exact = 3.0 * t + 0.5 * g * t * t
    error = x[0] - exact
    if position_error_sign == 0:
        assert abs(error) < 1e-12
    elif rule is point_mass.explicit_euler_step:
        assert error == pytest.approx(-g * t * dt / 2, rel=1e-9)
    else:
        assert error == pytest.approx(-0.5 * g * t * t, rel=1e-9)
