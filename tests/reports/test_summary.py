"""The report's summary: cheapest scheme per error budget, most accurate per compute budget, IK choices,
cases without a result grouped by reason, energy gains, all from hand-made rows."""

import math

import pandas as pd

from simparity.core.model.results import ResultRow
from simparity.reports import summary
from simparity.reports.sections.dynamics import scheme_row
from simparity.reports.sections.ik import rates


def _case(engine, integrator, dt, error, seconds_per_step, status="ok", detail=""):
    common = dict(scene="s", engine=engine, integrator=integrator, dt=dt, reference="analytic:exact", detail=detail)
    value = error if status == "ok" else math.nan
    step = seconds_per_step if status == "ok" else math.nan
    return [ResultRow(metric="orientation_error_max", value=value, unit="rad", status=status, **common),
            ResultRow(metric="time_per_step", value=step, unit="s", status=status, **common)]


def _table(cases) -> pd.DataFrame:
    return pd.DataFrame([r.as_dict() for case in cases for r in case])


def test_cheapest_within_budget_skips_ground_truths_and_diverged_cases():
    """Cost is time per step / dt; the exact truth, a diverged case and a case over budget never win."""
    table = _table([
        _case("analytic", "exact", 0.1, 0.0, 1e-9),                # a ground truth: never ranked
        _case("core", "rk4", 0.1, 5e-7, 1e-4),                     # 1e-3 s/s, within 1e-6
        _case("mujoco", "rk4", 0.05, 2e-7, 1e-5),                  # 2e-4 s/s, within 1e-6: cheapest
        _case("mujoco", "euler", 0.1, math.nan, 0, status="diverged", detail="blew up"),
        _case("pybullet", "euler", 0.1, 1e-2, 1e-6),               # 1e-5 s/s but 1e-2 rad: over budget
    ])
    cases = summary.dynamics_cases(table, "orientation_error_max")
    assert "analytic" not in set(cases["engine"])
    best = summary.cheapest_within(cases, 1e-6)
    assert (best["engine"], best["integrator"], best["dt"]) == ("mujoco", "rk4", 0.05)
    assert math.isclose(best["cost"], 2e-4)
    assert summary.cheapest_within(cases, 1e-9) is None
    accurate = summary.most_accurate_within(cases, 1e-4)      # only pybullet costs <= 1e-4 s/s
    assert accurate["engine"] == "pybullet"


def test_best_per_scheme_takes_least_error_and_counts_statuses():
    table = _table([_case("core", "rk4", 0.1, 1e-5, 1e-4), _case("core", "rk4", 0.05, 1e-6, 2e-4),
                    _case("core", "rk4", 0.2, math.nan, 0, status="diverged", detail="x"),
                    _case("core", "taylor2", 0.1, math.nan, 0, status="n/a", detail="point-mass rule")])
    schemes = summary.best_per_scheme(summary.dynamics_cases(table, "orientation_error_max")).set_index("integrator")
    best = schemes.loc["rk4"]
    assert best["dt"] == 0.05 and best["error"] == 1e-6 and best["any_result"]
    assert best["statuses"] in ("ok 2, diverged 1", "diverged 1, ok 2")
    assert not schemes.loc["taylor2", "any_result"] and math.isnan(schemes.loc["taylor2", "error"])


def test_ik_best_solver_and_fastest_reliable_one():
    rows = []
    for engine, solver, rate, seconds in [("core", "dls", 1.0, 5e-4), ("mujoco", "dls", 1.0, 3e-4),
                                          ("pybullet", "tuned", 0.9, 1e-4)]:
        common = dict(scene="ik", engine=engine, integrator=solver, dt=math.nan, reference="core:fk", status="ok")
        rows += [ResultRow(metric="solve_rate", value=rate, unit="1", **common),
                 ResultRow(metric="time_per_solve", value=seconds, unit="s", **common)]
    best, fastest = summary.best_ik(summary.ik_solvers(pd.DataFrame([r.as_dict() for r in rows])))
    assert best["engine"] == "mujoco"      # 100 %, the faster of the two
    assert fastest["engine"] == "mujoco"   # pybullet is faster but below 99 %


