"""A user's engine is built and described in a process of its own: one that crashes, exits or hangs as it is
constructed or asked about itself becomes a broken engine naming the cause, and simparity goes on."""

from __future__ import annotations

import time

import pandas as pd
import pytest

from simparity.comparisons.engines import probe as engine_probe
from simparity.comparisons.cli.main import main
from simparity.comparisons.engines.probe import PROBE_CHAIN, DescribedEngine, probe_engines
from simparity.comparisons.engines.placeholders import BrokenEngine
from simparity.comparisons.engines.registry import EngineSet
from simparity.comparisons.execute.isolation import CaseLimits
from simparity.comparisons.pipeline.session import ISOLATED, Execution, Session
from simparity.comparisons.scenes.library import load
from simparity.core.inhouse import InHouseEngine
from tests.comparisons.engines.probe_spy import spy_probes
from tests.helpers import THROWN_BALL, builtin

CORE_SPEC = "simparity.core.inhouse:InHouseEngine"
"""Core named by its spec: a plugin whose integrators differ by scene (contact or not)."""

SHORT_PROBE_SECONDS = 5.0
"""The hanging engine's limit in these tests: a probe's start and imports take ~1-2 s under load."""

OWN_SPEC = "tests.comparisons.engines.own_engine:OwnIntegrators"
"""A user's engine with an integrator of its own (``own_rk4``)."""

RUN_SECONDS = 90.0
"""A run of the tiny scene on core takes ~5 s, ~30 s on a loaded machine; far under the 900 s a hung case would
take."""


@pytest.fixture(scope="module")
def described_core():
    """Core named by its spec, described by one probe, and the scenes it was asked about (the projectile and the
    bouncing ball: core offers each different integrators): shared by the tests that read the description."""
    scenes = [builtin("lecture-projectile"), builtin("ball-bounce-k05")]
    return scenes, probe_engines([CORE_SPEC], scenes)[CORE_SPEC]


@pytest.mark.slow
def test_a_probe_describes_an_engine_as_it_describes_itself(described_core):
    scenes, described = described_core
    real = InHouseEngine()
    assert isinstance(described, DescribedEngine)
    assert described.name == CORE_SPEC and described.version() == real.version()  # "core" is the built-in's
    assert described.integrators() == real.integrators() and described.ik_solvers() == real.ik_solvers()
    for integrator in real.integrators():
        assert described.theoretical_order(integrator) == real.theoretical_order(integrator)
        assert described.stages(integrator) == real.stages(integrator)
        assert described.integrator_variant(integrator) == real.integrator_variant(integrator)
    for scene in scenes:  # contact methods on the bouncing ball, free-body integrators on the projectile
        assert described.scene_integrators(scene) == real.scene_integrators(scene)
    assert described.scene_integrators(scenes[0]) != described.scene_integrators(scenes[1])
    assert described.supports_kinematics(PROBE_CHAIN).ok
    # found by the mutation suite: a described engine offered no joint-motion integrator, so a plugin's chains in
    # motion were n/a in every run (and a planted bug in them passed the gate)
    assert described.joint_motion_integrators() == real.joint_motion_integrators() != ()
    assert described.joint_dynamics_methods() == real.joint_dynamics_methods()
    for integrator in real.joint_motion_integrators():
        assert described.theoretical_order(integrator) == real.theoretical_order(integrator)
        assert described.stages(integrator) == real.stages(integrator)


SEGFAULT, EXITS, HANGS = (f"tests.hostile_engines:{name}" for name in
                          ("SegfaultOnConstruction", "ExitInVersion", "HangInIntegrators"))
MISSING = "no_such_module_here:Engine"
"""A spec whose module does not import."""


def _run(scene, engines: str, out, *extra: str) -> int:
    """``simparity run`` of a scene file into ``out``: one worker, no timing repeats and no report (no test here
    reads one)."""
    return main(["run", str(scene), "--engines", engines, "--repeats", "0", "--jobs", "1", "--no-report",
                 "--out", str(out), *extra])


@pytest.fixture(scope="module")
def hostile_run(tmp_path_factory):
    """One run shared by the tests below: core beside an engine that segfaults as it is built, one that exits
    as it is asked its version, one that hangs as it is described (the probe's limit cut to SHORT_PROBE_SECONDS) and
    MISSING; its exit code, its seconds, its results table and what each engine's probe answered last."""
    folder = tmp_path_factory.mktemp("hostile")
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(engine_probe, "PROBE_SECONDS", SHORT_PROBE_SECONDS)
        spy = spy_probes(patch)
        start = time.monotonic()
        scene = folder / "throw.toml"
        scene.write_text(THROWN_BALL, encoding="utf-8")
        code = _run(scene, f"core,{SEGFAULT},{EXITS},{HANGS},{MISSING}", folder / "run")
        seconds = time.monotonic() - start
    return code, seconds, pd.read_csv(folder / "run" / "results.csv"), spy.answers


