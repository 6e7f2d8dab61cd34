"""The IK runner: every engine's solvers, cross-evaluated; failures and hard cases reported as rows."""

import dataclasses
import math

import numpy as np
import pytest

from simparity.comparisons.engines.registry import DEFAULT_ENGINES, make_engine
from simparity.comparisons.execute.ik_runner import IK_METRICS, own_stop_rate, stopping_rule
from simparity.comparisons.execute.in_process import run_in_process as run_scene
from simparity.comparisons.execute.ik_targets import random_targets
from simparity.comparisons.scenes.profiles import quick
from simparity.core.inhouse import InHouseEngine
from simparity.core.ik.jacobian_solvers import IKOptions
from simparity.core.model.engine import Engine, StoppingRule
from simparity.core.model.ik_result import IKResult
from simparity.core.model.metric_catalogue import OWN_STOP_POSITION_TOLERANCE, SOLVE_RATE, SOLVE_RATE_OWN_STOP
from simparity.core.model.results import FAILED, NOT_AVAILABLE, OK, UNSOLVED
from tests.helpers import builtin

# Issue #4: core's best solver solves >= 99.5 % of 1000 seeded iiwa pose targets.
REQUIRED_IIWA_SOLVE_RATE = 0.995

CAPPED_ITERATIONS = 30
"""max_iterations of the scenes (see :func:`_capped`) whose assertions are about what the harness reports (every
metric, the judges, n/a and its reason, the hard targets), not about how far a solver gets in 200 iterations: the
solvers that stall (the transpose method, every solver on the hard targets) were most of these tests' cost. Measured
at 200 and at 30: the rates asserted below hold alike (2-link DLS 0.917 and J^-1 > 0 at both, 3-link J^-1 0.94 and
0.92 > 0.8, every judge 1.0 on the analytic solutions, 11 beyond-reach rows, core's rate beside a wrong FK 0.9 and
0.8 > 0)."""


def _capped(scene, **changes):
    """``scene`` with at most :data:`CAPPED_ITERATIONS` iterations per solve (and ``changes``)."""
    return dataclasses.replace(scene, max_iterations=CAPPED_ITERATIONS, **changes)


@pytest.fixture(scope="module")
def iiwa_rows():
    """All engines on the built-in iiwa scene, 40 random targets (the hard targets in full), iterations capped."""
    scene = _capped(builtin("iiwa-ik"), n_targets=40)
    return run_scene(scene, [make_engine(name) for name in DEFAULT_ENGINES], make_engine, repeats=1)


@pytest.mark.slow
def test_every_engine_and_solver_has_every_metric(iiwa_rows):
    """Each engine x solver has all IK metrics (ok, or n/a with a reason) and a row per hard target."""
    cases = {}
    for r in iiwa_rows:
        cases.setdefault((r.engine, r.integrator), []).append(r)
    for engine in DEFAULT_ENGINES:
        assert any(e == engine for e, _ in cases), engine
    for (engine, solver), rows in cases.items():
        metrics = {r.metric for r in rows}
        assert set(IK_METRICS) <= metrics, (engine, solver)
        assert {f"hard_{h}" for h in builtin("iiwa-ik").hard_targets} <= metrics
        assert all(r.status in (OK, NOT_AVAILABLE) for r in rows), [r.detail for r in rows if r.status == FAILED]
        assert all(r.detail for r in rows if r.status == NOT_AVAILABLE)


@pytest.mark.slow
def test_unreachable_targets_are_reported_failures_with_finite_residuals(iiwa_rows):
    """Beyond reach: every solver reports a failure (reason given) with a finite residual, never NaN."""
    far = [r for r in iiwa_rows if r.metric == "hard_beyond_reach" and r.status == OK]
    assert len(far) >= 8
    for r in far:
        assert math.isfinite(r.value) and r.value > 0.1
        assert r.detail.startswith("failed: unreachable"), (r.engine, r.integrator, r.detail)


@pytest.mark.slow
def test_cross_evaluation_agrees_across_engines(iiwa_rows):
    """Every engine's FK puts each solution's end effector within float32 precision of the others'."""
    spread = [r.value for r in iiwa_rows if r.metric == "cross_eval_disagreement_max" and r.status == OK]
    assert spread and max(spread) < 1e-6  # PyBullet's float32 link states dominate (~1e-7 m)