def test_unresolved_cases_grouped_with_their_reasons_failed_first():
    table = _table([_case("core", "rk4", 0.1, 1e-5, 1e-4),
                    _case("mujoco", "euler", 0.1, 0, 0, status="diverged", detail="blew up"),
                    _case("mujoco", "euler", 0.2, 0, 0, status="diverged", detail="blew up"),
                    _case("pybullet", "x", 0.1, 0, 0, status="n/a", detail="no such integrator"),
                    _case("pinocchio", "rk4", 0.1, 0, 0, status="failed", detail="raised")])
    cases = summary.unresolved_cases(table)
    assert list(cases["status"]) == ["failed", "diverged", "n/a"]
    diverged = cases[cases["status"] == "diverged"].iloc[0]
    assert (diverged["scene"], diverged["engine"], diverged["integrator"]) == ("s", "mujoco", "euler")
    assert diverged["n_cases"] == 2 and diverged["dts"] == [0.1, 0.2]
    assert diverged["reason"] == "blew up" and not diverged["order_fit"]


def test_energy_gain_flagged_only_above_threshold_and_not_for_truths():
    def points(engine, values):
        return [dict(scene="s", engine=engine, integrator="i", dt=0.1, quantity="energy_change", unit="1", x=k,
                     value=v) for k, v in enumerate(values)]
    gain = summary.ENERGY_GAIN_FLAGGED
    series = pd.DataFrame(points("core", [0, 3 * gain, -1]) + points("mujoco", [0, 0.5 * gain, -1e-3])
                          + points("analytic", [0, 10 * gain]))
    flagged = summary.energy_gains(series)
    assert list(flagged["engine"]) == ["core"] and math.isclose(flagged["gain_max"].iloc[0], 3 * gain)


def test_variants_of_a_scheme_share_a_row_listing_what_differs():
    """Core's orientation updates of one scheme: one row; a cell lists each variant's value in the order the
    integrator cell names them, or one value where they all agree."""
    row = scheme_row("core", "rk4", [("quaternion", ("0.01", "2e-10", "ok 4")), ("matrix", ("0.01", "4e-09", "ok 4")),
                                      ("expmap", ("0.01", "2e-12", "ok 4"))])
    assert row == ("core", "rk4 (quaternion / matrix / expmap)", "0.01", "2e-10 / 4e-09 / 2e-12", "ok 4")
    assert scheme_row("mujoco", "rk4", [("", ("0.01", "1e-10", "ok 4"))]) == ("mujoco", "rk4", "0.01", "1e-10", "ok 4")


def test_ik_rates_at_both_criteria_with_unsolved_as_zero():
    """A solver stopped by its own 1e-4 m rule: 0 at the scene's 1e-6 m (n/a, unsolved), 0.97 at its own; the
    report says both, and a solver that stops at the scene's tolerance shows one rate."""
    rows = []
    for solver, rate, own, tolerance in [("default", None, 0.97, 1e-4), ("tuned", 0.9, 0.9, 1e-6)]:
        common = {"scene": "ik", "engine": "pybullet", "integrator": solver, "dt": math.nan, "reference": "core:fk"}
        unsolved = {"status": "n/a", "flag": "unsolved"} if rate is None else {"status": "ok"}
        rows += [ResultRow(metric="solve_rate", value=math.nan if rate is None else rate, unit="1", **common,
                           **unsolved),
                 ResultRow(metric="solve_rate_own_stop", value=own, unit="1", status="ok", **common),
                 ResultRow(metric="own_stop_position_tolerance", value=tolerance, unit="m", status="ok", **common),
                 ResultRow(metric="time_per_solve", value=1e-4, unit="s", status="ok", **common)]
    solvers = summary.ik_solvers(pd.DataFrame([r.as_dict() for r in rows])).set_index("integrator", drop=False)
    assert solvers.loc["default", "solve_rate"] == 0.0
    assert summary.own_rule_differs(solvers.loc["default"], 1e-6)
    assert not summary.own_rule_differs(solvers.loc["tuned"], 1e-6)
    assert rates(solvers.loc["default"], 1e-6) == "0.0% at 1e-06 m, 97.0% at its own 0.0001 m"
    assert rates(solvers.loc["tuned"], 1e-6) == "90.0% at 1e-06 m"
