"""Issue #39, options and output destinations: every option is input. A comma list that names nothing, an empty
or repeated name; a baseline that is no run folder; a number that means nothing; a memory limit no case can live
in; an engine spec that names no engine; a destination that cannot be written: one line, exit 2, before any case
runs, and a write that fails after the work says where its results are kept."""

from __future__ import annotations

import hashlib
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from simparity.comparisons.cli.main import EXIT_USAGE, main
from simparity.comparisons.engines.placeholders import BrokenEngine, NotAnEngine
from simparity.comparisons.engines.plugins import load_engine
from simparity.comparisons.execute.isolation import GIB, MIN_CASE_MEMORY_BYTES
from simparity.comparisons.pipeline.run_info import describe_run
from simparity.reports.store import RunWriter
from simparity.comparisons.engines.registry import make_engine
from simparity.comparisons.invariance.transforms import TRANSFORM_NAMES
from simparity.core.model.results import OK, ResultRow
from tests.helpers import builtin
from tests.comparisons.engines.test_plugins import site  # noqa: F401 - the fixture: fake installed plugins

SCENE = "lecture-projectile"


def _refused(capsys, argv: list[str]) -> str:
    """The one line ``argv`` is refused with (exit 2, no traceback)."""
    assert main(argv) == EXIT_USAGE, argv
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("simparity: error: ") and "Traceback" not in err, err
    return err


@pytest.fixture
def stored_run(tmp_path):
    """A run folder as 'simparity run' writes it, of a few rows of core on the projectile (no engine runs)."""
    folder = tmp_path / "stored"
    writer = RunWriter(folder, describe_run([make_engine("core")], "simparity run", [builtin(SCENE)], profile="quick"))
    writer.append([ResultRow(SCENE, "core", "rk4", dt, "position_error_max", 1e-12, "m", "analytic:exact", OK,
                             scheme="rk4") for dt in (0.1, 0.05)])
    writer.finish()
    return folder


def _digest(folder) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir()) if p.is_file()}


# --- Comma lists ----------------------------------------------------------------------------------------------------

LIST_OPTIONS = [
    (["run", SCENE, "--transform"], "translate"),
    (["run", SCENE, "--engines"], "core"),
    (["run", SCENE, "--check", "--check-engines"], "core"),
    (["run", SCENE, "--check", "--require-engines"], "core"),
    (["check", "RUN", "--check-engines"], "core"),
    (["check", "RUN", "--require-engines"], "core"),
]


@pytest.mark.parametrize("prefix, name", LIST_OPTIONS)
@pytest.mark.parametrize("value, words", [
    ("", "names nothing"), (",", "names nothing"), (" , ", "names nothing"), ("{n},", "an empty name"),
    (",{n}", "an empty name"), ("{n},,{n}", "an empty name"), ("{n},{n}", "named twice"), ("{n}, {n}", "named twice"),
])
def test_a_comma_list_naming_nothing_an_empty_or_a_repeated_name_is_refused(capsys, tmp_path, prefix, name, value,
                                                                             words):
    """Never read as fewer names (before #39 '' ran no transform, 'core,' ran core, ',' held every engine)."""
    argv = [tmp_path / "run" if a == "RUN" else a for a in prefix] + [value.format(n=name), "--out",
                                                                       str(tmp_path / "o")]
    if prefix[0] == "check":
        argv = argv[:-2]
    err = _refused(capsys, [str(a) for a in argv])
    assert f"argument {prefix[-1]}: " in err and words in err and "allowed: " in err
    assert not (tmp_path / "o").exists()


def test_an_unknown_transform_names_every_allowed_one(capsys, tmp_path):
    err = _refused(capsys, ["run", SCENE, "--transform", "translate,spin", "--out", str(tmp_path / "o")])
    assert "spin: no such transform" in err and all(name in err for name in TRANSFORM_NAMES)


