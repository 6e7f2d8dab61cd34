"""The CI verdict: bounds held row by row, expected blow-ups pass, baselines catch moves inside tolerance."""

import dataclasses
import math

import pandas as pd
import pytest

from simparity.comparisons.gate.check import BASELINE_RELATIVE, check_table, compare_with_baseline, explain_rows
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.scenes.profiles import quick
from simparity.comparisons.execute.in_process import run_in_process as run_scene
from simparity.comparisons.scenes.loading.scene_file import parse_scenes
from simparity.comparisons.pipeline.run_info import describe_run
from simparity.reports.store import RunWriter
from simparity.comparisons.gate.tolerances import load_tolerances
from simparity.core.dynamics import tableau
from simparity.core.model.files import tomllib
from simparity.core.model.results import COLUMNS, ROUNDING_FLOOR, ResultRow
from simparity.reports.store import read_run
from tests.helpers import builtin
from tests.comparisons.scenes.test_loader import VALID_DYNAMICS


def _table(rows):
    return pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS))


def _row(metric="order_position", value=4.02, status="ok", dt=math.nan, integrator="rk4", engine="core", detail=""):
    return ResultRow("s", engine, integrator, dt, metric, value, "1", "analytic:exact", status, detail)


@pytest.fixture
def bounds(tmp_path):
    path = tmp_path / "tol.toml"
    path.write_text("""
extends = "none"
[[bound]]
metric = "*"
status = ["ok", "n/a"]
reason = "must run"
[[bound]]
integrator = "rk4"
metric = "order_*"
expected = 4.0
band = 0.5
reason = "fourth order"
[[bound]]
integrator = "euler"
dt = "*"
status = "diverged"
reason = "must blow up"
""", encoding="utf-8")
    return load_tolerances(path)


def test_rows_inside_pass_outside_fail_with_a_one_line_reason(bounds):
    result = check_table(_table([_row(value=4.02), _row(metric="order_velocity", value=2.9)]), bounds)
    assert result.checked == 2 and len(result.violations) == 1
    line = result.violations[0].line()
    assert line == "s core rk4 order_velocity: 2.9, bound in [3.5, 4.5] (fourth order)"


def test_a_bounded_metric_that_went_n_a_is_a_violation_not_a_pass(bounds):
    result = check_table(_table([_row(value=math.nan, status="n/a", detail="saturated: lost")]), bounds)
    assert len(result.violations) == 1 and "status n/a; saturated: lost" in result.violations[0].found


def test_an_expected_blow_up_passes_and_a_bounded_run_fails(bounds):
    blew = _row(metric="position_error_max", value=math.nan, status="diverged", dt=0.01, integrator="euler")
    held = _row(metric="position_error_max", value=1e-3, status="ok", dt=0.02, integrator="euler")
    result = check_table(_table([blew, held]), bounds)
    assert [v.dt for v in result.violations] == [0.02] and "must blow up" in result.violations[0].line()


def test_baseline_flags_a_1e9_change_inside_tolerance_and_keeps_timing_apart():
    """An RK4 error of 1e-6 m moved by 1e-9 m (1e-3 relative, far inside any tolerance) is a move;
    a timing change is a note; a vanished row is missing, an added one new."""
    before = _table([_row("position_error_max", 1e-6, dt=0.01), _row("time_per_step", 1e-5, dt=0.01),
                     _row("velocity_error_max", 1e-7, dt=0.01)])
    after = _table([_row("position_error_max", 1e-6 + 1e-9, dt=0.01), _row("time_per_step", 2e-5, dt=0.01),
                    _row("angular_velocity_error_max", 1e-7, dt=0.01)])
    diff = compare_with_baseline(after, before)
    assert len(diff.moved) == 1 and "position_error_max" in diff.moved[0] and "1e-06 -> 1.001e-06" in diff.moved[0]
    assert len(diff.timing) == 1 and diff.blocking
    assert "velocity_error_max" in diff.missing[0] and "angular_velocity_error_max" in diff.new[0]
    same = compare_with_baseline(before, before)
    assert not (same.moved or same.missing or same.new or same.timing)
    assert BASELINE_RELATIVE < 1e-3


