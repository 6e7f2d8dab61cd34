"""Which integrator, engine by engine (issue #26): each engine's own cheapest scheme per error budget and most
accurate per cost budget, ranked by force evaluations per simulated second (ties: wall time), tallied over scenes,
and each scene's verdict in one line; on hand-made cases whose answers are known without the code under test."""

import math

import pandas as pd

from simparity.reports import engine_summary, summary


def _cases(rows) -> pd.DataFrame:
    """Cases as :func:`reports.summary.dynamics_cases` gives them: (engine, integrator, dt, error, wall cost,
    evaluations), all ok."""
    frame = pd.DataFrame(rows, columns=["engine", "integrator", "dt", "error", summary.WALL, summary.EVALUATIONS])
    return frame.assign(scene="s", status="ok", time_per_step=frame[summary.WALL] * frame["dt"],
                        batched_cost=math.nan)


# RK4 makes 4 evaluations a step, Euler 1: at dt 0.01, 400/s and 100/s.
CASES = _cases([
    ("core", "explicit_euler", 0.01, 1e-2, 0.01, 100.0),
    ("core", "rk4", 0.02, 1.6e-7, 0.02, 200.0),
    ("core", "rk4", 0.01, 1e-8, 0.04, 400.0),
    ("mujoco", "rk4", 0.01, 1e-8, 0.001, 400.0),
    ("mujoco", "euler", 0.01, 1e-2, 0.0003, 100.0),
    ("my_plugin", "verlet", 0.01, 1e-4, 0.5, 200.0),
    ("pinocchio", "rk4", 0.01, 1e-8, 0.08, 400.0),
])


def test_the_users_engines_come_first_and_ground_truths_never():
    order = engine_summary.engine_order(["analytic", "mujoco", "pinocchio", "my_plugin", "core", "tight", "pybullet"])
    assert order == ["core", "my_plugin", "mujoco", "pybullet", "pinocchio"]


def test_each_engine_picks_its_own_cheapest_by_evaluations_and_its_most_accurate_within_a_work_budget():
    picks = engine_summary.choices(CASES, summary.EVALUATIONS)
    assert list(picks) == ["core", "my_plugin", "mujoco", "pinocchio"]
    core = picks["core"]
    # Euler (100/s) misses 1e-3; RK4 at dt 0.02 (200/s) meets 1e-3 and 1e-6; only dt 0.01 (400/s) meets... none 1e-9
    assert (core["error ≤ 0.001"]["integrator"], core["error ≤ 0.001"]["dt"]) == ("rk4", 0.02)
    assert core["error ≤ 1e-06"]["dt"] == 0.02 and core["error ≤ 1e-09"] is None
    assert core["≤ 100 evaluations/s"]["integrator"] == "explicit_euler"
    assert core["≤ 1000 evaluations/s"]["dt"] == 0.01      # the most accurate within 1000/s: RK4 at the finer step
    assert picks["my_plugin"]["error ≤ 1e-06"] is None and picks["my_plugin"]["error ≤ 0.001"]["integrator"] == "verlet"


def test_overall_best_names_the_least_work_and_counts_schemes_doing_the_same_work():
    # Within 1e-6 the least work is core RK4 at dt 0.02 (200/s) alone; within 1e-7 three RK4s do 400/s, MuJoCo's
    # the quickest on the clock, so it is named and the two others counted.
    assert engine_summary.overall(CASES, 1e-6, summary.EVALUATIONS) == "core rk4 @ 0.02 (200/s, 20 ms)"
    assert engine_summary.overall(CASES, 1e-7, summary.EVALUATIONS) == "mujoco rk4 @ 0.01 (400/s, 1 ms; +2 as cheap)"
    assert engine_summary.overall(CASES, 1e-12, summary.EVALUATIONS) == "none"
    # By wall time MuJoCo's Euler is cheapest within 0.1.
    assert engine_summary.overall(CASES, 0.1, summary.WALL) == "mujoco euler @ 0.01 (0.3 ms)"


