"""Issue #12: plugin engines. An installed package's entry point in ``simparity.engines`` (or a ``module:Class``
spec) runs beside core in every scene, is listed by ``simparity engines`` and held to the CI gate; a plugin that
cannot import gives n/a rows with the reason, one that raises gives failed rows, and nothing breaks the run."""

from __future__ import annotations

import re
import importlib.util
import io
import json
import shutil
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pandas as pd
import pytest

from simparity import load_scene, run_scene
from simparity.comparisons.engines import plugins
from simparity.comparisons.engines.placeholders import BrokenEngine
from simparity.comparisons.cli.main import EXIT_FAILED_CASES, EXIT_OK, EXIT_USAGE, main
from simparity.comparisons.engines.registry import (ENGINE_NAMES, check_engine_names, EngineSet,
                                           make_engine)
from simparity.core.model.errors import UnknownEngineError
from simparity.core.inhouse import InHouseEngine
from simparity.core.model.results import FAILED, NOT_AVAILABLE, OK
from tests.comparisons.engines.probe_spy import spy_probes
from tests.helpers import THROWN_INTO_WIND

ROOT = Path(__file__).resolve().parents[3]
EXAMPLE = ROOT / "examples" / "plugin-engine"
EXAMPLE_VERSION = "0.1.0"
"""What examples/plugin-engine declares (its ``__version__``, which its pyproject.toml reads)."""

INSTALL_SECONDS = 120
"""pip may first fetch setuptools from the package index for an isolated build (about 3 s when cached)."""

NO_REPORT_ONE_JOB = ("--no-report", "--jobs", "1")
"""For a run whose report no test reads and whose parallelism none tests: a report costs ~5 CPU-s, a second
worker ~1 s."""

EULER_ORDER_BAND = 0.1
"""Explicit Euler's global error is C dt (1 + O(dt)): on this smooth scene, over dt 0.01-0.04 s against a
time scale of 2 s (m / b), the fitted slope is within a few hundredths of 1; 0.1 still tells it from 2."""
RK4_ORDER_BAND = 0.5
"""The shipped tolerances' band for rk4* (half the gap to the next integer order)."""

SCENE = THROWN_INTO_WIND

ENGINES_SOURCE = '''
from simparity.core.inhouse import InHouseEngine


class Exploding(InHouseEngine):
    def __init__(self):
        raise ValueError("boom in the constructor")


class NoVersion(InHouseEngine):
    def version(self):
        raise RuntimeError("no version here")


class ListedIntegrators(InHouseEngine):
    def integrators(self):
        return ["rk4"]


class RaisingOrder(InHouseEngine):
    def integrators(self):
        return ("rk4",)

    def theoretical_order(self, integrator):
        raise KeyError(integrator)


class NegativeStages(InHouseEngine):
    def stages(self, integrator):
        return -1


class ZeroStages(InHouseEngine):
    """A step that evaluates no force is no step: 0 would make every scheme free and win every work budget."""

    def stages(self, integrator):
        return 0


class FloatStages(InHouseEngine):
    def stages(self, integrator):
        return 4.0


class NotAnEngine:
    pass


class CrashingBuild(InHouseEngine):
    name = "crashing"

    def build_dynamics(self, scene, integrator, dt):
        raise ZeroDivisionError("build failed")


class Renamed(InHouseEngine):
    name = "mine"


def factory():
    return Renamed()


class Leapfrog(InHouseEngine):
    def integrators(self):
        return super().integrators() + ("leapfrog_demo",)
'''
"""Engines a user could write, each wrong in one way (or right: Renamed, factory), for specs and entry points."""