@pytest.mark.parametrize("argv", [
    ["history", "--engine", ""], ["history", ""], ["check", "RUN", "--explain", ""],
    ["check", "RUN", "--explain", "core", "--scene", " "], ["export", SCENE, "--engine", "mujoco", "--integrator", ""],
    ["run", SCENE, "--executor", "dask", "--scheduler", ""],
])
def test_an_empty_name_is_not_read_as_no_option(capsys, tmp_path, argv):
    """'' was read as the option not given: 'history --engine ""' matched every engine."""
    err = _refused(capsys, [str(tmp_path) if a == "RUN" else a for a in argv])
    assert "names nothing" in err


@pytest.mark.parametrize("argv", [
    ["run", SCENE, "--out", ""], ["run", SCENE, "--resume", ""], ["check", ""], ["check", "RUN", "--junit", ""],
    ["check", "RUN", "--summary", ""], ["check", "RUN", "--bless", ""], ["check", "RUN", "--tolerances", ""],
    ["report", ""], ["bench", "--out", ""], ["history", "--history", ""],
])
def test_an_empty_path_is_not_the_current_folder(capsys, tmp_path, argv):
    """'run --out ""' wrote its run into the current folder."""
    err = _refused(capsys, [str(tmp_path) if a == "RUN" else a for a in argv])
    assert "is no path" in err


# --- --baseline, --baseline-rel ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("baseline, words", [
    ("/etc", "results.csv: missing"), ("/proc", "results.csv: missing"), ("FILE", "a file, not a folder"),
    ("EMPTY", "results.csv: missing"), ("MISSING", "no such folder"), ("", "no folder named"),
    ("/dev/null", "a file, not a folder"),
])
def test_a_baseline_that_is_no_run_folder_is_one_line(capsys, stored_run, tmp_path, baseline, words):
    (tmp_path / "empty").mkdir()
    given = {"FILE": str(stored_run / "run.json"), "EMPTY": str(tmp_path / "empty"),
             "MISSING": str(tmp_path / "missing")}.get(baseline, baseline)
    err = _refused(capsys, ["check", str(stored_run), "--baseline", given])
    assert f"--baseline {given}" in err or "--baseline ''" in err
    assert words in err


def test_a_baseline_that_is_no_run_is_refused_before_the_run(capsys, tmp_path):
    err = _refused(capsys, ["run", SCENE, "--check", "--baseline", str(tmp_path), "--out", str(tmp_path / "o")])
    assert "--baseline" in err and not (tmp_path / "o").exists()


@pytest.mark.parametrize("value", ["nan", "-1", "inf", "-inf", "-1e-300"])
def test_a_baseline_rel_that_is_no_relative_change_is_refused(capsys, stored_run, value):
    err = _refused(capsys, ["check", str(stored_run), "--baseline", str(stored_run), f"--baseline-rel={value}"])
    assert "--baseline-rel" in err and "allowed: a finite relative change >= 0" in err


def test_a_baseline_rel_of_zero_flags_any_change_and_is_taken(capsys, stored_run):
    assert main(["check", str(stored_run), "--baseline", str(stored_run), "--baseline-rel", "0"]) != EXIT_USAGE
    assert "moved" in capsys.readouterr().out  # the verdict: 0 moved (the run against itself)


def test_a_baseline_rel_without_a_baseline_is_refused(capsys, stored_run):
    err = _refused(capsys, ["check", str(stored_run), "--baseline-rel", "1e-3"])
    assert "without --baseline" in err


@pytest.mark.parametrize("option", [["--junit", "j.xml"], ["--summary", "s.md"], ["--baseline", "latest"],
                                    ["--baseline-rel", "1"], ["--verbose"], ["--allow-unbounded"],
                                    ["--tolerances", "t.toml"]])