@pytest.mark.slow
def test_a_degraded_rk4_fails_the_shipped_tolerances(monkeypatch):
    """RK4 with a wrong stage weight (b = 1/6, 1/3, 1/3, 1/6 -> 1/6, 1/6, 1/2, 1/6: still consistent, second
    order at best) fails the shipped order gate on a tumbling box; the true RK4 passes."""
    scene = dataclasses.replace(quick(builtin("tumbling-box-stable")), integrators=("rk4",))
    bounds = load_tolerances()
    good = check_table(_table(run_scene(scene, [make_engine("core")], make_engine, repeats=0)), bounds)
    assert good.passed, [v.line() for v in good.violations]
    monkeypatch.setitem(tableau.TABLEAUX, "rk4", dataclasses.replace(tableau.RK4, b=(1 / 6, 1 / 6, 1 / 2, 1 / 6)))
    bad = check_table(_table(run_scene(scene, [make_engine("core")], make_engine, repeats=0)), bounds)
    assert not bad.passed and any(v.metric == "order_orientation" for v in bad.violations)


def test_a_run_with_sweep_columns_is_checked_and_compared_like_any_other(bounds, tmp_path):
    """The gate reads the fixed columns: a swept run's extra columns change no verdict, and a run stored before
    sweeps (fixed columns only) is its baseline without a move."""
    variants = parse_scenes(tomllib.loads(VALID_DYNAMICS + '[sweep]\n"body[ball].mass" = [1.0, 2.0]\n'))
    rows = [dataclasses.replace(_row(value=value), scene=scene.name) for scene in variants for value in (4.02, 2.9)]
    RunWriter(tmp_path / "new", describe_run([], "simparity run", variants)).append(rows)
    RunWriter(tmp_path / "old", describe_run([], "simparity run", [])).append(rows)
    new, old = read_run(tmp_path / "new")[0], read_run(tmp_path / "old")[0]
    assert "sweep:body[ball].mass" in new.columns and tuple(old.columns) == COLUMNS
    verdict = check_table(new, bounds)
    lines = [v.line() for v in verdict.violations]
    assert (verdict.checked, len(lines)) == (4, 2) and lines == [v.line() for v in check_table(old, bounds).violations]
    diff = compare_with_baseline(new, old)
    assert not (diff.moved or diff.missing or diff.new)


def test_a_bound_says_when_n_a_is_the_right_answer(tmp_path):
    """A bound that wants a number passes an n/a row whose flag it names in na_when (a resting run has no energy
    to gain), and fails an n/a row of another flag or none (the engine could not measure it)."""
    path = tmp_path / "tol.toml"
    path.write_text("""
extends = "none"
[[bound]]
metric = "energy_gain_max"
max = 0.0
na_when = ["nothing-to-measure"]
reason = "contact only takes energy away"
""", encoding="utf-8")
    bounds = load_tolerances(path)
    resting = dataclasses.replace(_row("energy_gain_max", math.nan, "n/a"), flag="nothing-to-measure")
    unmeasured = _row("energy_gain_max", math.nan, "n/a")
    result = check_table(_table([resting, unmeasured]), bounds)
    assert result.checked == 2 and len(result.violations) == 1 and result.violations[0].found.startswith("status n/a")


def test_an_alarm_flag_fails_every_bound_that_does_not_name_it(bounds, tmp_path):
    """An order that does not converge is n/a, which the catch-all allows; its alarm flag fails it anyway, unless
    a bound names the flag in na_when."""
    alarm = dataclasses.replace(_row("order_position", math.nan, "n/a", integrator="midpoint"), flag="not-converging")
    result = check_table(_table([alarm]), bounds)
    assert len(result.violations) == 1 and "not-converging" in result.violations[0].found
    path = tmp_path / "tol.toml"
    path.write_text("""
extends = "none"
[[bound]]
metric = "order_*"
status = ["ok", "n/a"]
na_when = ["not-converging"]
reason = "this scene's errors are dominated by its reference's own error"
""", encoding="utf-8")
    assert check_table(_table([alarm]), load_tolerances(path)).passed


def test_na_when_names_flags_only(tmp_path):
    path = tmp_path / "tol.toml"
    path.write_text('extends = "none"\n[[bound]]\nmetric = "*"\nstatus = "ok"\nna_when = ["nothing"]\nreason = "r"\n', encoding="utf-8")
    with pytest.raises(Exception, match="na_when"):
        load_tolerances(path)