class _Site:
    """A folder on the import path holding fake installed plugins: a dist-info with an entry_points.txt."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.modules: list[str] = []

    def install(self, entries: dict[str, str], module: str = "") -> None:
        """Register ``entries`` (name: module:attr) as the distribution fake-plugins 1.0; ``module``: the name of a
        module holding :data:`ENGINES_SOURCE`."""
        dist = self.folder / "fake_plugins-1.0.dist-info"
        dist.mkdir()
        (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: fake-plugins\nVersion: 1.0\n", encoding="utf-8")
        (dist / "entry_points.txt").write_text(
            "[simparity.engines]\n" + "".join(f"{name} = {value}\n" for name, value in entries.items()), encoding="utf-8")
        if module:
            self.add_module(module)

    def add_module(self, module: str) -> None:
        (self.folder / f"{module}.py").write_text(ENGINES_SOURCE, encoding="utf-8")
        self.modules.append(module)


def _forget_plugins() -> None:
    plugins.discover.cache_clear()


@pytest.fixture
def site(tmp_path, monkeypatch):
    folder = tmp_path / "site"
    folder.mkdir()
    monkeypatch.syspath_prepend(str(folder))
    _forget_plugins()
    made = _Site(folder)
    yield made
    _forget_plugins()
    for module in made.modules:
        sys.modules.pop(module, None)


def _scene(folder: Path) -> Path:
    """SCENE written to a file in ``folder``."""
    path = folder / "toss.toml"
    path.write_text(SCENE, encoding="utf-8")
    return path


@pytest.fixture
def scene_file(tmp_path) -> Path:
    return _scene(tmp_path)


def _rows(table: pd.DataFrame, engine: str) -> pd.DataFrame:
    return table[table.engine == engine]


def _results(out: Path) -> pd.DataFrame:
    """A run's results.csv, "n/a" kept as a status (only an empty dt or value is missing)."""
    return pd.read_csv(out / "results.csv", keep_default_na=False, na_values={"dt": ["", "nan"], "value": ["", "nan"]})


def _run(scene, engines: list[str]) -> pd.DataFrame:
    """``run_scene`` of a scene file or a built-in's name, isolated as ``simparity run`` runs, in one worker (a
    second worker costs a process start and no test here is about parallelism)."""
    return run_scene(str(scene), engines=engines, repeats=0, jobs=1)


# --- The installed example: listed, run beside core, failed by the gate ------------------------------------------

def _builds_without_isolation() -> bool:
    """True when this environment can build the example offline: setuptools >= 70.1 builds wheels itself, an
    older one (>= 61, the example's floor) with the wheel package."""
    try:
        version = tuple(int(part) for part in metadata.version("setuptools").split(".")[:2])
    except (metadata.PackageNotFoundError, ValueError):
        return False
    return version >= (70, 1) or (version >= (61, 0) and importlib.util.find_spec("wheel") is not None)


def _install_example(tmp_path: Path) -> Path:
    """pip-install a copy of examples/plugin-engine (the build writes into its source folder) into a target
    folder; offline when the environment can build it, else pip fetches setuptools for an isolated build."""
    source = shutil.copytree(EXAMPLE, tmp_path / "plugin-engine", ignore=shutil.ignore_patterns("build", "*.egg-info"))
    target = tmp_path / "target"
    offline = ["--no-build-isolation", "--no-index"] if _builds_without_isolation() else []
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--disable-pip-version-check",
                    "--target", str(target), *offline, str(source)], check=True, timeout=INSTALL_SECONDS,
                   capture_output=True)
    return target


def _simparity(args: list[str]) -> tuple[int, str]:
    """``simparity ARGS`` in this process (its probes and workers are processes of their own, with this import
    path): the exit code and what it printed. In a process of its own it cost a start and the imports again."""
    out = io.StringIO()
    return main(args, out=out), out.getvalue()


@pytest.mark.slow
def test_the_installed_example_is_listed_runs_beside_core_and_fails_the_gate_on_its_order(tmp_path, scene_file,
                                                                                         monkeypatch):
    target = _install_example(tmp_path)
    monkeypatch.syspath_prepend(str(target))  # installed there: on the import path, as PYTHONPATH puts it
    monkeypatch.chdir(tmp_path)
    _forget_plugins()
    try:
        _the_example_is_listed_runs_and_fails(tmp_path, scene_file)
    finally:
        _forget_plugins()
        for module in [name for name in sys.modules if name.startswith("simparity_example_engine")]:
            del sys.modules[module]


def _the_example_is_listed_runs_and_fails(tmp_path: Path, scene_file: Path) -> None:
    code, listing = _simparity(["engines"])
    assert code == EXIT_OK, listing
    [line] = [line for line in listing.splitlines() if line.startswith("example ")]
    assert f"from simparity-example-engine {EXAMPLE_VERSION}" in line and f"version {EXAMPLE_VERSION}" in line
    assert "dynamics: rk4" in line and "kinematics: no" in line

    out = tmp_path / "run"
    code, printed = _simparity(["run", str(scene_file), "--engines", "core,example", "--check", "--out", str(out),
                                "--repeats", "0", "--jobs", "1"])
    assert code == EXIT_FAILED_CASES, printed
    violations = [line for line in printed.splitlines() if line.startswith("violation: ")]
    assert violations and all(re.match(r"violation: toss example rk4[ :]", line) for line in violations), printed
    assert any("order_position" in line and "bound >= 3.5" in line for line in violations)

    table = _results(out)
    order = table[(table.metric == "order_position") & (table.integrator == "rk4")].set_index("engine")
    assert abs(order.loc["example", "value"] - 1.0) <= EULER_ORDER_BAND  # explicit Euler, whatever it claims
    assert abs(order.loc["core", "value"] - 4.0) <= RK4_ORDER_BAND
    assert set(_rows(table, "example").status) <= {OK, NOT_AVAILABLE}  # it ran: the gate fails it on numbers
    info = json.loads((out / "run.json").read_text(encoding="utf-8"))
    assert info["engine_versions"]["example"] == EXAMPLE_VERSION and info["theoretical_orders"]["example"] == {"rk4": 4}
    assert "example" in (out / "report.md").read_text(encoding="utf-8")


