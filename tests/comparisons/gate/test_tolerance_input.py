"""Issue #39 section 2: a tolerances file is input. A bound whose scene, engine, integrator or scheme can match
nothing that exists (an unknown name, a regular expression where a glob is meant) is refused in one line with the
closest names; one that exists but matches nothing in the run is a loud line; a bound that holds no value (an empty
interval, every value below 0 on an error, a power of dt no scheme has) is refused; matching does not grow as bounds x
rows; a truth is held to "zero against itself" only where it is its own reference. Every run here is a stored table of
rows written as ``simparity run`` writes them (no engine runs), but for the one that refuses a bound before a run.
"""

import dataclasses
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import pandas as pd
import pytest

from simparity.comparisons.cli.main import EXIT_OK, EXIT_USAGE, main
from simparity.comparisons.gate import tolerances
from simparity.comparisons.gate.bound_index import BoundIndex
from simparity.comparisons.gate.check import check_table
from simparity.comparisons.gate.tolerances import load_tolerances
from simparity.core.model.errors import ToleranceError
from simparity.core.model.results import COLUMNS, OK, ResultRow, reference_label

ERROR = 1e-8
"""The error every row here measured [m]."""


def _rows(scene: str = "my-scene", engine: str = "mine", reference: str = "analytic:exact") -> list[ResultRow]:
    return [ResultRow(scene, engine, "rk4", dt, "position_error_max", ERROR, "m", reference, OK, "", "", "rk4")
            for dt in (0.01, 0.02)]


def _stored(path: Path, rows: list[ResultRow]) -> Path:
    from simparity.comparisons.pipeline.run_info import describe_run
    from simparity.reports.store import RunWriter

    RunWriter(path, describe_run([], "test", [], "quick")).append(rows)
    return path


def _file(tmp_path: Path, body: str, name: str = "mine.toml") -> Path:
    path = tmp_path / name
    path.write_text(body, encoding="utf-8")
    return path


def _bound(**keys) -> str:
    lines = "".join(f"{key} = {value!r}\n".replace("'", '"') for key, value in keys.items())
    return f"[[bound]]\n{lines}reason = \"test\"\n"


def _check(capsys, run: Path, tolerances_file: Path, *options: str) -> tuple[int, str, str]:
    code = main(["check", str(run), "--tolerances", str(tolerances_file), *options])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


# --- Every key against what exists ----------------------------------------------------------------------------------

@pytest.mark.parametrize("key, pattern, closest", [
    ("scene", "my-sceen", "my-scene"),      # the run's scene, misspelled
    ("scene", "lecture-projectle", "lecture-projectile"),  # a built-in scene, misspelled
    ("engine", "mujocoo", "mujoco"),        # an engine that is not registered
    ("engine", "myne", "mine"),             # the run's engine, misspelled
    ("integrator", "rk5", "rk4"),
    ("integrator", "semi_implicit_eulr*", "semi_implicit_euler"),
    ("scheme", "rk44", "rk4"),
    ("scheme", "penalty+rk5", "penalty"),
])
def test_a_pattern_that_matches_nothing_that_exists_is_refused_with_the_closest_names(tmp_path, capsys, key, pattern,
                                                                                      closest):
    run = _stored(tmp_path / "run", _rows())
    path = _file(tmp_path, _bound(metric="position_error_max", max=1.0) + _bound(**{key: pattern}, max=1.0))
    code, out, err = _check(capsys, run, path)
    assert code == EXIT_USAGE and out == "" and len(err.strip().splitlines()) == 1
    assert f"{path}: bound[1].{key}: '{pattern}' matches no {key} that exists" in err
    assert (f"closest: {closest}" in err) if closest else "closest" not in err


def test_each_pattern_of_a_list_is_held_even_when_the_bound_matched_rows(tmp_path, capsys):
    """A scheme list whose first pattern matches the run's rows and whose second matches nothing that exists."""
    run = _stored(tmp_path / "run", _rows())
    code, out, err = _check(capsys, run, _file(tmp_path, _bound(scheme=["rk4", "nosuch"], max=1.0)))
    assert code == EXIT_USAGE and out == "" and "bound[0].scheme: 'nosuch' matches no scheme that exists" in err


def test_a_file_reached_through_extends_is_named_with_the_file_given(tmp_path, capsys):
    """The user gave mine.toml; its extends names base.toml, whose bound is refused: the line names both."""
    run = _stored(tmp_path / "run", _rows())
    _file(tmp_path, _bound(min=2.0, max=1.0), "base.toml")
    path = _file(tmp_path, 'extends = "base.toml"\n' + _bound(max=1.0))
    code, _, err = _check(capsys, run, path)
    assert code == EXIT_USAGE and len(err.strip().splitlines()) == 1
    assert err.startswith(f"simparity: error: {path}: extends: 'base.toml': ") and "base.toml: bound[0]" in err