def test_the_check_s_options_on_a_run_without_check_are_refused(capsys, tmp_path, option):
    """They were read and did nothing: a CI job writing no JUnit file, holding nothing to the baseline."""
    err = _refused(capsys, ["run", SCENE, *option, "--out", str(tmp_path / "o")])
    assert f"{option[0]} without --check" in err and not (tmp_path / "o").exists()


@pytest.mark.parametrize("option", [["--junit", "j.xml"], ["--baseline", "latest"], ["--verbose"]])
def test_the_check_s_options_with_bless_or_explain_are_refused(capsys, stored_run, tmp_path, option):
    for mode in (["--bless", str(tmp_path / "b.toml")], ["--explain", "core"]):
        err = _refused(capsys, ["check", str(stored_run), *mode, *option])
        assert f"{option[0]} with {mode[0]}" in err
    assert not (tmp_path / "b.toml").exists()


# --- Numbers --------------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("option, value", [
    ("--case-timeout", "nan"), ("--case-timeout", "inf"), ("--case-timeout", "0"), ("--case-timeout", "-5"),
    ("--case-memory", "nan"), ("--case-memory", "inf"), ("--case-memory", "0"), ("--case-memory", "-1"),
    ("--case-memory", "1e7"), ("--repeats", "-1"), ("--repeats", "101"), ("--repeats", "nan"), ("--jobs", "0"),
    ("--jobs", "-2"), ("--jobs", "100000"), ("--max-steps", "0"), ("--max-samples", "-1"), ("--max-joints", "0"),
    ("--max-steps", "1.5"),
])
def test_a_run_number_that_means_nothing_is_refused_before_the_run(capsys, tmp_path, option, value):
    err = _refused(capsys, ["run", SCENE, option, value, "--out", str(tmp_path / "o")])
    assert option in err and "allowed" in err and not (tmp_path / "o").exists()


@pytest.mark.parametrize("dt", ["nan", "inf", "0", "-0.01", "1e-300"])
def test_an_export_time_step_that_is_none_is_refused(capsys, dt):
    assert "--dt" in _refused(capsys, ["export", SCENE, "--engine", "mujoco", "--dt", dt])


def test_a_case_memory_every_case_would_die_in_is_refused_before_any_case_runs(capsys, tmp_path):
    """Before #39, --case-memory 0.001 ran every case into the limit and reported them failed, exit 1."""
    floor = MIN_CASE_MEMORY_BYTES / GIB
    for value in ("0.001", repr(floor * 0.99)):
        err = _refused(capsys, ["run", SCENE, "--case-memory", value, "--out", str(tmp_path / "o")])
        assert "--case-memory" in err and f"{floor:.3g}" in err and not (tmp_path / "o").exists()
    # at the floor the option is taken: the run goes on to the next mistake, its unknown scene
    err = _refused(capsys, ["run", "no-such-scene", "--case-memory", repr(floor), "--out", str(tmp_path / "o")])
    assert "no-such-scene" in err


# --- --engines naming no engine ---------------------------------------------------------------------------------------

MODULE = textwrap.dedent('''
    from simparity.core.inhouse import InHouseEngine

    class NotAnEngineAtAll:
        def integrators(self):
            return ("rk4",)

    class NeedsArguments(InHouseEngine):
        def __init__(self, config):
            super().__init__()

    class RaisingConstructor(InHouseEngine):
        def __init__(self):
            raise ValueError("boom")

    def make_a_number():
        return 3

    VALUE = 3
''')