def test_an_error_at_its_rounding_floor_meets_any_upper_bound_and_no_lower_one(tmp_path):
    """A value the harness flags as at its rounding floor is exact up to rounding: an upper bound written tighter
    than the rounding of this scene (an exact scheme's 1e-9 m/s, far from the origin) passes; the same value
    without the flag fails, and a lower bound it is under still fails."""
    path = tmp_path / "tol.toml"
    path.write_text("""
extends = "none"
[[bound]]
metric = "velocity_error_max"
max = 1e-9
reason = "exact scheme"
[[bound]]
metric = "position_error_final"
min = 0.1
reason = "closed form of the scheme's error"
""", encoding="utf-8")
    bounds = load_tolerances(path)
    far = _row("velocity_error_max", 1.05e-9, dt=0.002, integrator="backup")
    assert not check_table(_table([far]), bounds, cross_checked=False).passed
    assert check_table(_table([dataclasses.replace(far, flag=ROUNDING_FLOOR)]), bounds, cross_checked=False).passed
    low = dataclasses.replace(_row("position_error_final", 1e-15, dt=0.002), flag=ROUNDING_FLOOR)
    assert not check_table(_table([low]), bounds, cross_checked=False).passed


def _catch_all_only(tmp_path, numeric: str = ""):
    path = tmp_path / "catch_all.toml"
    path.write_text('extends = "none"\n[[bound]]\nmetric = "*"\nstatus = ["ok", "n/a"]\nreason = "it ran"\n' + numeric,
                    encoding="utf-8")
    return load_tolerances(path)


def test_a_run_held_only_to_its_statuses_is_too_unbounded_to_pass(tmp_path):
    """Ten series held only by a status catch-all fail the gate with a one-line reason; one numeric bound per series
    (here on its order) is enough; timing rows and a series with nothing measured (all n/a) do not count."""
    rows = [_row(metric=m, value=1.0, dt=0.01, integrator=f"scheme{k}") for k in range(10)
            for m in ("position_error_max", "time_per_step")]
    rows += [_row(metric="order_position", value=4.0, integrator=f"scheme{k}") for k in range(10)]
    rows += [_row(metric="position_error_max", value=math.nan, status="n/a", dt=0.01, integrator="cannot")]
    loose = check_table(_table(rows), _catch_all_only(tmp_path))
    assert loose.passed and len(loose.series) == 10 and loose.unbounded_share == 1.0
    reason = loose.too_unbounded()
    assert reason.startswith("10 of 10 series") and "--allow-unbounded" in reason and "\n" not in reason
    held = check_table(_table(rows), _catch_all_only(
        tmp_path, '[[bound]]\nmetric = "order_*"\nmin = 3.5\nreason = "fourth order"\n'))
    assert held.unbounded_share == 0.0 and held.too_unbounded() == "" and held.value_bounded == 10


@pytest.mark.slow  # ~9 s of CPU: the built-in suites run
def test_the_shipped_tolerances_hold_the_built_in_suites_to_values(tmp_path):
    """The shipped file leaves at most the documented share of the built-in suites' series without a value bound
    (the quick default suite, stored beside the tests as a results table is too large: measured here on a run of
    three representative scenes instead: a free body, a contact scene, an IK scene)."""
    table = pd.concat([_table(run_scene(quick(builtin(name)), [make_engine("core")], make_engine, repeats=0))
                       for name in ("lecture-projectile", "ball-bounce-k05", "lecture-planar-arm")])
    result = check_table(table, load_tolerances())
    assert result.passed and result.too_unbounded() == "", result.too_unbounded()


