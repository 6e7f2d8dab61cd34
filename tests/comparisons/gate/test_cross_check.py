"""Cross-checks: a user's scheme held to the built-in schemes of its kind in the same run."""

import dataclasses
import math

import pandas as pd

from simparity.comparisons.gate.cross_check import CROSS_CHECK_FACTOR, SOLVE_RATE_FRACTION, cross_check
from simparity.core.model.results import COLUMNS, ResultRow

BUILTIN = ("core", "mujoco")


def _row(engine, value, metric="position_error_max", scheme="rk4", status="ok", flag="", dt=0.01, unit="m"):
    return ResultRow("s", engine, "my-rk4" if engine == "user" else "rk4", dt, metric, value, unit, "analytic:exact",
                     status, "", flag, scheme)


def _check(*rows):
    return cross_check(pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS)), BUILTIN)


def test_a_user_scheme_beyond_the_largest_builtin_of_its_kind_names_both():
    """Core's RK4 errs 1e-5, MuJoCo's 2e-6: the user's RK4 may err up to 2 x the larger; at 2.7 x core's it is a
    violation that names the user's engine and core."""
    builtin = (_row("core", 1e-5), _row("mujoco", 2e-6))
    assert _check(*builtin, _row("user", 1e-5)) == []
    assert _check(*builtin, _row("user", 0.99 * CROSS_CHECK_FACTOR * 1e-5)) == []
    (violation,) = _check(*builtin, _row("user", 2.7e-5))
    assert violation.engine == "user" and "core rk4" in violation.reason and "rk4" in violation.reason


def test_only_the_same_kind_at_the_same_step_and_never_rounding():
    """Another kind, another step, or a built-in error at the rounding floor: nothing to hold the user's row to."""
    assert _check(_row("core", 1e-5, scheme="midpoint"), _row("user", 1.0)) == []
    assert _check(_row("core", 1e-5, dt=0.02), _row("user", 1.0)) == []
    assert _check(_row("core", 1e-13, flag="rounding-floor"), _row("user", 1e-12)) == []
    assert _check(_row("core", 1e-5), _row("user", 1.0, scheme="")) == []  # a user's engine that does not say


def test_saturated_where_the_builtins_measured_is_a_violation():
    (violation,) = _check(_row("core", 1e-5), _row("user", math.nan, status="n/a", flag="saturated"))
    assert violation.found == "saturated" and "core rk4" in violation.reason


def test_a_solve_rate_below_the_fraction_of_the_best_builtin_of_its_kind():
    rate = dict(metric="cross_eval_solve_rate_min", scheme="damped_least_squares", dt=math.nan, unit="1")
    builtin = (_row("core", 0.96, **rate), _row("mujoco", 0.6, **rate))
    assert _check(*builtin, _row("user", 0.96 * SOLVE_RATE_FRACTION + 0.01, **rate)) == []
    (violation,) = _check(*builtin, _row("user", 0.24, **rate))
    assert violation.engine == "user" and "core" in violation.reason


def test_builtins_are_not_cross_checked_against_each_other():
    assert _check(_row("core", 1e-3), _row("mujoco", 1e-6)) == []


def test_a_nullspace_term_that_moves_away_from_the_rest_pose():
    """The user's null-space solver ends farther from the rest pose (2.9 rad) than its plain solver (2.8): the
    secondary objective is worse, not better; equal (no redundancy) passes."""
    rest = dict(metric="rest_distance_median", dt=math.nan, unit="rad or m")
    plain = _row("user", 2.8, scheme="damped_least_squares", **rest)
    worse = ResultRow("s", "user", "dls+ns", math.nan, "rest_distance_median", 2.9, "rad or m", "core:fk", "ok", "",
                      "", "damped_least_squares+nullspace")
    (violation,) = _check(plain, worse)
    assert violation.integrator == "dls+ns" and "null-space" in violation.reason
    assert _check(plain, dataclasses.replace(worse, value=2.8)) == []


def test_an_unsolved_user_solver_against_a_builtin_that_solves():
    rate = dict(metric="cross_eval_solve_rate_min", scheme="damped_least_squares", dt=math.nan, unit="1")
    (violation,) = _check(_row("core", 0.96, **rate), _row("user", math.nan, status="n/a", flag="unsolved", **rate))
    assert violation.found == "0 (unsolved)"


def test_a_user_scheme_declaring_less_work_than_every_builtin_of_its_kind():
    """Core's and MuJoCo's RK4 evaluate the forces 4 times a step (400/s at dt 0.01): a user's RK4 declaring one
    stage (100/s) would be ranked the cheapest of every budget, and is a violation naming the built-in it undercuts;
    the same count, or more work, is none."""
    builtin = (_row("core", 400.0, metric="evaluations_per_second", unit="1/s"),
               _row("mujoco", 400.0, metric="evaluations_per_second", unit="1/s"))
    assert _check(*builtin, _row("user", 400.0, metric="evaluations_per_second", unit="1/s")) == []
    assert _check(*builtin, _row("user", 800.0, metric="evaluations_per_second", unit="1/s")) == []
    (violation,) = _check(*builtin, _row("user", 100.0, metric="evaluations_per_second", unit="1/s"))
    assert violation.engine == "user" and violation.metric == "evaluations_per_second"
    assert "core rk4" in violation.reason and "stages()" in violation.reason


def test_a_one_engine_kind_is_held_by_its_family_where_its_engine_did_not_measure():
    """A user's engine_rk4 (MuJoCo's RK4 on a free joint) beside no measured built-in of its kind is held by the RK4
    built-ins at 2 x, whether MuJoCo did not run or its row is n/a (a review: the n/a row made the user's row skip
    every cross-check while counting as held); where MuJoCo's measured, by MuJoCo's."""
    from simparity.comparisons.gate.cross_check import held_series

    core = _row("core", 1e-9, metric="joint_angle_error_max", unit="1")
    user = _row("user", 5e-3, metric="joint_angle_error_max", scheme="engine_rk4", unit="1")
    mujoco_na = _row("mujoco", math.nan, metric="joint_angle_error_max", scheme="engine_rk4", status="n/a", unit="1")
    for rows in ((core, user), (core, mujoco_na, user)):
        (violation,) = _check(*rows)
        assert violation.engine == "user" and "built-in rk4" in violation.reason
        table = pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS))
        assert ("s", "user", "my-rk4") in held_series(table, BUILTIN)
    mujoco = _row("mujoco", 4.5e-3, metric="joint_angle_error_max", scheme="engine_rk4", unit="1")
    assert _check(core, mujoco, user) == []  # within 1.25 x MuJoCo's: its own kind decides
