"""The pytest plugin, run in pytest sessions of their own: the documented example passes, broken variants fail.

The checks that need no ``--simparity-baseline`` share one session (:func:`inner`): the example, a tolerance the run
breaks, ``check_engines`` / ``require_engines`` and paths beside a test file in another folder are each a test file of
that session, and each test here reads its own inner tests' verdicts and failure texts (from the session's JUnit XML),
never another's. The two baselines are options of a whole session: each has its own, in this interpreter (the shared
session runs the example in a fresh one, the plugin found by its entry point, as a user runs it)."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from dataclasses import dataclass
from pathlib import Path

import pytest

pytest_plugins = ["pytester"]

EXAMPLE = Path(__file__).resolve().parents[2] / "docs" / "examples" / "test_my_numerics.py"
EXAMPLE_TEST = "test_the_lecture_projectile_keeps_its_known_errors"
EXAMPLE_CALL = 'simparity.check("lecture-projectile", engines=["core"], profile="quick")'

IMPOSSIBLE_RK4 = ('integrator = "rk4"\nmetric = "order_velocity"\nexpected = 5.0\nband = 0.01\nstatus = ["ok", "n/a"]\n'
                  'reason = "impossible"\n')
"""A bound no RK4 run can meet: order exactly 5."""

DRAG = Path(__file__).resolve().parents[2] / "comparisons" / "scenes" / "falling-linear-drag.toml"
DRAG_RK4 = "drag_rk4.toml"
"""The shipped falling-linear-drag scene (its name, so the shipped bounds hold it) with RK4 alone: the bounds below
are on RK4's order, and its other integrators and their orientation variants cost ~8 s of CPU a run."""
RK4_ALONE = '[simulation]\nintegrators = ["rk4"]\n'

BROKEN = f'''
def test_broken(simparity):
    simparity.check("{DRAG_RK4}", engines=["core"], tolerances="tight.toml", profile="quick", isolate=False)
'''
"""A tolerance the run breaks (the cases run in the test's process: what is tested is the verdict, not isolation)."""

HELD = f"""
def test_core_alone(simparity):
    simparity.check("{DRAG_RK4}", engines=["core", "mujoco"], tolerances="tight_mujoco.toml", profile="quick",
                    check_engines=["core"], isolate=False)

def test_both_held(simparity):
    simparity.check("{DRAG_RK4}", engines=["core", "mujoco"], tolerances="tight_mujoco.toml", profile="quick",
                    isolate=False)

def test_a_ghost_required(simparity):
    simparity.check("{DRAG_RK4}", engines=["core"], profile="quick", require_engines=["core", "ghost"],
                    isolate=False)
"""
"""Issue #38: a bound MuJoCo's RK4 breaks, held on core alone and on both; a required engine not in the run."""

BESIDE = '''
def test_found_beside(simparity):
    simparity.check("drop.toml", engines=["core"], tolerances="mine.toml", profile="quick", allow_unbounded=True,
                    isolate=False)

def test_unknown(simparity):
    simparity.check("no-such-scene-anywhere", engines=["core"], profile="quick", isolate=False)
'''
"""Run from the session's folder, a test in ``suite/`` finds its scene and tolerances beside itself."""


@dataclass(frozen=True)
class InnerSession:
    """A pytest session's output and, by test name, each test's outcome and failure text."""

    stdout: str
    outcomes: dict[str, str]
    failures: dict[str, str]

    def failure(self, test: str) -> pytest.LineMatcher:
        """The failure text of ``test`` (failed, as asserted first), to match lines in."""
        assert self.outcomes[test] == "failed", (test, self.outcomes, self.stdout[-2000:])
        return pytest.LineMatcher(self.failures[test].splitlines())