def test_core_solves_the_iiwa_criterion():
    """Core damped least squares: >= 99.5 % of the scene's 1000 pose targets, none outside the limits."""
    scene = builtin("iiwa-ik")
    targets = random_targets(scene, make_engine(scene.reference).build_kinematics(scene.chain))
    options = IKOptions(scene.position_tolerance, scene.orientation_tolerance, scene.max_iterations)
    result = make_engine("core").build_ik(scene.chain, "damped_least_squares", options).solve(
        targets.position_world, targets.rotation_world, scene.q_start)
    assert len(targets.position_world) == 1000
    assert result.solve_rate >= REQUIRED_IIWA_SOLVE_RATE
    assert not np.any(result.limit_violation > 0)
    assert np.all(np.isfinite(result.position_residual)) and np.all(np.isfinite(result.q))


@pytest.mark.slow
def test_analytic_two_link_beside_the_iterative_solvers():
    """On the lecture's 2-link arm the analytic solver solves every reachable target; others are measured. The
    Jacobian inverse works on the arm's plane (its 2 joints move the tip in 2 directions: a square system there)."""
    scene = _capped(builtin("lecture-2link-ik"), n_targets=60)
    rows = run_scene(scene, [make_engine("analytic"), make_engine("core")], make_engine, repeats=1)
    rate = {(r.engine, r.integrator): r.value for r in rows if r.metric == "solve_rate" and r.status == OK}
    assert rate[("analytic", "two_link")] == 1.0
    assert 0 < rate[("core", "damped_least_squares")] <= 1.0
    inverse = [r for r in rows if r.integrator == "jacobian_inverse" and r.metric == "solve_rate"]
    assert inverse[0].status == OK and inverse[0].value > 0


def test_a_failing_solver_still_reports_every_hard_target():
    """A solver that raises gets failed rows for every metric and every hard target, with the error."""
    from simparity.core.inhouse import InHouseEngine

    class _Broken(InHouseEngine):
        name = "broken"

        def build_ik(self, chain, solver, options):
            raise RuntimeError("no solver today")

    scene = dataclasses.replace(builtin("iiwa-ik"), n_targets=5)
    rows = run_scene(scene, [_Broken()], make_engine, repeats=1)
    dls = [r for r in rows if r.integrator == "damped_least_squares"]
    assert {r.metric for r in dls} >= set(IK_METRICS) | {f"hard_{h}" for h in scene.hard_targets}
    assert {r.status for r in dls} == {FAILED} and all("no solver today" in r.detail for r in dls)


@pytest.mark.slow
def test_float32_judge_does_not_fail_double_precision_solutions():
    """A solution within tolerance in double is granted by every judge, PyBullet's float32 FK included."""
    scene = _capped(builtin("lecture-2link-ik"), n_targets=40)  # the analytic solutions judged: no iteration
    rows = run_scene(scene, [make_engine("analytic"), make_engine("pybullet"), make_engine("core")], make_engine,
                        repeats=1)
    cross = {r.integrator: r.value for r in rows if r.metric == "cross_eval_solve_rate_min"}
    own = {r.integrator: r.value for r in rows if r.metric == "solve_rate"}
    assert cross["two_link"] == own["two_link"] == 1.0


def test_unavailable_engine_says_why_in_ik_scenes():
    """An engine whose library fails to import gets n/a IK rows naming the import error."""
    from simparity.comparisons.engines.registry import UnavailableEngine

    scene = dataclasses.replace(builtin("lecture-2link-ik"), n_targets=5)
    rows = run_scene(scene, [UnavailableEngine("mujoco", "No module named 'mujoco'")], make_engine, repeats=1)
    assert rows and all(r.status == NOT_AVAILABLE and "not importable" in r.detail for r in rows)


def test_an_engine_without_ik_solvers_says_so_in_ik_scenes():
    """A dynamics-only engine (here: the tight reference) gets n/a IK rows saying it offers no IK solver."""
    scene = dataclasses.replace(builtin("lecture-2link-ik"), n_targets=5)
    rows = run_scene(scene, [make_engine("tight")], make_engine, repeats=1)
    assert rows and all(r.status == NOT_AVAILABLE and r.detail == "tight offers no IK solver" for r in rows)


