"""Issue #42's closed forms of loads that change with time against an independent evaluation: the integrals of
each kind of time function against adaptive quadrature, the driven damped joint against a tight ODE solve (piecewise
between a hold's jumps), each to <= 1e-12."""

from __future__ import annotations

import warnings

import numpy as np
from scipy.integrate import IntegrationWarning, quad, solve_ivp

from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes.library import resolve
from simparity.comparisons.scenes.loading.scene_file import load_scene
from simparity.core.model.scenes.time_functions import HeldFunction, Sinusoid, SmoothFunction
from simparity.references.analytic.forced import driven_joint, integrals
from simparity.references.common.time_loads import at, jump_times

CLOSED_FORM_AGREEMENT = 1e-12
"""Issue #42's bar for a closed form against an independent evaluation, relative to the quantity's scale."""

SOLVE_TOLERANCE = 1e-13
"""rtol = atol of the ODE solves the driven joint is checked against (DOP853, restarted at each jump)."""

SMOOTH = SmoothFunction(np.array([[0.3], [-0.8], [0.25]]),
                        (Sinusoid(np.array([1.5]), 1.5, 0.4), Sinusoid(np.array([-0.4]), 0.3, -1.0)))
HELD = HeldFunction(np.array([[0.0], [0.7], [-0.2], [0.4]]), period_s=0.15, phase_s=0.05)
TIMES = np.linspace(0.0, 1.2, 13)


def _quadrature(function, times):
    """(F1, F2) of a one-component function by adaptive quadrature split at its jumps: F1(t) = int_0^t f and, by
    Cauchy's formula for a repeated integral, F2(t) = int_0^t (t - s) f(s) ds."""
    breaks = jump_times([function], 2.0)

    def integral(kernel, t):
        points = [b for b in breaks if b < t] or None
        with warnings.catch_warnings():  # QUADPACK's "roundoff detected" at 1e-14: the comparison below judges
            warnings.simplefilter("ignore", IntegrationWarning)
            return quad(kernel, 0.0, t, points=points, epsabs=1e-14, epsrel=1e-14, limit=200)[0] if t > 0 else 0.0

    f1 = np.array([integral(lambda s: float(at(function, s)[0]), t) for t in times])
    f2 = np.array([integral(lambda s, t=t: (t - s) * float(at(function, s)[0]), t) for t in times])
    return f1, f2


def test_the_integrals_of_each_kind_of_function_match_quadrature():
    for function in (SMOOTH, HELD):
        first, second = integrals(function, TIMES)
        f1, f2 = _quadrature(function, TIMES)
        scale = max(np.abs(f1).max(), np.abs(f2).max())
        np.testing.assert_allclose(first[:, 0], f1, rtol=0, atol=CLOSED_FORM_AGREEMENT * scale)
        np.testing.assert_allclose(second[:, 0], f2, rtol=0, atol=CLOSED_FORM_AGREEMENT * scale)


def _solved_joint(q0, qdot0, inertia, damping, force, function, times):
    """I q'' = f + tau(t) - b q' by DOP853, one solve per interval between the hold's jumps."""
    jumps = jump_times([function], times[-1])
    starts = np.concatenate([[0.0], jumps])
    y0, out = np.array([q0, qdot0]), np.empty((len(times), 2))
    for a, b in zip(starts, np.append(jumps, times[-1])):
        def rate(t, y, start=a):
            return [y[1], (force + at(function, t, start)[0] - damping * y[1]) / inertia]
        inside = (times >= a) & (times <= b)
        sol = solve_ivp(rate, (a, b), y0, method="DOP853", rtol=SOLVE_TOLERANCE, atol=SOLVE_TOLERANCE,
                        dense_output=True)
        out[inside] = sol.sol(times[inside]).T
        y0 = sol.y[:, -1]
    return out[:, 0], out[:, 1]


def test_a_driven_joint_matches_a_tight_solve_with_and_without_damping():
    smooth = SmoothFunction(np.array([[0.2]]), (Sinusoid(np.array([0.3]), 1.5, 0.5),))
    for function in (smooth, HELD):
        for damping in (0.0, 0.5):
            q, qdot = driven_joint(0.1, 6.0, 1 / 3, damping, 0.05, function, TIMES)
            q_ref, qdot_ref = _solved_joint(0.1, 6.0, 1 / 3, damping, 0.05, function, TIMES)
            scale = max(np.abs(q_ref).max(), np.abs(qdot_ref).max())
            np.testing.assert_allclose(q, q_ref, rtol=0, atol=CLOSED_FORM_AGREEMENT * scale)
            np.testing.assert_allclose(qdot, qdot_ref, rtol=0, atol=CLOSED_FORM_AGREEMENT * scale)


def test_a_timed_torque_that_is_zero_throughout_leaves_the_body_torque_free(tmp_path):
    """A held-out case: every sample 0 made the analytic engine look for the torque's axis among no vectors (an
    IndexError, a traceback from `simparity show`); such a load exerts nothing, and the closed form is torque-free."""
    text = resolve("torque-pulse").read_text(encoding="utf-8").replace("[0.0, 0.0, 0.5]", "[0.0, 0.0, 0.0]")
    path = tmp_path / "idle.toml"
    path.write_text(text.replace('name = "torque-pulse"', 'name = "idle"'), encoding="utf-8")
    scene = load_scene(path)
    analytic = make_engine("analytic")
    assert analytic.supports_dynamics(scene, "exact").ok
    run = analytic.build_dynamics(scene, "exact", 0.01).run(10)
    assert not run.angular_velocity_world.any()