def _run_session(folder: Path) -> InnerSession:
    """``pytest -v`` in ``folder``, as pytester runs it in a subprocess (no outer options, no user config)."""
    junit = folder / "junit.xml"
    env = {key: value for key, value in os.environ.items() if key not in ("PYTEST_ADDOPTS", "TOX_ENV_DIR")}
    env |= {"HOME": str(folder), "PY_COLORS": "0"}
    done = subprocess.run([sys.executable, "-m", "pytest", "-v", "-p", "no:cacheprovider", f"--junitxml={junit}",
                           f"--basetemp={folder / 'basetemp'}"], cwd=folder, env=env, capture_output=True, text=True,
                          check=False)
    assert junit.is_file(), done.stdout[-2000:] + done.stderr[-2000:]  # the session ran
    outcomes, failures = {}, {}
    for case in ElementTree.parse(junit).getroot().iter("testcase"):
        found = [child for child in case if child.tag in ("failure", "error", "skipped")]
        outcomes[case.get("name")] = {"failure": "failed"}.get(found[0].tag, found[0].tag) if found else "passed"
        failures[case.get("name")] = "\n".join(f"{c.get('message', '')}\n{c.text or ''}" for c in found)
    return InnerSession(done.stdout, outcomes, failures)


@pytest.fixture(scope="module")
def inner(tmp_path_factory) -> InnerSession:
    """One pytest session holding every test file below that takes no baseline (the documented example, isolated as
    it is written; test_broken.py, test_held.py and suite/test_mine.py, their cases in the test's process)."""
    from tests.comparisons.scenes.test_loader import VALID_DYNAMICS

    folder = tmp_path_factory.mktemp("inner")
    files = {"test_example.py": EXAMPLE.read_text(encoding="utf-8"), "test_broken.py": BROKEN, "test_held.py": HELD,
             DRAG_RK4: DRAG.read_text(encoding="utf-8").replace("[simulation]\n", RK4_ALONE),
             "tight.toml": f"[[bound]]\n{IMPOSSIBLE_RK4}",
             "tight_mujoco.toml": f'[[bound]]\nengine = "mujoco"\n{IMPOSSIBLE_RK4}',
             "suite/__init__.py": "", "suite/test_mine.py": BESIDE,
             "suite/drop.toml": VALID_DYNAMICS.replace("dt = [0.01]", "dt = [0.01, 0.005]"),
             "suite/mine.toml": '[[bound]]\nscene = "drop"\nmetric = "position_error_max"\nmax = 1e-9\n'
                                'reason = "free fall is exact for the lecture\'s Taylor rule"\n'
                                'integrator = "taylor2"\n'}
    for name, text in files.items():
        (folder / name).parent.mkdir(exist_ok=True)
        (folder / name).write_text(text, encoding="utf-8")
    return _run_session(folder)


@pytest.mark.slow  # the shared session: ~14 s of CPU (as four sessions of their own: ~57)
def test_the_documented_example_passes(inner):
    assert inner.outcomes[EXAMPLE_TEST] == "passed", inner.failures[EXAMPLE_TEST]


@pytest.mark.slow
def test_a_tolerance_the_run_breaks_fails_with_the_violation(inner):
    """A bound no RK4 run can meet (order exactly 5) fails the test and names the metric and the bound."""
    failure = inner.failure("test_broken")
    assert "bound in [4.99, 5.01] (impossible)" in failure.str()
    failure.fnmatch_lines(["falling-linear-drag core rk4 order_velocity: 4.0*, bound in *"])


@pytest.mark.slow
def test_check_engines_leaves_the_others_findings_out_and_require_engines_fails_without_one(inner):
    """Issue #38: a bound MuJoCo's RK4 breaks does not fail a test that holds core alone; a required engine that is
    not in the run fails it, naming it."""
    assert inner.outcomes["test_core_alone"] == "passed", inner.failures["test_core_alone"]
    inner.failure("test_both_held").fnmatch_lines(["*falling-linear-drag mujoco rk4 order_velocity: 4.0*(impossible)*"])
    inner.failure("test_a_ghost_required").fnmatch_lines(["*ghost (require_engines=): no rows in this run*"])


