"""Issue #38 section 3: a gate that checks what the user wrote, and only what they asked.

A metric misspelled in a tolerances file is refused (exit 2, naming the closest names), a bound of the user's that
matched no row is said so; ``--check-engines`` (or the file's ``check_engines``) says which engines the gate holds, the
others' violations are findings that never fail it; ``--require-engines`` fails a gate an engine measured nothing in;
the verdict line says how many engines the gate held. Every run here is a stored table of rows written as ``simparity
run`` writes them (no engine runs), but for the one that shows MuJoCo's refusal of a model in its own words.
"""

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from simparity.comparisons.cli.main import EXIT_FAILED_CASES, EXIT_OK, EXIT_USAGE, main
from simparity.comparisons.gate.metric_names import unknown_metric
from simparity.comparisons.gate.tolerances import DEFAULT_TOLERANCES, load_tolerances
from simparity.core.model.errors import ToleranceError
from simparity.core.model.results import NOT_AVAILABLE, OK, ResultRow

ERROR_SCALE = 1e-6
"""The users' engines' error per second of time step in these runs [m/s]: 1e-8 m at dt = 0.01 s."""
ERROR_MAX = 1e-7
"""The users' bound on the error [m]: ten times what a right engine errs by here, a tenth of a wrong one's."""
WRONG = 100.0
"""How many times a wrong engine's error is a right one's: ten times over ERROR_MAX."""

BOUND = f'''
[[bound]]
scene = "my-scene"
metric = "position_error_max"
max = {ERROR_MAX}
reason = "ten times what a right engine errs by on my scene"
'''


def _stored(path: Path, rows: list[ResultRow]) -> Path:
    from simparity.comparisons.pipeline.run_info import describe_run
    from simparity.reports.store import RunWriter

    RunWriter(path, describe_run([], "test", [], "quick")).append(rows)
    return path


def _rows(engine: str, factor: float = 1.0, status: str = OK, detail: str = "") -> list[ResultRow]:
    return [ResultRow("my-scene", engine, f"scheme{k}", dt, "position_error_max", ERROR_SCALE * dt * factor, "m",
                      "analytic:exact", status, detail) for k in range(2) for dt in (0.01, 0.02)]


