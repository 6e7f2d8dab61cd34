"""The pytest plugin, run under pytester: the documented example passes, a broken variant fails."""

from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

EXAMPLE = Path(__file__).resolve().parents[2] / "docs" / "examples" / "test_my_numerics.py"


@pytest.mark.slow  # ~10 s of CPU: a pytest session in a subprocess
def test_the_documented_example_passes(pytester):
    pytester.makepyfile(test_example=EXAMPLE.read_text(encoding="utf-8"))
    result = pytester.runpytest_subprocess()
    result.assert_outcomes(passed=1)


@pytest.mark.slow
def test_a_tolerance_the_run_breaks_fails_with_the_violation(pytester):
    """A bound no RK4 run can meet (order exactly 5) fails the test and names the metric and the bound."""
    pytester.makefile(".toml", tight='[[bound]]\nintegrator = "rk4"\nmetric = "order_velocity"\n'
                                     'expected = 5.0\nband = 0.01\nstatus = ["ok", "n/a"]\nreason = "impossible"\n')
    pytester.makepyfile(test_broken='''
def test_broken(simparity):
    simparity.check("falling-linear-drag", engines=["core"], tolerances="tight.toml", profile="quick")
''')
    result = pytester.runpytest_subprocess()
    result.assert_outcomes(failed=1)
    assert "bound in [4.99, 5.01] (impossible)" in result.stdout.str()
    result.stdout.fnmatch_lines(["falling-linear-drag core rk4 order_velocity: 4.0*, bound in *"])


@pytest.mark.slow
def test_check_engines_leaves_the_others_findings_out_and_require_engines_fails_without_one(pytester):
    """Issue #38: a bound MuJoCo's RK4 breaks does not fail a test that holds core alone; a required engine that is
    not in the run fails it, naming it."""
    pytester.makefile(".toml", tight='[[bound]]\nengine = "mujoco"\nintegrator = "rk4"\nmetric = "order_velocity"\n'
                                     'expected = 5.0\nband = 0.01\nstatus = ["ok", "n/a"]\nreason = "impossible"\n')
    pytester.makepyfile(test_held="""
def test_core_alone(simparity):
    simparity.check("falling-linear-drag", engines=["core", "mujoco"], tolerances="tight.toml", profile="quick",
                    check_engines=["core"])

def test_both_held(simparity):
    simparity.check("falling-linear-drag", engines=["core", "mujoco"], tolerances="tight.toml", profile="quick")

def test_a_ghost_required(simparity):
    simparity.check("falling-linear-drag", engines=["core"], profile="quick", require_engines=["core", "ghost"])
""")
    result = pytester.runpytest_subprocess("-v")
    result.assert_outcomes(passed=1, failed=2)
    result.stdout.fnmatch_lines(["*test_core_alone PASSED*", "*test_both_held FAILED*"])
    result.stdout.fnmatch_lines(["*falling-linear-drag mujoco rk4 order_velocity: 4.0*(impossible)*"])
    result.stdout.fnmatch_lines(["*ghost (require_engines=): no rows in this run*"])


@pytest.fixture(scope="module")
def example_run():
    """The example's scene as it checks it (quick, core) and the table run_scene gives for it: one run of ~10 s for
    the baselines below, each built from its own copy."""
    from simparity.comparisons.api import load_scene, run_scene
    from simparity.comparisons.scenes.profiles import quick

    scene = quick(load_scene("lecture-projectile"))
    return scene, run_scene(scene, engines=["core"], repeats=0)


@pytest.mark.slow
def test_a_baseline_that_differs_fails(pytester, tmp_path, example_run):
    """--simparity-baseline with a stored run whose value differs: the move is reported."""
    from simparity.comparisons.pipeline.run_info import describe_run
    from simparity.reports.store import RunWriter
    from simparity.core.model.results import ResultRow

    scene, table = example_run
    table = table.copy()
    table.loc[table["metric"] == "position_error_final", "value"] *= 1.01
    writer = RunWriter(tmp_path / "base", describe_run([], "test", [scene]))
    writer.append([ResultRow(**row) for row in table.to_dict("records")])
    pytester.makepyfile(test_example=EXAMPLE.read_text(encoding="utf-8"))
    result = pytester.runpytest_subprocess("--simparity-baseline", str(tmp_path / "base"))
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines(["*moved since*position_error_final*"])


@pytest.mark.slow
def test_paths_are_found_beside_the_test_file_and_bad_input_is_a_one_line_failure(pytester):
    """Run from another folder, a test finds its scene and tolerances files beside itself; an unknown scene fails
    its test with simparity's one-line message, not a traceback."""
    from tests.comparisons.scenes.test_loader import VALID_DYNAMICS

    suite = pytester.mkpydir("suite")
    (suite / "drop.toml").write_text(VALID_DYNAMICS.replace("dt = [0.01]", "dt = [0.01, 0.005]"), encoding="utf-8")
    (suite / "mine.toml").write_text('[[bound]]\nscene = "drop"\nmetric = "position_error_max"\nmax = 1e-9\n'
                                     'reason = "free fall is exact for the lecture\'s Taylor rule"\n'
                                     'integrator = "taylor2"\n', encoding="utf-8")
    (suite / "test_mine.py").write_text('''
def test_found_beside(simparity):
    simparity.check("drop.toml", engines=["core"], tolerances="mine.toml", profile="quick", allow_unbounded=True)

def test_unknown(simparity):
    simparity.check("no-such-scene-anywhere", engines=["core"], profile="quick")
''', encoding="utf-8")
    result = pytester.runpytest_subprocess("suite")
    result.assert_outcomes(passed=1, failed=1)
    output = result.stdout.str()
    assert "simparity: 'no-such-scene-anywhere'" in output or "simparity: no-such-scene-anywhere" in output
    assert "Traceback" not in output and "UnknownSceneError" not in output


@pytest.mark.slow
def test_the_documented_example_passes_against_a_baseline_that_ran_more_engines(pytester, tmp_path, example_run):
    """A stored quick run of the example's scene on core and another engine (here: core's rows under a second name),
    plus another scene: the example, which runs core alone, has nothing moved and nothing missing."""
    import dataclasses

    from simparity.comparisons.pipeline.run_info import describe_run

    from simparity.reports.store import RunWriter
    from simparity.core.model.results import ResultRow

    scene, table = example_run
    rows = [ResultRow(**row) for row in table.to_dict("records")]
    more = rows + [dataclasses.replace(r, engine="mujoco") for r in rows] + [
        dataclasses.replace(r, scene="wind") for r in rows]
    RunWriter(tmp_path / "base", describe_run([], "test", [scene], "quick")).append(more)
    pytester.makepyfile(test_example=EXAMPLE.read_text(encoding="utf-8"))
    result = pytester.runpytest_subprocess("--simparity-baseline", str(tmp_path / "base"))
    result.assert_outcomes(passed=1)


@pytest.mark.parametrize("baseline, relative", [("", None), ("  ", 0.1), (None, 0.1)])
def test_an_empty_baseline_or_a_relative_change_without_one_is_refused(baseline, relative):
    """Issue #39: '' is never read as "no baseline", and a threshold without a baseline compares with nothing."""
    from simparity.comparisons.pytest_plugin import SimparityChecker

    with pytest.raises(pytest.UsageError, match="simparity-baseline"):
        SimparityChecker(baseline, relative)