@pytest.mark.slow
def test_a_crash_or_an_exit_while_building_or_describing_is_a_broken_engine(hostile_run):
    found = hostile_run[3]
    segfault = found[SEGFAULT]
    assert isinstance(segfault, BrokenEngine) and "killed by signal 11 (SIGSEGV)" in segfault.reason
    assert "in File" in segfault.reason  # where, from the faulthandler's stack
    exits = found[EXITS]
    assert isinstance(exits, BrokenEngine) and "exited with code 3" in exits.reason
    missing = found[MISSING]
    assert isinstance(missing, BrokenEngine) and "does not import here: ModuleNotFoundError" in missing.reason


@pytest.mark.slow
def test_a_hang_while_describing_is_a_broken_engine_within_the_limit(hostile_run):
    hung = hostile_run[3][HANGS]
    assert isinstance(hung, BrokenEngine) and f"took more than {SHORT_PROBE_SECONDS:g} s" in hung.reason


@pytest.mark.slow
def test_a_run_goes_on_when_an_engine_crashes_as_it_is_built(hostile_run):
    """Before, the segfault in the constructor killed `simparity run` itself; now its cases fail, core's complete."""
    code, _, table, _ = hostile_run
    assert code == 1
    for spec, cause in ((SEGFAULT, "SIGSEGV"), (EXITS, "exited with code 3")):
        rows = table[table.engine == spec]
        assert len(rows) and set(rows.status) == {"failed"} and rows.detail.str.contains(cause).all(), spec
    core = table[(table.engine == "core") & (table.metric == "position_error_max")]
    assert len(core) >= 2 and set(core.status) == {"ok"}


@pytest.mark.slow
def test_an_engine_that_hung_while_described_is_not_built_again_by_the_cases(hostile_run):
    """Its cases fail at once with the probe's cause, instead of each hanging to the 900 s case limit."""
    code, seconds, table, _ = hostile_run
    assert code == 1
    assert seconds < RUN_SECONDS
    rows = table[table.engine == HANGS]
    assert len(rows) and set(rows.status) == {"failed"}
    assert rows.detail.str.contains(f"took more than {SHORT_PROBE_SECONDS:g} s", regex=False).all()


@pytest.mark.slow
def test_a_scene_file_and_the_quick_profile_may_name_a_spec_engines_own_integrators(tmp_path, monkeypatch):
    """Before, `own_rk4` was refused as no engine's integrator: only built-ins' and installed plugins' names were
    known when the scene file was checked. Each run probes the engine once, though it asks it twice (what it
    offers, for the scene file; the run's scenes): before, a probe per question."""
    scene = tmp_path / "throw.toml"
    scene.write_text(THROWN_BALL.replace('integrators = ["rk4"]', 'integrators = ["own_rk4"]'), encoding="utf-8")
    probes = spy_probes(monkeypatch).started
    for quick in ([], ["--quick"]):
        out = tmp_path / f"run{len(quick)}"
        probes.clear()
        assert _run(scene, f"core,{OWN_SPEC}", out, *quick) == 0
        assert probes == {OWN_SPEC: 1}
        table = pd.read_csv(out / "results.csv", keep_default_na=False)
        own = table[(table.engine == "own") & (table.metric == "position_error_max")]
        assert list(own.integrator) == ["own_rk4", "own_rk4"] and set(own.status) == {"ok"}
        assert (table[table.engine == "core"].status == "n/a").all()  # core offers no own_rk4


def test_a_run_without_transforms_ends_its_probes_before_its_cases(tmp_path, monkeypatch):
    """A kept probe holds its engine's imports; a run with no transformed scenes to ask about keeps none while its
    cases run."""
    spy = spy_probes(monkeypatch)
    engines = EngineSet(("core", OWN_SPEC))
    scene = tmp_path / "throw.toml"
    scene.write_text(THROWN_BALL, encoding="utf-8")
    scenes = load([str(scene)], engines=engines)
    Session(scenes, engines, profile="quick", execution=Execution(ISOLATED, 1, CaseLimits(60.0, None)))
    assert spy.started == {OWN_SPEC: 1}
    assert all(process.poll() is not None for process in spy.processes)


def test_a_described_engine_runs_nothing(described_core):
    described = described_core[1]
    assert described.stages("rk4") == 4 and described.stages("explicit_euler") == 1  # what it declared, as data
    with pytest.raises(Exception, match="described, not built"):
        described.build_dynamics(builtin("lecture-projectile"), "rk4", 0.01)