def _file(tmp_path: Path, text: str, name: str = "mine.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _check(capsys, run: Path, *options: str) -> tuple[int, str, str]:
    code = main(["check", str(run), *options])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


# --- What the user wrote: metric names against the catalogue ------------------------------------------------------

@pytest.mark.parametrize("metric, says", [("positon_error_max", "'positon_error_max' is not a metric"),
                                          ("positon_*", "the pattern 'positon_*' matches no metric")])
def test_a_misspelled_metric_is_refused_naming_file_key_and_the_closest_names(tmp_path, capsys, metric, says):
    """Before: the bound matched no row, held nothing and the gate passed (exit 0)."""
    run = _stored(tmp_path / "run", _rows("mine", factor=WRONG))
    tolerances = _file(tmp_path, BOUND.replace('"position_error_max"', f'"{metric}"'))
    code, out, err = _check(capsys, run, "--tolerances", str(tolerances))
    assert code == EXIT_USAGE and out == ""
    assert len(err.strip().splitlines()) == 1
    assert f"{tolerances}: bound[0].metric: {says}" in err and "closest: " in err and "position" in err


@pytest.mark.parametrize("metric", ["hard_elbow_solved", "hard_*", "invariance_*_rescale", "*_error_*", "order_*"])
def test_a_family_member_or_a_pattern_the_catalogue_matches_is_accepted(metric):
    assert unknown_metric(metric) == ""


def test_every_metric_of_the_shipped_tolerances_is_in_the_catalogue():
    bounds = load_tolerances(DEFAULT_TOLERANCES)
    assert bounds and all(unknown_metric(b.metric) == "" for b in bounds) and all(b.shipped for b in bounds)


def test_a_bound_of_the_user_s_that_matches_no_row_is_a_loud_line_not_a_failure(tmp_path, capsys):
    run = _stored(tmp_path / "run", _rows("mine"))
    tolerances = _file(tmp_path, BOUND + BOUND.replace('"my-scene"', '"my-scen*"').replace(
        '"position_error_max"', '"order_*"') + BOUND.replace('"my-scene"', '"wind"'))
    code, out, _ = _check(capsys, run, "--tolerances", str(tolerances))
    lines = [line for line in out.splitlines() if line.startswith("tolerances: ")]
    assert code == EXIT_OK
    assert lines == [f"tolerances: {tolerances}: bound[1] matched no row of this run: its metric 'order_*' matches none "
                     "of the run's 1 metrics; it held nothing",
                     f"tolerances: {tolerances}: bound[2] matched no row of this run: its scene 'wind' matches none "
                     "of the run's 1 scenes; it held nothing"]


# --- Only what the user asked: the engines the gate holds ------------------------------------------------------------

def test_check_engines_reports_the_others_findings_and_never_fails_on_them(tmp_path, capsys):
    """Before: a violation of any engine failed the gate, whichever engine the user was gating."""
    run = _stored(tmp_path / "run", _rows("mine") + _rows("theirs", factor=WRONG))
    tolerances = _file(tmp_path, BOUND)
    code, out, _ = _check(capsys, run, "--tolerances", str(tolerances))
    assert code == EXIT_FAILED_CASES and "violation: my-scene theirs" in out
    junit = tmp_path / "junit.xml"
    code, out, _ = _check(capsys, run, "--tolerances", str(tolerances), "--check-engines", "mine", "--junit", str(junit))
    assert code == EXIT_OK and "violation:" not in out
    assert [line.split(":")[0] for line in out.splitlines()].count("finding (not held)") == 4  # a line per case
    assert all("theirs" in line for line in out.splitlines() if line.startswith("finding"))
    assert "check passed: 4 metrics of 1 engine (mine) checked (not held: theirs, 4 findings, never blocking)" in out
    suite = ET.parse(junit).getroot()
    assert suite.get("failures") == "0" and suite.get("skipped") == "4"
    # the same asked in the tolerances file; the command line wins over it
    held = _file(tmp_path, 'check_engines = ["mine"]\n' + BOUND, "held.toml")
    assert _check(capsys, run, "--tolerances", str(held))[0] == EXIT_OK
    assert _check(capsys, run, "--tolerances", str(held), "--check-engines", "theirs")[0] == EXIT_FAILED_CASES


def test_a_held_engine_the_run_does_not_have_is_a_one_line_error(tmp_path, capsys):
    run = _stored(tmp_path / "run", _rows("mine"))
    code, out, err = _check(capsys, run, "--check-engines", "mien", "--allow-unbounded")
    assert code == EXIT_USAGE and out == "" and "--check-engines: mien: not an engine of the run" in err
    assert "allowed: the run's engines, mine" in err


# --- A gate with one engine fewer is not green: required engines ---------------------------------------------------

MINE = BOUND.replace('scene = "my-scene"', 'scene = "my-scene"\nengine = "mine"')
"""The user's bound on their own engine alone."""
REFUSAL = ("MuJoCo refuses the model (bounding a mass or balancing an inertia would change it): Error: mass and "
           "inertia of moving bodies must be larger than mjMINVAL Element name 'l1', id 2")


def test_a_required_engine_missing_or_measuring_nothing_fails_the_gate_in_its_own_words(tmp_path, capsys):
    run = _stored(tmp_path / "run", _rows("mine") + _rows("mujoco", status=NOT_AVAILABLE, detail=REFUSAL))
    tolerances = _file(tmp_path, MINE)
    code, out, _ = _check(capsys, run, "--tolerances", str(tolerances))
    assert code == EXIT_OK and "8 metrics of 2 engines (mine, mujoco) checked" in out
    assert "mujoco measured nothing" in out  # held, but said so
    code, out, _ = _check(capsys, run, "--tolerances", str(tolerances), "--require-engines", "mine,mujoco,ghost")
    required = [line for line in out.splitlines() if line.startswith("required: ")]
    assert code == EXIT_FAILED_CASES and "check FAILED" in out
    assert required == [f"required: mujoco (--require-engines): no measured ok row; n/a: {REFUSAL}",
                        "required: ghost (--require-engines): no rows in this run (not run, or not installed)"]
    asked = _file(tmp_path, 'require_engines = ["mujoco"]\n' + MINE, "required.toml")
    code, out, _ = _check(capsys, run, "--tolerances", str(asked))
    assert code == EXIT_FAILED_CASES and f"required: mujoco ({asked}: require_engines)" in out
    assert _check(capsys, run, "--tolerances", str(tolerances), "--require-engines", "mine")[0] == EXIT_OK


@pytest.mark.parametrize("text, says", [('check_engines = "mine"\n', "expected a list of engine names"),
                                        ("check_engines = []\n", "expected a list of engine names"),
                                        ('check_engine = ["mine"]\n', "check_engine: unknown table")])
def test_a_bad_engine_key_in_a_tolerances_file_is_refused(tmp_path, text, says):
    with pytest.raises(ToleranceError, match=says):
        load_tolerances(_file(tmp_path, text + BOUND))


def test_run_refuses_engine_options_without_check(tmp_path, capsys):
    assert main(["run", "wind", "--out", str(tmp_path / "o"), "--check-engines", "core"]) == EXIT_USAGE
    assert "without --check" in capsys.readouterr().err and not (tmp_path / "o").exists()


@pytest.mark.slow
def test_an_engine_that_refuses_a_model_is_a_row_with_its_own_words(tmp_path):
    """MuJoCo refuses a moving link without mass (its compiler's mjMINVAL); the row says so in MuJoCo's words."""
    from simparity.comparisons.api import run_scene

    (tmp_path / "arm.urdf").write_text(MASSLESS_LINK_ARM, encoding="utf-8")
    scene = _file(tmp_path, MASSLESS_LINK_SCENE, "scene.toml")
    table = run_scene(scene, engines=["core", "mujoco"], repeats=0, profile="quick")
    refused = table[table["engine"] == "mujoco"]
    assert len(refused) and set(refused["status"]) == {NOT_AVAILABLE}
    assert refused["detail"].str.contains("mass and inertia of moving bodies must be larger than mjMINVAL").all()
    assert OK in set(table[table["engine"] == "core"]["status"])


MASSLESS_LINK_ARM = """<?xml version="1.0"?>
<robot name="massless-link-arm">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="l1"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="10" velocity="3"/>
  </joint>
  <link name="l1"/>
  <joint name="j2" type="revolute">
    <parent link="l1"/><child link="l2"/><origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="10" velocity="3"/>
  </joint>
  <link name="l2">
    <inertial><origin xyz="0.15 0 0"/><mass value="1.0"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
</robot>
"""
"""Two revolute joints with a link without mass between them: Pinocchio and core take it, MuJoCo's compiler not."""

MASSLESS_LINK_SCENE = """
[scene]
name = "massless-link-arm"
description = "a moving link without mass"
kind = "joint_dynamics"
reference = "pinocchio"

[chain]
urdf = "arm.urdf"
tip_link = "l2"

[world]
gravity_world = [0.0, 0.0, -9.81]

[sampling]
states = 5
seed = 1
"""


def test_the_report_s_verdict_names_each_finding_s_engine_and_the_engines_held(tmp_path):
    """What the report's "is my engine right?" sections are built from: each line's engine, and whom the gate holds
    (``simparity run --check --check-engines`` passes its names through the session to the report)."""
    from simparity.comparisons.gate.check import check_table, held_to
    from simparity.comparisons.gate.check_output import report_verdict
    from simparity.comparisons.gate.tolerances import EngineNames
    from simparity.reports.store import read_run

    run = _stored(tmp_path / "run", _rows("mine", factor=WRONG) + _rows("theirs", factor=WRONG))
    result = check_table(read_run(run)[0], load_tolerances(_file(tmp_path, BOUND)))
    verdict = report_verdict(result, ("mine",))
    assert verdict.held == ("mine",) and set(verdict.engines) == {"mine", "theirs"}
    assert all(line.split()[1] == engine for line, engine in zip(verdict.violations, verdict.engines))
    narrowed = report_verdict(held_to(result, EngineNames(("theirs",), "--check-engines")))
    assert narrowed.held == ("theirs",) and narrowed.outside_count == verdict.outside_count  # findings still listed


def test_run_check_refuses_a_held_engine_it_does_not_run_before_running(tmp_path, capsys):
    out = tmp_path / "o"
    code = main(["run", "wind", "--quick", "--engines", "core", "--out", str(out), "--check", "--check-engines",
                 "core,mine"])
    assert code == EXIT_USAGE and "--check-engines: mine: not an engine of the run" in capsys.readouterr().err
    assert not (out / "results.csv").exists()


@pytest.mark.slow
def test_the_report_opens_with_the_users_engine_only_when_the_gate_holds_it(tmp_path, capsys):
    run = _stored(tmp_path / "run", _rows("mine") + _rows("core"))
    assert main(["report", str(run)]) == EXIT_OK
    assert "\n## Is mine right?\n" in (run / "report.md").read_text(encoding="utf-8")
    held = _file(tmp_path, 'check_engines = ["core"]\n' + BOUND, "held.toml")
    assert main(["report", str(run), "--tolerances", str(held)]) == EXIT_OK
    assert "## Is mine right?" not in (run / "report.md").read_text(encoding="utf-8")