@pytest.mark.parametrize("key, pattern", [("scene", "ur.*"), ("engine", "(core|mujoco)"), ("scene", "^wind$"),
                                          ("integrator", "rk4.+"), ("scene", r"ur\d-ik")])
def test_a_regular_expression_where_a_glob_is_meant_is_refused_saying_so(tmp_path, capsys, key, pattern):
    run = _stored(tmp_path / "run", _rows())
    code, _, err = _check(capsys, run, _file(tmp_path, _bound(**{key: pattern}, max=1.0)))
    assert code == EXIT_USAGE and "reads as a regular expression" in err and "globs" in err


def test_a_glob_that_exists_but_matches_nothing_in_the_run_is_a_loud_line_and_a_matching_one_is_silent(tmp_path,
                                                                                                       capsys):
    run = _stored(tmp_path / "run", _rows())
    path = _file(tmp_path, _bound(engine="m*", metric="position_error_max", max=1.0)
                 + _bound(engine="pybullet", max=1.0) + _bound(scene="ur5-*", max=1.0)
                 + _bound(scheme=["penalty+*", "soft+*"], max=1.0) + _bound(integrator="clik*", max=1.0))
    code, out, _ = _check(capsys, run, path, "--junit", str(tmp_path / "junit.xml"))
    lines = [line for line in out.splitlines() if line.startswith("tolerances: ")]
    assert code == EXIT_OK
    assert [line.split(": ", 2)[2].split(" matched")[0] for line in lines] == [f"bound[{i}]" for i in (1, 2, 3, 4)]
    assert "its engine 'pybullet' matches none of the run's 1 engines" in lines[0]
    assert "its scheme ['penalty+*', 'soft+*'] matches none" in lines[2]
    skipped = ET.parse(tmp_path / "junit.xml").getroot().find(".//testcase[@classname='tolerances']/skipped")
    assert skipped is not None and skipped.text.splitlines() == [line.removeprefix("tolerances: ") for line in lines]


def test_a_bound_that_can_match_nothing_is_refused_before_a_run_starts(tmp_path, capsys):
    path = _file(tmp_path, _bound(engine="pinochio", max=1.0))
    code = main(["run", "--quick", "--check", "--tolerances", str(path), "--engines", "core", "--out",
                 str(tmp_path / "out"), "lecture-projectile"])
    err = capsys.readouterr().err
    assert code == EXIT_USAGE and "'pinochio' matches no engine that exists" in err and "closest: pinocchio" in err
    assert not (tmp_path / "out").exists()


def test_every_shipped_bound_matches_something_that_exists():
    from simparity.comparisons.gate.bound_names import refuse_impossible

    shipped = load_tolerances()
    refuse_impossible([dataclasses.replace(b, shipped=False) for b in shipped], {})


# --- Bounds that hold no value ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("keys, key, says", [
    (dict(metric="order_*", min=2, max=1), "min", "bound in [2, 1] holds no value"),
    (dict(metric="position_error_max", max=1e-3, dt_power=1e308), "dt_power", "1e+308 is no scheme's order"),
    (dict(metric="position_error_max", max=1e-3, dt_power=-17), "dt_power", "is no scheme's order"),
    (dict(metric="position_error_max", max=-1), "max", "which is never negative"),
    (dict(metric="*_error_*", max=-1e-9, dt_power=4), "max", "which is never negative"),
    (dict(metric="energy_drift_max", expected=-1.0, rel=0.5), "expected", "which is never negative"),
    (dict(metric="time_per_step", max=-1.0, dt_power=1, expected=-0.5, band=0.1), "expected", "never negative"),
    (dict(metric="order_position", expected=4.0, band=0.3, min=4.5), "expected", "holds no value"),
    (dict(metric="order_position", min=3.5, dt=1e308), "dt", "is not a time step"),
    (dict(metric="order_position", expected=4.0, rel=1e308), "rel", "is more than the expected value itself"),
    (dict(metric="order_position", min=3.5, reference="others"), "reference", "is not allowed"),
])
def test_a_bound_that_holds_no_value_is_refused_naming_its_key(tmp_path, keys, key, says):
    with pytest.raises(ToleranceError) as caught:
        load_tolerances(_file(tmp_path, _bound(**keys)))
    assert f"bound[0].{key}: " in str(caught.value) and says in str(caught.value)


@pytest.mark.parametrize("text", ["max = nan", "min = inf", "expected = -inf\nband = 1.0"])
def test_a_limit_that_is_not_finite_is_refused(tmp_path, text):
    with pytest.raises(ToleranceError, match="expected a finite number"):
        load_tolerances(_file(tmp_path, f'[[bound]]\nmetric = "position_error_max"\n{text}\nreason = "x"\n'))