# --- Plugins that cannot run ----------------------------------------------------------------------------------------

MISTYPED_SPEC = "no_such_module_for_simparity_tests:X"
"""A spec whose module does not exist (a typing error)."""


@pytest.fixture(scope="module")
def unrunnable_run(tmp_path_factory):
    """One ``simparity run --check`` shared by the tests of engines that cannot run, the installed plugins ghost
    (does not import) and exploding (raises in its constructor) and MISTYPED_SPEC, beside core on SCENE and on a
    kinematics scene (the planar arm), in a worker process as 'simparity run' runs: its exit code, results and
    what it printed. The plugins are installed for the run only (the other tests install their own)."""
    folder = tmp_path_factory.mktemp("unrunnable")
    (folder / "site").mkdir()
    site = _Site(folder / "site")
    site.install({"ghost": "no_such_module_for_simparity_tests:Engine", "exploding": "plugin_engines_a:Exploding"},
                 "plugin_engines_a")
    with pytest.MonkeyPatch.context() as patch:
        patch.syspath_prepend(str(site.folder))
        _forget_plugins()
        try:
            printed = io.StringIO()
            code = main(["run", str(_scene(folder)), "lecture-planar-arm", "--engines",
                         f"core,ghost,exploding,{MISTYPED_SPEC}", "--repeats", "0", "--out", str(folder / "run"),
                         "--check", *NO_REPORT_ONE_JOB], out=printed)
        finally:
            _forget_plugins()
            sys.modules.pop("plugin_engines_a", None)
    return code, _results(folder / "run"), printed.getvalue()


@pytest.mark.slow
def test_a_plugin_that_fails_to_import_fails_its_rows_with_the_import_error(unrunnable_run):
    """Asked for and never run, it must not pass the gate as n/a: its rows fail, naming the import error."""
    code, both, _ = unrunnable_run
    assert code == EXIT_FAILED_CASES
    dynamics, kinematics = both[both.scene == "toss"], both[both.scene == "lecture-planar-arm"]
    for table in (dynamics, kinematics):
        ghost = _rows(table, "ghost")
        cases = ghost[~ghost.metric.str.startswith("order_")]  # an order over cases that never ran: n/a, "too few"
        assert len(cases) and set(cases.status) == {FAILED}
        assert cases.detail.str.contains("ghost is broken: no_such_module_for_simparity_tests:Engine does not import "
                                         "here: ModuleNotFoundError", regex=False).all()
        assert OK in set(_rows(table, "core").status)


@pytest.mark.slow
def test_a_plugin_whose_constructor_raises_fails_its_rows_and_the_run_goes_on(unrunnable_run):
    """In worker processes, as 'simparity run' runs: exit 1 (an engine failed), every other case measured."""
    code, table, _ = unrunnable_run
    assert code == EXIT_FAILED_CASES
    exploding = _rows(table, "exploding")
    assert len(exploding) and set(exploding.status) == {FAILED}
    assert exploding.detail.str.contains("ValueError: boom in the constructor", regex=False).all()
    core = _rows(table, "core")
    assert set(core[core.metric == "position_error_max"].status) == {OK}


@pytest.mark.slow
def test_a_mistyped_spec_module_fails_the_run_and_the_gate(unrunnable_run):
    code, _, printed = unrunnable_run
    assert code == EXIT_FAILED_CASES
    violations = [line for line in printed.splitlines() if line.startswith("violation: ")]
    # the gate fails the spec itself (ghost and exploding, failing beside it, have their own violations)
    assert "check FAILED" in printed and any(f" {MISTYPED_SPEC} " in line for line in violations), printed


BROKEN_ATTRS = ("NoVersion", "ListedIntegrators", "RaisingOrder", "NotAnEngine", "NoSuchClass")
"""The attributes of ENGINES_SOURCE (or not in it) that break the interface, each in its own way."""


SHARED_MODULE = "plugin_engines_b"
"""The module of ENGINES_SOURCE the shared run's specs name (on the import path while this module's tests run)."""