def test_a_diverged_case_is_one_line_with_the_count_of_its_metrics():
    """Eight rows of one case that went diverged against a bound wanting ok are one grouped line; another case is
    another line; --verbose keeps every row (the violations themselves)."""
    from simparity.comparisons.gate.violation import grouped

    metrics = ("position_error_max", "position_error_final", "orientation_error_max", "velocity_error_max",
               "angular_velocity_error_max", "energy_drift_max", "angular_momentum_drift_max",
               "quaternion_norm_deviation_max")
    rows = [_row(metric=m, value=math.nan, status="diverged", dt=dt, integrator="rk4", detail="blew up at t = 1 s")
            for dt in (0.01, 0.02) for m in metrics]
    result = check_table(_table(rows), load_tolerances())
    lines = [g.line() for g in grouped(result.violations)]
    assert len(result.violations) == 16 and len(lines) == 2
    assert lines[0].startswith("s core rk4 dt=0.01: 8 metrics (position_error_max, position_error_final, "
                               "orientation_error_max, +5 more): status diverged; blew up at t = 1 s, bound status ok")


def test_a_baseline_compares_only_the_scenes_and_engines_both_runs_ran():
    """A baseline with more scenes and engines than the run: nothing missing, nothing moved, the left-out rows
    counted in one line; a row gone within a shared scene x engine is still missing; timing is one line per scene."""
    def rows(scene, engine, factor=1.0):
        return [dataclasses.replace(_row("position_error_max", 1e-6, dt=dt, engine=engine), scene=scene)
                for dt in (0.01, 0.02)] + [dataclasses.replace(_row("time_per_step", 1e-5 * factor, dt=dt,
                                                                    engine=engine), scene=scene) for dt in (0.01, 0.02)]
    baseline = _table(rows("a", "core") + rows("a", "mujoco") + rows("b", "core"))
    subset = _table(rows("a", "core", factor=2.0))
    diff = compare_with_baseline(subset, baseline)
    assert not (diff.moved or diff.missing or diff.new or diff.blocking)
    assert diff.timing == ["a: 2 of 2 timings changed, now / before x2 to x2"]
    assert diff.out_of_scope == 8 and diff.scope_line() == ("not compared: 8 baseline rows of scenes x engines this "
                                                            "run did not run")
    gone = compare_with_baseline(_table(rows("a", "core")[1:]), baseline)
    assert len(gone.missing) == 1 and gone.blocking


def test_explain_rows_lists_every_matching_bound_and_which_decided(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text('[[bound]]\nmetric = "order_*"\nmin = 0.0\nreason = "mine"\n', encoding="utf-8")
    table = _table([_row(metric="order_position", value=4.0, integrator="rk4")]).assign(scheme="rk4")
    lines = explain_rows(table, load_tolerances(path), "core", metric="order_*")
    assert lines[0].startswith("s core rk4 order_position = 4: ") and "bound(s) matched" in lines[0]
    assert lines[1].startswith("  decides: ") and "mine.toml: bound[0]" in lines[1] and "(mine)" in lines[1]
    overridden = [line for line in lines[2:] if "default.toml" in line]
    assert overridden and all("overridden: the deciding bound's file extends this one" in line for line in overridden)


def test_a_series_that_measured_nothing_neither_counts_nor_hides_an_unbounded_one(tmp_path):
    """Held-out finding: an all-n/a series decided by a value bound that allows n/a measured nothing; it must not
    count as bounded, so the one measured series without a value bound is 1 of 1."""
    bounds = _catch_all_only(tmp_path, '[[bound]]\nintegrator = "cannot"\nmetric = "*"\nmax = 1.0\n'
                                       'status = ["ok", "n/a"]\nreason = "allows n/a"\n')
    rows = [_row(metric="position_error_max", value=math.nan, status="n/a", dt=0.01, integrator="cannot"),
            _row(metric="position_error_max", value=1e-3, dt=0.01, integrator="measured")]
    result = check_table(_table(rows), bounds)
    assert result.series == {("s", "core", "measured"): False} and result.too_unbounded()


def test_an_ok_row_without_a_finite_value_breaks_a_numeric_bound_and_a_huge_power_does_not_crash(tmp_path):
    bounds = _catch_all_only(tmp_path, '[[bound]]\nmetric = "order_*"\nmin = 3.5\nreason = "fourth order"\n'
                                       '[[bound]]\nmetric = "position_*"\nmax = 1e308\ndt_power = -16\nreason = "x"\n')
    rows = [_row(value=math.inf), _row(metric="position_error_max", value=1.0, dt=1e-300)]
    result = check_table(_table(rows), bounds)
    assert [v.metric for v in result.violations] == ["order_position"]