@pytest.fixture
def user_module(tmp_path, monkeypatch):
    (tmp_path / "cli_options_engines.py").write_text(MODULE, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    yield "cli_options_engines"
    sys.modules.pop("cli_options_engines", None)


@pytest.mark.parametrize("attr, words", [
    ("NotAnEngineAtAll", "is the class NotAnEngineAtAll, not a simparity.core.engine.Engine subclass"),
    ("NeedsArguments", "cannot be called without arguments"), ("make_a_number", "returned a value of type int"),
    ("VALUE", "is a value of type int"), ("Nowhere", "has no attribute Nowhere"),
])
def test_a_spec_naming_no_engine_is_not_an_engine(user_module, attr, words):
    engine = load_engine(f"{user_module}:{attr}")
    assert isinstance(engine, NotAnEngine) and words in engine.mistake
    assert "allowed: an Engine subclass" in engine.mistake


def test_an_engine_whose_own_code_raises_stays_a_broken_engine_that_runs(user_module):
    """The engine's bug is a finding of the run (failed rows), not a mistake in the command."""
    engine = load_engine(f"{user_module}:RaisingConstructor")
    assert isinstance(engine, BrokenEngine) and not isinstance(engine, NotAnEngine) and "boom" in engine.reason


@pytest.mark.slow  # a process of its own describes the engine, or runs the command
@pytest.mark.parametrize("spec, words", [
    ("os:path", "os:path is a value of type module"), ("json:dumps", "json:dumps cannot be called without arguments"),
    ("json:JSONDecoder", "not a simparity.core.engine.Engine subclass"), ("json:nothere", "has no attribute nothere"),
    ("os:getcwd", "returned a value of type str"),
])
def test_engines_naming_no_engine_are_refused_before_the_run(capsys, tmp_path, spec, words):
    """Before #39 each ran, every case failed, exit 1."""
    err = _refused(capsys, ["run", SCENE, "--engines", f"core,{spec}", "--out", str(tmp_path / "o")])
    assert err.startswith("simparity: error: --engines: ") and words in err and not (tmp_path / "o").exists()


# --- Destinations ---------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("option, target, words", [
    ("--junit", "DIR", "is a folder"), ("--junit", "MISSING/j.xml", "No such file or directory"),
    ("--junit", "/proc/j.xml", "cannot write"), ("--junit", "FILE/j.xml", "Not a directory"),
    ("--summary", "DIR", "is a folder"), ("--summary", "/proc/s.md", "cannot write"),
    ("--bless", "DIR", "is a folder"), ("--bless", "MISSING/b.toml", "No such file or directory"),
    ("--bless", "/dev/full", "No space left on device"),
])
def test_a_check_destination_that_cannot_be_written_is_one_line(capsys, stored_run, tmp_path, option, target, words):
    before = _digest(stored_run)
    given = target.replace("DIR", str(tmp_path)).replace("MISSING", str(tmp_path / "missing")).replace(
        "FILE", str(stored_run / "run.json"))
    err = _refused(capsys, ["check", str(stored_run), option, given])
    assert f"{given}" in err and words in err and _digest(stored_run) == before
    assert not (tmp_path / "missing").exists()


def test_a_full_device_after_the_verdict_keeps_the_verdict_and_the_run(capsys, stored_run):
    """--summary /dev/full opens (the probe cannot tell), the write fails: one line, the verdict printed before it,
    the run untouched."""
    before = _digest(stored_run)
    assert main(["check", str(stored_run), "--summary", "/dev/full"]) == EXIT_USAGE
    captured = capsys.readouterr()
    assert captured.out.splitlines()[-1].startswith("check ")
    assert captured.err.count("\n") == 1 and "--summary /dev/full: cannot write: No space left on device" in captured.err
    assert _digest(stored_run) == before


def test_a_junit_file_the_probe_did_not_make_is_not_left_behind(capsys, stored_run, tmp_path):
    """The probe opens without writing and removes what it created: a refused check leaves no empty JUnit file."""
    junit = tmp_path / "j.xml"
    _refused(capsys, ["check", str(stored_run), "--junit", str(junit), "--baseline", str(tmp_path / "missing")])
    assert not junit.exists()


