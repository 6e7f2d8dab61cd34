"""A sweep as a whole (reports/sweep_summary.py), from hand-made cases: each engine x integrator over every variant
(its worst variant, the median, the median cost), the variants shown with a section of their own, and variants
merged into one line where the report lists scenes."""

import math

import pandas as pd

from simparity.core.model.run_info import RunInfo
from simparity.core.model.results import ResultRow
from simparity.reports import sweep_summary
from simparity.reports.sweep_summary import FIRST, HARDEST, LAST, across, merge_variants, union, variant_cases


def _cases(values, statuses=None, costs=None, engine="core", integrator="rk4", dt=0.01):
    """One case per variant v0, v1, ... of one scheme."""
    statuses = statuses or ["ok"] * len(values)
    costs = costs or [1e-3] * len(values)
    return pd.DataFrame({"scene": [f"v{k}" for k in range(len(values))], "engine": engine, "integrator": integrator,
                         "dt": dt, "status": statuses, "value": values, "cost": costs})


def test_across_takes_the_worst_variant_the_median_and_the_median_cost():
    cases = _cases([1e-6, 4e-6, 2e-6], costs=[1e-3, 1.0, 2e-3])   # one slow timing does not decide the cost
    row = across(cases, ["engine", "integrator", "dt"]).iloc[0]
    assert (row["status"], row["value"], row["worst_scene"]) == ("ok", 4e-6, "v1")
    assert (row["median"], row["best"]) == (2e-6, 1e-6)
    assert row["cost"] == 2e-3 and row["statuses"] == "ok 3" and row["variants"] == 3


def test_a_case_not_ok_in_every_variant_is_not_ok_across_them():
    cases = _cases([1e-6, math.nan, math.nan], statuses=["ok", "diverged", "n/a"])
    row = across(cases, ["engine", "integrator", "dt"]).iloc[0]
    assert row["status"] == "diverged" and row["value"] == 1e-6 and row["variants"] == 1
    assert set(row["statuses"].split(", ")) == {"ok 1", "diverged 1", "n/a 1"}


def test_a_solve_rate_is_worst_at_its_lowest():
    row = across(_cases([1.0, 0.9, 0.95]), ["engine", "integrator"], lower_is_better=False).iloc[0]
    assert (row["value"], row["worst_scene"], row["best"]) == (0.9, "v1", 1.0)


def test_shown_variants_are_the_ends_and_the_hardest():
    """The hardest ranks worst on average over the schemes (the first in the sweep's order on a tie); the ends are
    shown whatever their errors."""
    cases = pd.concat([_cases([1e-6, 5e-6, 3e-6, 2e-6]), _cases([1e-3, 2e-3, 5e-3, 1e-3], engine="mujoco")])
    shown = sweep_summary._shown(cases, ["v0", "v1", "v2", "v3"], ["engine", "integrator", "dt"], True)
    assert shown == {"v0": (FIRST,), "v1": (HARDEST,), "v3": (LAST,)}   # v1 and v2 tie on mean rank 0.875
    alone = sweep_summary._shown(_cases([1e-6, 1e-3]), ["v0", "v1"], ["engine", "integrator", "dt"], True)
    assert alone == {"v0": (FIRST,), "v1": (LAST, HARDEST)}


def test_merge_variants_puts_a_sweeps_variants_on_one_row():
    frame = pd.DataFrame({"scene": ["a_1", "a_2", "b"], "engine": "core", "n_cases": [2, 3, 1],
                          "dts": [[0.01], [0.02, 0.01], [0.1]]})
    merged = merge_variants(frame, {"a_1": "sweep of a", "a_2": "sweep of a"}, ["engine"],
                            n_cases=("n_cases", "sum"), dts=("dts", union))
    assert merged.to_dict("records") == [
        {"scene": "sweep of a", "engine": "core", "variants": 2, "n_cases": 5, "dts": [0.01, 0.02]},
        {"scene": "b", "engine": "core", "variants": 1, "n_cases": 1, "dts": [0.1]}]


def test_variant_cases_of_ik_keep_every_solver_and_take_the_time_per_solve_as_cost():
    rows = pd.DataFrame([ResultRow(scene, engine, solver, math.nan, metric, value, "1", "analytic:fk", "ok").as_dict()
                         for scene in ("v0", "v1") for engine, solver in (("analytic", "two_link"), ("core", "dls"))
                         for metric, value in (("solve_rate", 1.0), ("time_per_solve", 1e-4),
                                               ("hard_stretched", 0.5))])
    cases = variant_cases(rows, "ik", "solve_rate")
    assert list(cases["engine"]) == ["analytic", "core", "analytic", "core"]
    assert set(cases["value"]) == {1.0} and set(cases["cost"]) == {1e-4}


def test_a_run_without_a_sweep_has_no_sweeps():
    table = pd.DataFrame([ResultRow("s", "core", "rk4", 0.01, "position_error_max", 1e-6, "m", "analytic:exact",
                                    "ok").as_dict()])
    assert sweep_summary.sweeps(table, RunInfo()) == []