def test_ranking_falls_back_to_wall_time_when_nothing_counted_its_evaluations():
    assert summary.ranking_cost(CASES) == summary.EVALUATIONS
    assert summary.ranking_cost(CASES.assign(**{summary.EVALUATIONS: math.nan})) == summary.WALL
    assert summary.ranking_cost(CASES.drop(columns=[summary.EVALUATIONS])) == summary.WALL


def test_an_engine_without_stage_counts_is_not_ranked_overall_but_ranks_its_own_schemes_by_wall_time():
    """A plugin that declares no stages: left out of the overall ranking by work, but its own choice per error
    budget is still made (by its wall time: fair within one engine), and no work budget is said to bind it."""
    uncounted = CASES.assign(**{summary.EVALUATIONS: CASES[summary.EVALUATIONS].where(CASES["engine"] != "mujoco")})
    assert engine_summary.overall(uncounted, 1e-7, summary.EVALUATIONS) == "core rk4 @ 0.01 (400/s, 40 ms; +1 as cheap)"
    mujoco = engine_summary.choices(uncounted, summary.EVALUATIONS)["mujoco"]
    assert mujoco["error ≤ 0.001"]["integrator"] == "rk4"      # Euler's 1e-2 misses it; RK4 is within, by wall time
    assert engine_summary.pick(mujoco["error ≤ 0.001"], summary.WALL, show_error=False) == "rk4 @ 0.01 (1 ms)"
    assert mujoco["≤ 100 evaluations/s"] == engine_summary.NO_STAGE_COUNT
    tallied = engine_summary.tally([engine_summary.choices(uncounted, summary.EVALUATIONS)] * 2)["mujoco"]
    assert tallied["≤ 100 evaluations/s"] == engine_summary.NO_STAGE_COUNT and tallied["error ≤ 0.001"] == "rk4 ×2"


def test_tally_counts_each_engines_choice_over_scenes_most_frequent_first():
    other = _cases([("core", "midpoint", 0.01, 1e-4, 0.02, 200.0), ("mujoco", "rk4", 0.01, 1e-8, 0.001, 400.0)])
    per_scene = [engine_summary.choices(cases, summary.EVALUATIONS) for cases in (CASES, CASES, other)]
    tallies = engine_summary.tally(per_scene)
    assert tallies["core"]["error ≤ 0.001"] == "rk4 ×2, midpoint ×1"
    assert tallies["core"]["error ≤ 1e-09"] == "none ×3"
    assert tallies["my_plugin"]["error ≤ 0.001"] == "verlet ×2"   # it ran on two scenes of three: not a "none"


def test_tally_names_at_most_a_few_schemes_and_counts_the_rest():
    scenes = [engine_summary.choices(_cases([("core", name, 0.01, 1e-4, 0.01, 100.0)]), summary.EVALUATIONS)
              for name in ("a", "a", "b", "c", "d", "e")]
    assert engine_summary.tally(scenes)["core"]["error ≤ 0.001"] == "a ×2, b ×1, c ×1, others ×2"


def test_a_dynamics_verdict_says_each_engines_best_orders_findings_and_cases_without_a_result():
    fits = pd.DataFrame([("core", "rk4", 4.02, ""), ("core", "explicit_euler", 0.31, "below-theory"),
                         ("mujoco", "rk4", 4.0, "")], columns=["engine", "integrator", "value", "flag"])
    cases = pd.concat([CASES, _cases([("core", "explicit_euler", 0.04, math.nan, math.nan, 25.0)]).assign(
        status="diverged")])
    verdict = engine_summary.dynamics_verdict(cases, fits, 2, "rad")
    assert verdict.startswith("most accurate: core rk4 1e-08, my_plugin verlet 0.0001, mujoco rk4 1e-08, "
                              "pinocchio rk4 1e-08 rad")
    assert "orders 2 of 3 as theory; below: core explicit_euler 0.31" in verdict
    assert verdict.endswith("2 findings; cases diverged 1")


