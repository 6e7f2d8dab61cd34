"""One pipeline: ``simparity.run_scene`` and the pytest fixture run scenes through the session ``simparity run`` uses,
isolated by default: an engine that segfaults gives failed rows (a failed test), and the interpreter goes on."""

import os
import subprocess
import sys
import textwrap

from pathlib import Path

import pandas as pd
import pytest

from simparity import run_scene
from simparity.comparisons.pipeline.session import engine_specs, refuse_unreachable
from simparity.comparisons.scenes.library import load
from simparity.core.model.errors import SimparityError
from simparity.core.model.results import FAILED, OK
from simparity.core.inhouse import InHouseEngine
from tests.helpers import smoke

pytest_plugins = ["pytester"]

ROOT = Path(__file__).resolve().parents[3]
SCENE = "lecture-projectile"
SEGFAULTING = "tests.hostile_engines:SegfaultingEngine"

SCRIPT_SECONDS = 120
"""[s] A script that runs one small scene on one engine: imports and a worker start take a few seconds; a hang
would take for ever."""


def _small():
    """The scene as the execution tests trim it (two time steps, 100 steps of the coarsest): a crash, the isolation
    and the rows' equality do not depend on how long a case runs."""
    return smoke(load([SCENE])[0])


ONE_WORKER = 1
"""Workers of an isolated run here: one less than one per time step, and the second time step's
cases run in the worker that ran the first's (after the crash, where there is one)."""


def _with_root_on_path() -> str:
    """PYTHONPATH with the repository first (tests.helpers, for a script run in a subprocess), the rest kept."""
    return os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p)


@pytest.fixture(scope="module")
def isolated_with_a_segfault():
    """The small scene run isolated on core and the segfaulting engine by one worker, shared by the test of the crash
    and the test comparing core's rows with an in-process run (core's cases run in a process of their own, so the
    engine beside them changes none of their rows: what the second test compares is the isolation)."""
    return run_scene(_small(), engines=["core", SEGFAULTING], repeats=0, jobs=ONE_WORKER)


@pytest.mark.slow  # worker processes, one of them crashing
def test_run_scene_isolates_an_engine_that_segfaults(isolated_with_a_segfault):
    """The segfault kills the engine's case process, not this interpreter: its rows are failed, core's are ok."""
    table = isolated_with_a_segfault
    crashed = table[table["engine"] == "segfaulting"]
    assert FAILED in set(crashed["status"]) and OK not in set(crashed["status"])  # n/a: its orders, from no case
    assert crashed["detail"].str.contains("SIGSEGV|segmentation", case=False).any()
    assert OK in set(table[table["engine"] == "core"]["status"])


@pytest.mark.slow  # a run in process beside the shared isolated run
def test_run_scene_in_process_gives_the_rows_of_the_isolated_run(isolated_with_a_segfault):
    """isolate=False is the same pipeline in this process: the same rows, timing aside (core's rows of the isolated
    run, the segfaulting engine's set aside)."""
    isolated = isolated_with_a_segfault[isolated_with_a_segfault["engine"] != "segfaulting"]
    inline = run_scene(_small(), engines=["core"], repeats=0, isolate=False)
    untimed = ~isolated["metric"].str.startswith("time_per_")
    pd.testing.assert_frame_equal(isolated[untimed].reset_index(drop=True),
                                  inline[~inline["metric"].str.startswith("time_per_")].reset_index(drop=True))


def test_an_engine_class_is_run_by_its_spec():
    assert engine_specs(["core", InHouseEngine, InHouseEngine()]) == (
        "core", "simparity.core.inhouse:InHouseEngine", "simparity.core.inhouse:InHouseEngine")
    with pytest.raises(SimparityError, match="neither an engine name nor an Engine"):
        engine_specs([42])


def test_an_engine_defined_in_main_is_refused_in_one_line_when_isolated():
    with pytest.raises(SimparityError, match="defined in __main__.*isolate=False"):
        refuse_unreachable(("core", "__main__:MyEngine"))


@pytest.mark.slow  # ~7 s of CPU: a script run in a subprocess
def test_a_script_s_own_engine_is_refused_isolated_and_runs_in_process(tmp_path):
    """A script run directly (its engine in __main__): isolated, one line and no hang; in process, it runs."""
    script = tmp_path / "mine.py"
    script.write_text(textwrap.dedent(f"""
        import sys
        import simparity
        from simparity.core.inhouse import InHouseEngine
        from simparity.core.errors import SimparityError

        class Mine(InHouseEngine):
            name = "mine"

        from tests.helpers import smoke

        # smoke (the quick profile, trimmed to 2 time steps of 100 steps): the refusal comes before any case runs,
        # and the in-process run needs only ok rows of the script's engine, not the full 6 s ladder down to 1/240 s
        scene = smoke(simparity.load_scene("{SCENE}"))
        try:
            simparity.run_scene(scene, engines=[Mine], repeats=0)
        except SimparityError as err:
            print("refused:", err)
        table = simparity.run_scene(scene, engines=[Mine], repeats=0, isolate=False)
        print("in process:", sorted(set(table["engine"])), (table["status"] == "ok").sum())
    """), encoding="utf-8")
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=SCRIPT_SECONDS,
                          env={**os.environ, "PYTHONPATH": _with_root_on_path()})
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("refused: engine __main__:Mine: defined in __main__")
    assert lines[1].startswith("in process: ['mine']") and int(lines[1].split()[-1]) > 0


@pytest.mark.slow  # ~7 s of CPU: a pytest session, two isolated runs
def test_the_fixture_fails_a_test_whose_engine_segfaults_and_the_session_goes_on(pytester, monkeypatch):
    monkeypatch.setenv("PYTHONPATH", str(ROOT))  # the hostile engines' module, for the test run and its workers
    # the quick profile's coarsest time step, not smoke's 100 steps: check() judges core's rows by the shipped bounds,
    # written for the scene's whole 6 s; one time step is one group, so each check starts one worker, not two
    pytester.makepyfile(test_crash=f'''
import dataclasses

from simparity.comparisons.scenes.library import load
from simparity.comparisons.scenes.profiles import quick


def _coarse():
    scene = quick(load(["{SCENE}"])[0])
    return dataclasses.replace(scene, dts=scene.dts[-1:])


def test_crash(simparity):
    simparity.check(_coarse(), engines=["{SEGFAULTING}"])


def test_after(simparity):
    simparity.check(_coarse(), engines=["core"])
''')
    # in this process (a pytest session started in a process of its own cost its start and imports again): the
    # segfault, in a case process, would take this session down with the inner one were it not isolated
    result = pytester.runpytest_inprocess()
    result.assert_outcomes(passed=1, failed=1)
    result.stdout.fnmatch_lines(["*lecture-projectile segfaulting*failed*"])