def test_singular_start_pose_is_reported():
    """The planar 2-link arm stretched straight (q = 0) loses a direction of motion there: the start pose is
    reported singular (rank deficiency 1); bent (q2 = 1 rad) it is regular."""
    from simparity.comparisons.execute.ik_runner import start_rank_deficiency

    scene = builtin("lecture-2link-ik")
    model = make_engine("pinocchio").build_kinematics(scene.chain)
    stretched = start_rank_deficiency(dataclasses.replace(scene, q_start=np.zeros(scene.chain.n_joints)), model)
    assert stretched.value == 1 and "start pose singular" in stretched.note
    bent = start_rank_deficiency(dataclasses.replace(scene, q_start=np.array([0.3, 1.0])), model)
    assert bent.value == 0 and "start pose regular" in bent.note


class _Boasting(InHouseEngine):
    """Core's solvers, but every target is claimed solved (a success criterion gone wrong)."""

    name = "boasting"

    def build_ik(self, chain, solver, options):
        model = super().build_ik(chain, solver, options)
        solve = model.solve

        def claims_all(*args):
            result = solve(*args)
            return dataclasses.replace(result, success=np.ones_like(result.success),
                                       reason=np.full_like(result.reason, ""))

        model.solve = claims_all
        return model


class _OffsetFK(InHouseEngine):
    """Core, with its forward kinematics 1 mm off along x (a frame at fault)."""

    name = "offset-fk"

    def build_kinematics(self, chain):
        model = super().build_kinematics(chain)
        fk = model.forward_kinematics

        def shifted(q):
            poses = fk(q)
            return dataclasses.replace(poses, position_world=poses.position_world + np.array([1e-3, 0.0, 0.0]))

        model.forward_kinematics = shifted
        return model


def _quick_rows(name, engines):
    return run_scene(_capped(quick(builtin(name))), engines, make_engine, repeats=1)


def _offering(engine: Engine, solver: str) -> Engine:
    """``engine`` offering ``solver`` alone. For the tests that assert on one solver's rows: a case's rows do not
    depend on the engine's other solvers (measured: ur5-ik's damped-least-squares rows, timing aside, the same bits
    either way), whose solves were most of these tests' cost."""
    engine.ik_solvers = lambda: (solver,)
    return engine


@pytest.mark.slow
def test_a_claim_no_fk_confirms_is_counted():
    """A solver that claims every target solved while the transpose method stalls: its unconfirmed claims are
    counted (the harness's residual check by every engine's FK refuses them); core's own claims are confirmed."""
    rows = _quick_rows("iiwa-ik", [_offering(make_engine("core"), "transpose"), _offering(_Boasting(), "transpose")])
    claims = {(r.engine, r.integrator): r.value for r in rows if r.metric == "unconfirmed_claims"}
    assert claims[("core", "transpose")] == 0.0 and claims[("boasting", "transpose")] > 0.5


@pytest.mark.slow
def test_a_wrong_fk_is_blamed_on_its_engine_alone():
    """An engine whose FK is 1 mm off: its own rows show the departure; core's solve rates are judged by the FKs
    that agree with the reference, so they do not drop."""
    dls = "damped_least_squares"
    rows = _quick_rows("ur5-ik", [_offering(make_engine("core"), dls), _offering(_OffsetFK(), dls)])
    value = {(r.engine, r.integrator, r.metric): r for r in rows}
    assert value[("offset-fk", "damped_least_squares", "fk_departure_max")].value == pytest.approx(1e-3)
    assert value[("core", "damped_least_squares", "fk_departure_max")].value == 0.0
    alone = {(r.integrator, r.metric): r.value for r in _quick_rows("ur5-ik", [_offering(make_engine("core"), dls)])}
    assert alone[("damped_least_squares", "cross_eval_solve_rate_min")] > 0  # judged by the offset FK, it would be 0
    assert value[("core", "damped_least_squares", "cross_eval_solve_rate_min")].value == alone[
        ("damped_least_squares", "cross_eval_solve_rate_min")]