def test_errors_that_agree_to_rounding_are_one_result_and_the_cheapest_is_named():
    """Pinocchio's RK4 error a last digit below MuJoCo's (the same method) does not make it the most accurate: within
    AGREE_RELATIVE the cheaper on the clock is named."""
    close = CASES.copy()
    close.loc[close["engine"] == "pinocchio", "error"] = 1e-8 * (1 - summary.AGREE_RELATIVE / 10)
    best = summary.most_accurate_within(close, 1000.0, summary.EVALUATIONS)
    assert (best["engine"], best["integrator"]) == ("mujoco", "rk4")
    close.loc[close["engine"] == "pinocchio", "error"] = 1e-8 * (1 - 10 * summary.AGREE_RELATIVE)
    assert summary.most_accurate_within(close, 1000.0, summary.EVALUATIONS)["engine"] == "pinocchio"  # really better


def test_an_engine_that_measured_nothing_says_why_in_every_cell_and_in_the_verdict():
    nothing = _cases([("pybullet", "euler", 0.01, math.nan, math.nan, math.nan)]).assign(status="n/a")
    blown = _cases([("pinocchio", "euler", 0.01, math.nan, math.nan, math.nan)]).assign(status="diverged")
    cases = pd.concat([CASES[CASES["engine"] != "pinocchio"], nothing, blown])
    picks = engine_summary.choices(cases, summary.EVALUATIONS)
    assert set(picks["pybullet"].values()) == {"n/a"} and set(picks["pinocchio"].values()) == {"diverged"}
    assert engine_summary.tally([picks, picks])["pybullet"]["error ≤ 0.001"] == "n/a ×2"
    verdict = engine_summary.dynamics_verdict(cases, pd.DataFrame(columns=["engine", "integrator", "value", "flag"]),
                                              0, "m")
    assert "pybullet: n/a" in verdict and "pinocchio: diverged" in verdict


def test_an_engine_with_a_scheme_without_a_stage_count_ranks_all_its_schemes_by_wall_time():
    """Ranking by work would silently drop the scheme that declares no count, however good."""
    partly = CASES.copy()
    partly.loc[(partly["engine"] == "core") & (partly["integrator"] == "explicit_euler"), summary.EVALUATIONS] = math.nan
    assert engine_summary.own_cost(partly[partly["engine"] == "core"], summary.EVALUATIONS) == summary.WALL
    picks = engine_summary.choices(partly, summary.EVALUATIONS)["core"]
    assert picks["error ≤ 0.001"]["dt"] == 0.02                   # RK4 at 0.02: 0.02 s/s, the least wall time within
    uncounted = CASES.assign(**{summary.EVALUATIONS: math.nan})
    assert engine_summary.overall(uncounted, 1e-6, summary.EVALUATIONS) == (
        "none counted (4 cases without a stage count within)")


def test_tally_always_says_how_often_an_engine_had_none():
    scenes = [engine_summary.choices(_cases([("core", name, 0.01, error, 0.01, 100.0)]), summary.EVALUATIONS)
              for name, error in (("a", 1e-4), ("b", 1e-4), ("c", 1e-4), ("d", 1e-4), ("e", 1.0))]
    assert engine_summary.tally(scenes)["core"]["error ≤ 0.001"] == "a ×1, b ×1, c ×1, others ×1, none ×1"


def test_tally_counts_the_variants_of_a_scheme_as_the_scheme():
    variants = {"core": {"rk4+matrix": ["rk4", "matrix"], "rk4": ["rk4", "quaternion"]}}
    scenes = [engine_summary.choices(_cases([("core", name, 0.01, 1e-8, 0.01, 400.0)]), summary.EVALUATIONS)
              for name in ("rk4", "rk4+matrix", "rk4+matrix")]
    assert engine_summary.tally(scenes, variants)["core"]["error ≤ 1e-06"] == "rk4 ×3"