@pytest.mark.parametrize("target, words", [
    ("FILE", "exists and is not a folder"), ("/proc", "cannot write in that folder"),
    ("/proc/x", "cannot write in that folder"), ("FILE/x", "exists and is not a folder"),
])
def test_a_run_or_bench_folder_that_cannot_be_written_is_refused_before_the_work(capsys, stored_run, target, words):
    given = target.replace("FILE", str(stored_run / "run.json"))
    for command in (["run", SCENE, "--engines", "core"], ["bench"]):
        err = _refused(capsys, [*command, "--out", given])
        assert f"--out {given}" in err and (words in err or "Not a directory" in err)


def test_a_junit_file_of_a_run_that_cannot_be_written_is_refused_before_the_run(capsys, tmp_path):
    err = _refused(capsys, ["run", SCENE, "--check", "--junit", str(tmp_path / "missing" / "j.xml"), "--out",
                            str(tmp_path / "o")])
    assert "--junit" in err and not (tmp_path / "o").exists()


@pytest.mark.slow  # a process of its own describes the engine, or runs the command
def test_the_console_script_exits_2_on_a_full_device_without_a_traceback(stored_run):
    """As CI calls it: a process, its exit code and its standard error."""
    done = subprocess.run([sys.executable, "-m", "simparity.comparisons.cli", "check", str(stored_run), "--summary",
                           "/dev/full"], capture_output=True, text=True, timeout=120)
    assert done.returncode == EXIT_USAGE and done.stderr.count("\n") == 1 and "Traceback" not in done.stderr
    assert "No space left on device" in done.stderr


@pytest.mark.slow
def test_a_run_whose_summary_cannot_be_written_keeps_the_run_and_names_it(capsys, tmp_path):
    """The write after the run fails (a full device): the run's folder is complete and the message points at it."""
    out = tmp_path / "run"
    # the arm's configurations, not the projectile's integrators and time steps: what is tested is the write after
    # the run, whatever it ran (~3 s of CPU less)
    code = main(["run", "lecture-planar-arm", "--quick", "--engines", "core", "--jobs", "1", "--out", str(out),
                 "--check", "--summary", "/dev/full"])
    captured = capsys.readouterr()
    assert code == EXIT_USAGE and captured.err.count("\n") == 1 and "--summary /dev/full" in captured.err
    assert f"the run's results are kept in {out} ('simparity check {out}' checks them again)" in captured.err
    assert (out / "results.csv").is_file() and (out / "report.md").is_file()
    assert main(["check", str(out)]) != EXIT_USAGE  # the kept run checks


# --- A fuzz pass over the options -------------------------------------------------------------------------------

FUZZ_SEED = 39
"""The seed of the option fuzz's generated comma lists (one seeded generator, passed explicitly)."""

LIST_TOKENS = ("core", "mujoco", "", " ", "core", "translate", "rotate", "\t", "é", "x" * 80, "a:b", "-", "*")
NUMBERS = {  # value: meaningless for the option (refused naming it) or not
    "--case-timeout": {"nan": True, "inf": True, "-inf": True, "0": True, "-1": True, "1e309": True, "0x10": True,
                       "": True, "1e-320": True, "0.5": True, "1e8": True, "1": False, "5": False},
    "--case-memory": {"nan": True, "inf": True, "0": True, "-0": True, "0.1": True, "1e6": False, "1e7": True,
                      "1": False, "١": False},  # an Arabic-Indic one is a number to Python: taken, as 1
    "--repeats": {"-1": True, "101": True, "1.0": True, "nan": True, "0": False, "3": False, "1_0": False},
    "--jobs": {"0": True, "-1": True, "257": True, "2.5": True, "1": False},
    "--max-steps": {"0": True, "-3": True, "1e3": True, "1": False, str(10 ** 30): False},
    "--max-samples": {"0": True, "-1": True, "": True, "7": False},
    "--max-joints": {"0": True, "nan": True, "2": False},
}
RUN_PATHS = ["", "/proc", "/proc/x/y", "/dev/null", "/dev/full", "/dev/null/x", "FILE", "FILE/x", "x" * 5000,
             "a\0b", "/sys/x"]