@pytest.fixture(scope="module")
def shared_table(tmp_path_factory):
    """One run shared by the tests of specs: core beside a spec of each of BROKEN_ATTRS, CrashingBuild and
    Renamed (each is described in a probe of its own and its rows are its own: an engine that fails does not
    touch another's), SHARED_MODULE on the path."""
    folder = tmp_path_factory.mktemp("specs")
    (folder / f"{SHARED_MODULE}.py").write_text(ENGINES_SOURCE, encoding="utf-8")
    with pytest.MonkeyPatch.context() as patch:
        patch.syspath_prepend(str(folder))
        try:
            yield _run(_scene(folder), ["core", *(f"{SHARED_MODULE}:{attr}" for attr in
                                                  (*BROKEN_ATTRS, "CrashingBuild", "Renamed"))])
        finally:
            sys.modules.pop(SHARED_MODULE, None)


@pytest.mark.slow
@pytest.mark.parametrize("attr, reason", [
    ("NoVersion", "version() raised RuntimeError: no version here"),
    ("ListedIntegrators", "integrators() returned ['rk4'] (allowed: a tuple of str)"),
    ("RaisingOrder", "theoretical_order('rk4') raised KeyError: 'rk4'"),
    ("NotAnEngine", "plugin_engines_b:NotAnEngine is the class NotAnEngine, not a simparity.core.engine.Engine "
                    "subclass"),  # told without constructing it (#39)
    ("NoSuchClass", "AttributeError"),
])
def test_an_engine_that_breaks_the_interface_fails_its_rows_with_the_reason(shared_table, attr, reason):
    spec, table = f"{SHARED_MODULE}:{attr}", shared_table
    broken = _rows(table, spec)
    assert len(broken) and set(broken.status) == {FAILED}
    assert broken.detail.str.contains(reason, regex=False).all(), broken.detail.iloc[0]
    assert OK in set(_rows(table, "core").status)


@pytest.mark.parametrize("attr, returned", [("NegativeStages", "-1"), ("ZeroStages", "0"), ("FloatStages", "4.0")])
def test_an_engine_declaring_a_bad_stage_count_is_broken_with_a_one_line_reason(site, attr, returned):
    """stages() is force evaluations per step: a count below 1 or not an integer is refused as it loads, in one line."""
    site.add_module("plugin_engines_b")
    engine = plugins.load_engine(f"plugin_engines_b:{attr}")
    assert isinstance(engine, BrokenEngine)
    first = InHouseEngine().integrators()[0]
    assert engine.reason == (f"plugin_engines_b:{attr} is broken: plugin_engines_b:{attr}: stages({first!r}) "
                             f"returned {returned} (allowed: an int >= 1, force evaluations per step, or None)")


@pytest.mark.slow
def test_an_engine_whose_build_raises_fails_each_case_with_the_error(shared_table):
    table = shared_table  # SHARED_MODULE:CrashingBuild, named "crashing"
    cases = table[(table.engine == "crashing") & table.dt.notna()]
    assert len(cases) and set(cases.status) == {FAILED}
    assert cases.detail.str.startswith("ZeroDivisionError: build failed").all()


# --- Names: specs, shadowing, unknown names --------------------------------------------------------------------------

@pytest.mark.slow
def test_a_module_class_spec_runs_under_the_engine_s_own_name(shared_table):
    spec = f"{SHARED_MODULE}:Renamed"
    assert check_engine_names(["core", spec]) == ("core", spec)
    mine = _rows(shared_table, "mine")  # the shared run's other engines have names of their own
    assert spec not in set(shared_table.engine) and len(mine) and OK in set(mine.status)
    assert make_engine(f"{SHARED_MODULE}:factory").name == "mine"  # a zero-argument callable returning an Engine
    # a built-in's name is taken: the spec names the engine instead
    assert make_engine("simparity.core.inhouse:InHouseEngine").name == "simparity.core.inhouse:InHouseEngine"


def test_a_spec_s_module_is_found_in_the_current_folder(tmp_path, monkeypatch):
    folder = tmp_path / "work"
    folder.mkdir()
    (folder / "plugin_engines_e.py").write_text(ENGINES_SOURCE, encoding="utf-8")
    monkeypatch.chdir(folder)
    monkeypatch.setattr(sys, "path", [p for p in sys.path if p not in ("", ".", str(folder))])
    monkeypatch.delitem(sys.modules, "plugin_engines_e", raising=False)
    engine = make_engine("plugin_engines_e:Renamed")
    sys.modules.pop("plugin_engines_e", None)
    assert engine.name == "mine" and sys.path[-1] == str(folder)