@pytest.mark.slow
def test_paths_are_found_beside_the_test_file_and_bad_input_is_a_one_line_failure(inner):
    """Run from another folder, a test finds its scene and tolerances files beside itself; an unknown scene fails
    its test with simparity's one-line message, not a traceback."""
    assert inner.outcomes["test_found_beside"] == "passed", inner.failures["test_found_beside"]
    output = inner.failure("test_unknown").str()
    assert "simparity: 'no-such-scene-anywhere'" in output or "simparity: no-such-scene-anywhere" in output
    for text in (output, inner.stdout):
        assert "Traceback" not in text and "UnknownSceneError" not in text


@pytest.fixture(scope="module")
def example_run():
    """The example's scene as it checks it (quick, core) and the table run_scene gives for it, its cases in this
    process (where a case runs changes none of its values; isolated, the workers cost ~8 s of CPU): the baseline of
    the example's session below."""
    from simparity.comparisons.api import load_scene, run_scene
    from simparity.comparisons.scenes.profiles import quick

    scene = quick(load_scene("lecture-projectile"))
    return scene, run_scene(scene, engines=["core"], repeats=0, isolate=False)


def _example_in_process() -> str:
    """The documented example with its cases in the test's process, for the sessions that hold it to a baseline:
    what they test is the comparison (the example as written, isolated, passes in :func:`inner`)."""
    text = EXAMPLE.read_text(encoding="utf-8")
    assert text.count(EXAMPLE_CALL) == 1, "the example's check call changed: update EXAMPLE_CALL"
    return text.replace(EXAMPLE_CALL, EXAMPLE_CALL.replace(")", ", isolate=False)"))


MOVED_SCENE = "lecture-2link-dynamics"
MOVED_METRIC = "mass_matrix_definiteness_min"
"""A scene checked against a baseline in which one of its values moved: the two-link arm's joint dynamics on core
(~0.02 s of CPU, not the example's ~3 s); its mass matrix's smallest eigenvalue is ~0.16 on every row, so 1 % more
is a move at any threshold the plugin defaults to."""


@pytest.mark.slow
def test_a_baseline_that_differs_fails(pytester, tmp_path, example_run):
    """--simparity-baseline with a stored run whose value differs: the move is reported. (``example_run`` imports what
    a run imports before pytester's in-process session, which un-imports what it imported: NumPy's extension modules
    cannot be imported twice in one process.)"""
    from simparity.comparisons.api import load_scene, run_scene
    from simparity.comparisons.pipeline.run_info import describe_run
    from simparity.comparisons.scenes.profiles import quick
    from simparity.reports.store import RunWriter
    from simparity.core.model.results import ResultRow

    scene = quick(load_scene(MOVED_SCENE))
    table = run_scene(scene, engines=["core"], repeats=0, isolate=False)
    table.loc[table["metric"] == MOVED_METRIC, "value"] *= 1.01
    writer = RunWriter(tmp_path / "base", describe_run([], "test", [scene]))
    writer.append([ResultRow(**row) for row in table.to_dict("records")])
    pytester.makepyfile(test_moved=f"""
def test_moved(simparity):
    simparity.check("{MOVED_SCENE}", engines=["core"], profile="quick", isolate=False)
""")
    result = pytester.runpytest_inprocess("--simparity-baseline", str(tmp_path / "base"))
    result.assert_outcomes(failed=1)
    result.stdout.fnmatch_lines([f"*moved since*{MOVED_METRIC}*"])


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
    pytester.makepyfile(test_example=_example_in_process())
    result = pytester.runpytest_inprocess("--simparity-baseline", str(tmp_path / "base"))
    result.assert_outcomes(passed=1)


@pytest.mark.parametrize("baseline, relative", [("", None), ("  ", 0.1), (None, 0.1)])
def test_an_empty_baseline_or_a_relative_change_without_one_is_refused(baseline, relative):
    """Issue #39: '' is never read as "no baseline", and a threshold without a baseline compares with nothing."""
    from simparity.comparisons.pytest_plugin import SimparityChecker

    with pytest.raises(pytest.UsageError, match="simparity-baseline"):
        SimparityChecker(baseline, relative)