CHECK_PATHS = ["", "/", "/proc/x", "/dev/null/x", "DIR", "MISSING/x", "FILE/x", "x" * 5000, "a\0b", "/dev/full"]


def _lists(rng) -> list[str]:
    """Comma lists of 1 to 4 tokens, drawn with ``rng``: empty, blank, repeated, unknown, long names."""
    return [",".join(rng.choice(LIST_TOKENS, size=rng.integers(1, 5))) for _ in range(64)]


def _fuzz_inputs(rng, stored, tmp_path) -> list[tuple[list[str], str | None]]:
    """(argv, the option its refusal must name, or None when the value is allowed)."""
    inputs: list[tuple[list[str], str | None]] = []
    for text in _lists(rng):
        names = [n.strip() for n in text.split(",")]
        hostile = "" in names or len(set(names)) < len(names)
        inputs.append((["run", "no-such-scene", "--engines", text], "--engines" if hostile else None))
        transform_hostile = hostile or not set(names) <= {"translate", "rotate"}
        inputs.append((["run", "no-such-scene", "--transform", text], "--transform" if transform_hostile else None))
        inputs.append((["check", str(stored), "--require-engines", text], "--require-engines" if hostile else None))
    for option, values in NUMBERS.items():
        for value, hostile in values.items():
            inputs.append((["run", "no-such-scene", f"{option}={value}"], option if hostile else None))
    for value in ["nan", "-1", "inf", "-inf", "", "1e309", "0", "1e-3"]:
        hostile = value not in ("0", "1e-3")
        inputs.append((["check", str(stored), "--baseline", str(stored), f"--baseline-rel={value}"],
                       "--baseline-rel" if hostile else None))
    places = {"FILE": str(stored / "run.json"), "DIR": str(tmp_path), "MISSING": str(tmp_path / "missing")}

    def place(path: str) -> str:
        return next((path.replace(k, v) for k, v in places.items() if path.startswith(k)), path)

    for path in RUN_PATHS:
        inputs.append((["run", SCENE, "--engines", "core", "--out", place(path)], "--out"))
        inputs.append((["bench", "--out", place(path)], "--out"))
    for path in CHECK_PATHS:
        for option in ("--junit", "--summary", "--bless", "--baseline"):
            inputs.append((["check", str(stored), option, place(path)], option))
    return inputs


@pytest.mark.sweep
@pytest.mark.slow
def test_a_fuzz_pass_over_the_options_ends_without_a_traceback_or_a_silent_pass(capsys, stored_run, tmp_path):
    """Some 300 generated inputs: each hostile one is one line naming its option, exit 2, and nothing is written
    (the stored run unchanged, no folder made); an allowed one goes on to the next mistake or the check."""
    before = _digest(stored_run)
    inputs = _fuzz_inputs(np.random.default_rng(FUZZ_SEED), stored_run, tmp_path)
    assert len(inputs) >= 300
    for argv, option in inputs:
        code = main(argv)
        captured = capsys.readouterr()
        assert "Traceback" not in captured.err, argv
        if option is not None:
            assert code == EXIT_USAGE and captured.err.count("\n") == 1, (argv, captured.err)
            assert option in captured.err, (argv, captured.err)
        else:
            assert code in (0, 1, EXIT_USAGE) and captured.err.count("\n") <= 1, (argv, captured.err)
    assert _digest(stored_run) == before and not (tmp_path / "missing").exists()


@pytest.mark.slow  # a process of its own describes the engine, or runs the command
def test_an_installed_plugin_naming_no_engine_is_refused_before_the_run(site, capsys, tmp_path):
    """An entry point is a module:attr too: one naming a function of the standard library is refused like a spec."""
    site.install({"notanengine": "json:dumps"})
    err = _refused(capsys, ["run", SCENE, "--engines", "core,notanengine", "--out", str(tmp_path / "o")])
    assert "--engines: json:dumps cannot be called without arguments" in err and not (tmp_path / "o").exists()