@pytest.mark.parametrize("keys", [dict(metric="order_position", max=-0.5),   # an order may be negative
                                  dict(metric="mass_matrix_definiteness_min", min=-1.0, max=-0.5),  # signed
                                  dict(metric="position_error_max", min=0.0, max=0.0),  # exactly 0
                                  dict(metric="position_error_max", expected=-1.0, band=2.0),  # reaches >= 0
                                  dict(metric="position_error_max", max=1e-3, dt_power=-16)])
def test_a_bound_that_holds_some_value_is_accepted(tmp_path, keys):
    assert len(load_tolerances(_file(tmp_path, "extends = \"none\"\n" + _bound(**keys)))) == 1


def test_more_bounds_than_the_limit_are_refused_in_one_line(tmp_path, monkeypatch):
    monkeypatch.setattr(tolerances, "MAX_BOUNDS", 3)
    body = "extends = \"none\"\n" + _bound(metric="order_*", min=0.5) * 4
    with pytest.raises(ToleranceError, match="4 bounds .*at most 3 bounds"):
        load_tolerances(_file(tmp_path, body))


# --- Matching grows with the rows, not with bounds x rows -------------------------------------------------------------

ROWS = 300
SCALING_SLACK = 2
"""Candidate bounds matched per row at most: a row's own bound, and the catch-all."""


def _generated(count: int) -> list:
    """The shipped catch-all and ``count`` bounds, each for scenes of its own: alternately a pattern (a user's file keyed
    by scene) and a name written out (a blessed file's)."""
    catch_all = load_tolerances()[0]
    return [catch_all] + [dataclasses.replace(catch_all, scene=f"s{i}-*" if i % 2 else f"s{i}-x", metric="position_error_max",
                                              order=i + 1, max=float(i), statuses=(OK,), where=f"gen: bound[{i + 1}]")
                          for i in range(count)]


def _attempts(count: int) -> tuple[int, list[float | None]]:
    """Candidate bounds matched for :data:`ROWS` rows, each of another generated bound's scenes; what decided each."""
    index = BoundIndex(_generated(count))
    scenes = [f"s{i}-x" for i in range(0, count, count // ROWS)][:ROWS]
    decided = [index.decider(scene, "core", "rk4", "position_error_max", 0.01, "rk4") for scene in scenes]
    return index.attempts, [bound.max if bound is not None else None for bound in decided]


def test_matching_attempts_grow_with_the_rows_not_with_the_bounds():
    (small, _), (large, decided) = _attempts(2_000), _attempts(20_000)
    assert small <= SCALING_SLACK * ROWS and large <= SCALING_SLACK * ROWS  # a scan: ROWS x 20,001
    assert decided == [float(i) for i in range(0, 20_000, 20_000 // ROWS)][:ROWS]


def test_the_index_decides_as_a_scan_of_every_bound_does():
    bounds = _generated(200)
    index = BoundIndex(bounds)
    for i in range(0, 200, 7):
        row = (f"s{i}-{'y' if i % 2 else 'x'}", "core", "rk4", "position_error_max" if i % 3 else "order_rk4", 0.01,
               "rk4", False)
        scanned = sorted((b for b in bounds if b.matches(*row)), key=lambda b: b.precedence, reverse=True)
        assert index.matching(*row) == scanned and index.decider(*row) is scanned[0]


# --- A truth against itself, and against another engine's reference ---------------------------------------------------

def _truth_rows(reference: str) -> pd.DataFrame:
    rows = [ResultRow("my-arm", "analytic", "closed_form", 0.01, metric, 2e-16, "m", reference, OK, "", "",
                      "closed_form") for metric in ("position_error_max", "impact_time_error")]
    return pd.DataFrame([r.as_dict() for r in rows], columns=list(COLUMNS))


def test_a_truth_is_held_to_zero_against_itself_only():
    shipped = load_tolerances()
    own = check_table(_truth_rows(reference_label("analytic", "closed_form")), shipped, cross_checked=False)
    other = check_table(_truth_rows("pinocchio:dop853"), shipped, cross_checked=False)
    assert sorted(v.metric for v in own.violations) == ["impact_time_error", "position_error_max"]
    assert other.passed and other.checked == 2
    assert math.isclose(own.checked, other.checked)


@pytest.mark.parametrize("digits", [400, 5001])
def test_an_integer_beyond_any_float_is_refused_in_one_line(tmp_path, capsys, digits):
    """Held-out review of #39: 1 followed by 400 zeros overflowed a float (OverflowError); 5,001 digits pass Python's
    integer-string limit (ValueError inside the TOML parser)."""
    run = _stored(tmp_path / "run", _rows())
    path = _file(tmp_path, f'[[bound]]\nmetric = "position_error_max"\nmax = 1{"0" * digits}\nreason = "r"\n')
    code, out, err = _check(capsys, run, path)
    assert code == EXIT_USAGE and out == "" and len(err.strip().splitlines()) == 1 and str(path) in err