@pytest.mark.slow
def test_the_jacobian_inverse_where_it_applies_and_n_a_where_it_does_not():
    """The lecture's 3-link planar arm moves in 3 of a pose's 6 directions (x, y, the turn about z): J^-1 solves
    its planar pose targets; with 3-D position targets its 3 x 3 Jacobian has a zero row: n/a with the reason,
    never a 0 % ok."""
    scene = _capped(quick(builtin("lecture-3link-ik")))
    rows = run_scene(scene, [_offering(make_engine("core"), "jacobian_inverse")], make_engine, repeats=1)
    inverse = {r.metric: r for r in rows if r.integrator == "jacobian_inverse"}
    assert inverse["cross_eval_solve_rate_min"].status == OK and inverse["cross_eval_solve_rate_min"].value > 0.8
    position = dataclasses.replace(scene, target_kind="position")
    rows = run_scene(position, [_offering(make_engine("core"), "jacobian_inverse")], make_engine, repeats=1)
    inverse = {r.metric: r for r in rows if r.integrator == "jacobian_inverse"}
    assert inverse["solve_rate"].status == NOT_AVAILABLE
    assert "moves in 2 of the target's 3" in inverse["solve_rate"].detail


def _hand_result(position, orientation, violation) -> IKResult:
    """An IKResult of three targets with the given residuals [m], [rad] and limit violations, judged as failures
    (the own-stop rate reads only the residuals and the violations)."""
    n = len(position)
    return IKResult(q=np.zeros((n, 2)), success=np.zeros(n, bool), iterations=np.zeros(n, int),
                    position_residual=position, orientation_residual=orientation, limit_violation=violation,
                    reason=np.full(n, "iteration_cap"))


def test_own_stop_rate_counts_the_solvers_own_thresholds():
    """Position 5e-5, 2e-4 and 5e-7 m, the first 0.1 rad off: a position-only 1e-4 m rule meets targets 1 and 3,
    adding 1e-4 rad leaves target 3, and a target outside its limits meets no rule."""
    result = _hand_result(np.array([5e-5, 2e-4, 5e-7]), np.array([0.1, 0.0, 0.0]), np.zeros(3))
    assert own_stop_rate(result, StoppingRule(1e-4)) == 2 / 3
    assert own_stop_rate(result, StoppingRule(1e-4, 1e-4)) == 1 / 3
    outside = _hand_result(result.position_residual, np.zeros(3), np.array([0.0, 0.0, 1e-3]))
    assert own_stop_rate(outside, StoppingRule(1e-4)) == 1 / 3


def test_a_solver_without_a_rule_stops_at_the_scenes_tolerances():
    """A solver that declares nothing is judged by its own rule as the harness judges it; a declared rule is kept."""
    scene = builtin("lecture-2link-ik")
    model = InHouseEngine().build_ik(scene.chain, "damped_least_squares", IKOptions())
    rule = stopping_rule(model, scene)
    assert (rule.position_tolerance, rule.orientation_tolerance) == (scene.position_tolerance,
                                                                    scene.orientation_tolerance)
    model.stopping_rule = StoppingRule(1e-3, description="a plugin's own threshold")
    assert stopping_rule(model, scene).position_tolerance == 1e-3


@pytest.mark.parametrize("position, orientation", [(0.0, 1.0), (math.nan, 1.0), (math.inf, 1.0), (1e-4, 0.0)])
def test_a_stopping_rule_needs_positive_thresholds(position, orientation):
    with pytest.raises(ValueError):
        StoppingRule(position, orientation)


def test_every_ik_case_reports_both_rates_and_its_rule():
    """The documented CLIK stops at |log6| < 1e-4: none solved at the scene's 1e-6, most at its own rule, and the
    rows say which rule; a solver that stops at the scene's tolerances reports the same rate twice."""
    scene = dataclasses.replace(builtin("lecture-2link-ik"), n_targets=20, hard_targets=())
    rows = run_scene(scene, [make_engine("pinocchio")], make_engine, repeats=1)
    by = {(r.integrator, r.metric): r for r in rows}
    documented_own = by[("clik-documented", SOLVE_RATE_OWN_STOP)]
    assert by[("clik-documented", SOLVE_RATE)].flag == UNSOLVED
    # Measured: 0.9 of 20, as clik at the scene's tolerance (the rest fail alike).
    assert documented_own.status == OK and documented_own.value >= 0.5
    assert "|log6 err| < 0.0001" in documented_own.detail
    assert by[("clik-documented", OWN_STOP_POSITION_TOLERANCE)].value == 1e-4
    assert by[("clik", SOLVE_RATE_OWN_STOP)].value == by[("clik", SOLVE_RATE)].value
    assert by[("clik", OWN_STOP_POSITION_TOLERANCE)].value == scene.position_tolerance