@pytest.mark.slow
def test_a_built_in_name_wins_over_a_plugin_and_simparity_engines_lists_every_state(site):
    site.install({"core": "plugin_engines_f:Renamed", "exploding": "plugin_engines_f:Exploding",
                  "ghost": "no_such_module_for_simparity_tests:Engine", "two,names": "plugin_engines_f:Renamed",
                  "renamed": "plugin_engines_f:Renamed"}, "plugin_engines_f")
    assert type(make_engine("core")) is InHouseEngine
    assert make_engine("renamed").name == "renamed"  # the entry point's name, not the class's
    out = io.StringIO()
    assert main(["engines"], out=out) == EXIT_OK
    listed = out.getvalue().splitlines()
    lines = {line.split()[0]: line for line in listed if "  built-in; " not in line}
    origin = "from fake-plugins 1.0"
    assert [line.split()[0] for line in listed if "  built-in; " in line] == list(ENGINE_NAMES)
    assert "not used: shadowed by the built-in engine core" in lines["core"] and origin in lines["core"]
    assert origin in lines["exploding"] and "failed: " in lines["exploding"] and "boom in the constructor" in lines["exploding"]
    assert origin in lines["ghost"] and "failed: ghost is broken: no_such_module_for_simparity_tests:Engine does not " \
        "import here" in lines["ghost"]
    assert "not used: the name 'two,names' is not an engine name" in lines["two,names"]
    assert "version numpy" in lines["renamed"] and "kinematics: yes" in lines["renamed"]


def test_an_unknown_engine_is_a_one_line_error_naming_the_installed_plugins(site, tmp_path, capsys):
    site.install({"ghost": "no_such_module_for_simparity_tests:Engine"})
    code = main(["run", "lecture-projectile", "--engines", "core,nosuch,bad:", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == EXIT_USAGE and err.count("\n") == 1
    assert "unknown engine(s): nosuch, bad:" in err and "mujoco" in err and "ghost (plugin)" in err
    assert "module:Class" in err


def test_a_failed_search_for_plugins_leaves_the_built_ins_working(monkeypatch):
    def broken_metadata(**kwargs):
        raise OSError("unreadable site-packages")

    monkeypatch.setattr(plugins.metadata, "entry_points", broken_metadata)
    _forget_plugins()
    try:
        with pytest.raises(UnknownEngineError, match="nosuch"):
            check_engine_names(["nosuch"])
        assert type(make_engine("core")) is InHouseEngine and "rk4" in EngineSet().integrators
        out = io.StringIO()
        assert main(["engines"], out=out) == EXIT_OK
        assert out.getvalue().splitlines()[-1].startswith("plugins not searched: ") and "unreadable" in out.getvalue()
    finally:
        _forget_plugins()


@pytest.mark.slow
def test_a_scene_file_may_name_a_plugin_s_integrator(site, tmp_path):
    site.install({"leap": "plugin_engines_g:Leapfrog"}, "plugin_engines_g")
    path = tmp_path / "leap.toml"
    path.write_text(SCENE.replace('integrators = ["rk4"]', 'integrators = ["leapfrog_demo"]'), encoding="utf-8")
    assert load_scene(str(path)).integrators == ("leapfrog_demo",)


@pytest.mark.slow
def test_an_installed_plugin_a_run_does_not_name_is_never_asked(site, scene_file, tmp_path, monkeypatch):
    """Describing a plugin takes a process of its own (a slow one: up to the probe's minute): a run, a scene file
    or the quick profile that does not need it never asks; a run naming it asks it alone, in one probe for the
    scene files and the run."""
    site.install({"leap": "plugin_engines_h:Leapfrog", "other": "plugin_engines_h:Renamed"}, "plugin_engines_h")
    asked = spy_probes(monkeypatch).started
    assert main(["run", str(scene_file), "--quick", "--engines", "core", "--out", str(tmp_path / "a"),
                 *NO_REPORT_ONE_JOB]) == EXIT_OK
    assert main(["list"], out=io.StringIO()) == EXIT_OK
    assert not asked
    leap = tmp_path / "leap.toml"
    leap.write_text(SCENE.replace('integrators = ["rk4"]', 'integrators = ["rk4", "leapfrog_demo"]'), encoding="utf-8")
    code = main(["run", str(leap), "--quick", "--engines", "core,leap", "--out", str(tmp_path / "b"),
                 *NO_REPORT_ONE_JOB])
    assert code != EXIT_USAGE  # the scene file was accepted (the demo integrator's own cases may fail)
    assert asked == {"leap": 1}
