"""The simparity command: list, run, export, report, and clean errors for user mistakes."""

import dataclasses
import io
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from simparity.comparisons.cli.main import EXIT_OK, EXIT_USAGE, main
from simparity.comparisons.engines.registry import DEFAULT_ENGINES
from simparity.comparisons.gate.history import HISTORY_ENV
from simparity.comparisons.scenes.library import builtin_paths
from simparity.comparisons.scenes.profiles import quick
from simparity.core.model.results import COLUMNS, NOT_AVAILABLE, OK, STATUSES
from simparity.reports.store import read_run
from tests.helpers import builtin
from tests.comparisons.scenes.test_loader import BROKEN


def _run(argv):
    out = io.StringIO()
    code = main(argv, out=out)
    return code, out.getvalue()


@pytest.mark.slow  # over 1.5 s of CPU on a 2-core CI-class machine (tests/conftest.py)
def test_list_names_every_builtin_scene():
    """'simparity list' prints one line per built-in scene, starting with its name; a file with a sweep, one line
    per variant in the sweep's order."""
    code, text = _run(["list"])
    lines = text.strip().splitlines()
    assert code == EXIT_OK
    variants = {"restitution-sweep": [f"restitution-sweep_restitution-{k}" for k in ("0.3", "0.5", "0.7", "0.9")]}
    assert [line.split()[0] for line in lines] == [v for name in sorted(builtin_paths()) for v in variants.get(name, [name])]


@pytest.mark.slow
@pytest.mark.parametrize("suite", [None, "default", "hard"])
def test_run_without_scenes_runs_a_whole_builtin_suite(tmp_path, monkeypatch, suite):
    """No scene argument means every built-in scene of the suite (default: "default"), each once, on
    the default engines; a scene file lists its suites."""
    seen = []

    def run_scenes(scenes, engines, *args, **kwargs):
        for scene in scenes:
            seen.append((scene.name, tuple(e.name for e in engines)))
            yield scene, [], []

    monkeypatch.setattr("simparity.comparisons.pipeline.session.run_scenes", run_scenes)
    code, _ = _run(["run", "--out", str(tmp_path), "--jobs", "1", "--no-report"]
                   + (["--suite", suite] if suite else []))
    assert code == EXIT_OK
    wanted = suite or "default"
    in_suite = [name for name, path in builtin_paths().items()
                if re.search(rf'^suites = \[.*"{wanted}"', path.read_text(encoding="utf-8"), re.M)
                or (wanted == "default" and "\nsuites = " not in path.read_text(encoding="utf-8"))]
    assert [name for name, _ in seen] == sorted(in_suite) and len(in_suite) >= 8
    assert all(engines == DEFAULT_ENGINES for _, engines in seen)


def test_scenes_and_a_suite_together_are_refused(tmp_path, capsys):
    assert main(["run", "wind", "--suite", "hard", "--out", str(tmp_path / "o")]) == EXIT_USAGE
    assert "give one" in capsys.readouterr().err


@pytest.mark.slow
def test_lecture_scenes_end_to_end(tmp_path):
    """'simparity run' on the two lecture scenes writes results.csv and report.md with every engine's rows."""
    # --quick keeps the command's whole path (every default engine and time step, timing repeats, results.csv,
    # report.md, run.json); it leaves out only core's orientation variants (+matrix, +expmap: the point never
    # rotates; tests/core/dynamics/test_integrators.py runs them) and half the arm's 200 configurations
    # --jobs 1: one worker process, not one per CPU (what is tested is the output, not the parallelism)
    code, text = _run(["run", "lecture-projectile", "lecture-planar-arm", "--quick", "--out", str(tmp_path),
                       "--repeats", "1", "--jobs", "1"])
    assert code == EXIT_OK, text
    table, _ = read_run(tmp_path)
    assert tuple(table.columns) == COLUMNS
    assert set(table["status"]) <= set(STATUSES)
    for scene in ("lecture-projectile", "lecture-planar-arm"):
        rows = table[table["scene"] == scene]
        assert set(rows["engine"]) == set(DEFAULT_ENGINES), scene
        assert set(rows["status"]) <= {OK, NOT_AVAILABLE}, rows[~rows["status"].isin([OK, NOT_AVAILABLE])]
        assert (rows[rows["status"] == NOT_AVAILABLE]["detail"].str.len() > 0).all()
    report = (tmp_path / "report.md").read_text()
    assert "## lecture-projectile (dynamics)" in report
    kinematics = report.split("## Kinematics", 1)[1]   # kinematics scenes share one section and table
    assert "**lecture-planar-arm**" in kinematics and "| lecture-planar-arm | " in kinematics
    assert (tmp_path / "run.json").is_file()


@pytest.mark.parametrize("name, base, old, new, key, words", BROKEN[:6], ids=[b[0] for b in BROKEN[:6]])
def test_broken_scene_exits_2_with_one_line(tmp_path, capsys, name, base, old, new, key, words):
    """A broken scene file gives exit code 2 and one line naming file and key, no traceback, no results."""
    path = tmp_path / "bad.toml"
    path.write_text(base.replace(old, new, 1))
    code = main(["run", str(path), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == EXIT_USAGE
    assert err.count("\n") == 1 and err.startswith("simparity: error: ")
    assert str(path) in err and key in err and words in err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "argv, words",
    [
        (["run", "no-such-scene"], "'no-such-scene' is not a built-in scene or an existing file"),
        (["run", "lecture-projectile", "--engines", "core,havok"], "unknown engine(s): havok"),
        (["run", "lecture-projectile", "--repeats", "-1"], "--repeats -1"),
        (["run", "lecture-projectile", "--engines", ","], "argument --engines: ',' names nothing"),
        (["run", "lecture-projectile", "--out", "/dev/null"], "exists and is not a folder"),
        (["report", "/nonexistent/run"], "missing"),
        (["export", "lecture-projectile", "--engine", "mujoco", "--integrator", "verlet"], "no integrator 'verlet'"),
        (["export", "lecture-projectile", "--engine", "mujoco", "--dt", "-1"], "--dt -1"),
    ],
)
def test_user_mistakes_exit_2(capsys, argv, words):
    """Unknown scenes, engines, integrators, bad numbers and missing runs are one-line errors with exit 2."""
    assert main(argv) == EXIT_USAGE
    err = capsys.readouterr().err
    assert words in err and "Traceback" not in err


@pytest.mark.parametrize("engine, marker", [("mujoco", "<mujoco"), ("pybullet", "<robot"), ("pinocchio", "<robot")])
def test_export_prints_the_model_for_kinematics(engine, marker):
    """export prints the MJCF or URDF each adapter builds for the chain."""
    code, text = _run(["export", "lecture-planar-arm", "--engine", engine])
    assert code == EXIT_OK and marker in text and "elbow" in text


@pytest.mark.parametrize("engine, marker", [("mujoco", "<freejoint"), ("pybullet", "URDF_USE_INERTIA_FROM_FILE"),
                                            ("pinocchio", "free-flyer")])
def test_export_prints_the_model_for_dynamics(engine, marker):
    """For a dynamics scene export shows the model and the settings given through the API."""
    code, text = _run(["export", "lecture-projectile", "--engine", engine])
    assert code == EXIT_OK and marker in text


@pytest.mark.slow
def test_report_rerenders_a_stored_run(tmp_path):
    """'simparity report DIR' rebuilds report.md from results.csv alone."""
    assert _run(["run", "lecture-planar-arm", "--engines", "core,analytic", "--out", str(tmp_path), "--repeats", "1",
                 "--jobs", "1", "--no-report"])[0] == 0
    assert not (tmp_path / "report.md").exists()  # the run drew none: what follows is the stored run's alone
    code, _ = _run(["report", str(tmp_path)])
    assert code == EXIT_OK and "lecture-planar-arm" in (tmp_path / "report.md").read_text()


@pytest.mark.slow
def test_console_script_help(capsys):
    """The installed entry point answers --help for every command."""
    # One process for the entry point itself (its imports, its exit code); every command's --help then through the
    # main() that entry point calls (python -m simparity.comparisons.cli is sys.exit(main())): the same parsers, without
    # the ~4 s a process's imports cost each
    done = subprocess.run([sys.executable, "-m", "simparity.comparisons.cli", "--help"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0 and "usage: simparity" in done.stdout
    for command in ("run", "list", "export", "report"):
        with pytest.raises(SystemExit) as exited:
            main([command, "--help"])
        assert exited.value.code == 0 and capsys.readouterr().out.startswith(f"usage: simparity {command} ")


def test_urdf_with_an_unsupported_element_exits_2_naming_it(tmp_path, capsys):
    """A scene whose URDF has a mimic joint on the chain is a one-line error naming the element."""
    (tmp_path / "robot.urdf").write_text(
        '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
        '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1"/></joint>'
        '<joint name="j2" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1"/><mimic joint="j1"/></joint></robot>')
    (tmp_path / "scene.toml").write_text(
        '[scene]\nname = "m"\nkind = "kinematics"\nreference = "core"\n[chain]\nurdf = "robot.urdf"\n')
    assert main(["run", str(tmp_path / "scene.toml"), "--out", str(tmp_path / "out")]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "mimic" in err and "j2" in err


def test_repeated_engine_names_are_refused(tmp_path, capsys):
    """--engines core,core is one line, exit 2, before anything runs (it ran core once before #39)."""
    assert main(["run", "lecture-planar-arm", "--engines", "core,core", "--out", str(tmp_path / "o")]) == EXIT_USAGE
    assert "core named twice" in capsys.readouterr().err and not (tmp_path / "o").exists()


@pytest.mark.slow
def test_export_output_is_only_the_model():
    """Piped, 'export --engine pybullet' is one XML document (a provenance comment, then the robot) and says
    nothing on stderr: PyBullet's banner stays out."""
    done = subprocess.run([sys.executable, "-m", "simparity.comparisons.cli", "export", "lecture-planar-arm", "--engine",
                           "pybullet"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0
    assert ET.fromstring(done.stdout).tag == "robot" and "build time" not in done.stdout
    assert "build time" not in done.stderr


ARM_RUN = ["run", "lecture-planar-arm", "--engines", "core", "--repeats", "0", "--jobs", "1", "--no-report"]
"""A cheap run (the arm's configurations on core, one worker, no report) for the tests of what any run does."""


@pytest.fixture(scope="module")
def arm_run(tmp_path_factory):
    """One :data:`ARM_RUN`, shared by the tests that read its exit code and output or copy its folder: (code, text,
    folder)."""
    folder = tmp_path_factory.mktemp("arm") / "run"
    code, text = _run(ARM_RUN + ["--out", str(folder), "--history", str(folder.parent / "history.sqlite")])
    return code, text, folder


@pytest.mark.slow
def test_out_holding_a_run_is_refused_unless_forced(tmp_path, capsys, arm_run):
    """A second run into the same --out exits 2 and leaves the first run untouched; --force overwrites."""
    code, _, first = arm_run
    assert code == EXIT_OK
    shutil.copytree(first, tmp_path, dirs_exist_ok=True)  # this test's own copy of the first run
    argv = ARM_RUN + ["--out", str(tmp_path)]
    before = (tmp_path / "results.csv").read_bytes()
    capsys.readouterr()
    assert main(argv) == EXIT_USAGE
    err = capsys.readouterr().err
    assert "already holds a run" in err and "--force" in err and err.count("\n") == 1
    assert (tmp_path / "results.csv").read_bytes() == before
    assert main(argv + ["--force"]) == EXIT_OK


@pytest.mark.slow
def test_default_output_folders_never_collide(tmp_path, monkeypatch):
    """Two runs in the same second get two folders."""
    monkeypatch.chdir(tmp_path)
    for _ in range(2):
        assert main(ARM_RUN, out=io.StringIO()) == EXIT_OK
    assert len([p for p in (tmp_path / "simparity-results").iterdir() if p.is_dir()]) == 2


@pytest.fixture(scope="module")
def projectile_run(tmp_path_factory):
    """One `run lecture-projectile --quick --engines core --check` (the numerics take ~10 s), shared by the tests that
    read it and never change it: its exit code, its output, its folder and the history database it recorded into.
    No report: none of them reads one."""
    folder = tmp_path_factory.mktemp("projectile")
    history = folder / "history.sqlite"
    code, text = _run(["run", "lecture-projectile", "--quick", "--engines", "core", "--out", str(folder / "run"),
                       "--check", "--jobs", "1", "--no-report", "--history", str(history)])
    return code, text, folder / "run", history


@pytest.mark.slow
def test_run_check_junit_summary_and_history(tmp_path, capsys, projectile_run):
    """run --check passes on the shipped tolerances; a tolerance the run breaks gives exit 1 with the violation on one
    line, a JUnit file with the failing case and a summary; history shows both runs side by side."""
    code, text, first, recorded = projectile_run
    assert code == EXIT_OK and "check passed" in text
    shutil.copyfile(recorded, os.environ[HISTORY_ENV])  # this test's own history: the first run recorded in it
    tight = tmp_path / "tight.toml"
    tight.write_text('[[bound]]\nintegrator = "explicit_euler"\nmetric = "position_error_max"\nmax = 1e-20\n'
                     'reason = "tighter than any first-order error"\n', encoding="utf-8")
    junit, summary = tmp_path / "junit.xml", tmp_path / "summary.md"
    code = main(["check", str(first), "--tolerances", str(tight), "--junit", str(junit), "--summary", str(summary)])
    out = capsys.readouterr().out
    assert code == 1
    violations = [line for line in out.splitlines() if line.startswith("violation: ")]
    steps = len(quick(builtin("lecture-projectile")).dts)  # one violation per time step of the quick profile
    assert len(violations) == steps and all("explicit_euler" in v and "first-order" in v for v in violations)
    assert ET.parse(junit).getroot().get("failures") == str(steps)
    assert "## simparity check: failed" in summary.read_text(encoding="utf-8")
    second = tmp_path / "second"
    assert main(["run", "lecture-projectile", "--quick", "--engines", "core", "--out", str(second), "--jobs", "1",
                 "--no-report"]) == 0
    assert main(["check", str(second), "--baseline", "latest"]) == EXIT_OK  # same numerics: nothing moved
    capsys.readouterr()
    assert main(["history", "lecture-projectile", "--engine", "core", "--metric", "position_error_final"]) == EXIT_OK
    shown = capsys.readouterr().out.splitlines()
    euler = [line for line in shown if " explicit_euler " in line and "0.0333333" in line]
    assert shown[0].count("#") == 2 and len(euler) == 1 and euler[0].count("0.97536") == 2


@pytest.mark.slow
def test_a_broken_history_database_never_loses_a_run(tmp_path, capsys, monkeypatch):
    """A database that fails when the run is recorded: one line on stderr, the run's CSV and report are written,
    exit 0. (One that is no database at all is refused before the run: tests/system/test_output_confinement.py.)"""
    from simparity.comparisons.pipeline import session
    from simparity.core.model.errors import HistoryError

    def broken(*args, **kwargs):
        raise HistoryError(f"{tmp_path / 'history.sqlite'}: run history unusable: disk I/O error")

    monkeypatch.setattr(session, "record_run", broken)
    code = main(["run", "lecture-planar-arm", "--engines", "core", "--repeats", "0", "--jobs", "1",
                 "--out", str(tmp_path / "r"), "--history", str(tmp_path / "history.sqlite")])
    err = capsys.readouterr().err
    assert code == EXIT_OK and err.startswith("simparity: history not updated") and err.count("\n") == 1
    assert (tmp_path / "r" / "results.csv").is_file() and (tmp_path / "r" / "report.md").is_file()


@pytest.mark.parametrize("dt", ["inf", "nan", "0", "-0.01"])
def test_export_refuses_a_time_step_that_is_not_one(capsys, dt):
    assert main(["export", "lecture-projectile", "--engine", "mujoco", "--dt", dt]) == EXIT_USAGE
    assert "(allowed: a finite number of seconds > 0" in capsys.readouterr().err


@pytest.mark.slow
def test_a_reader_that_stops_early_gets_no_traceback():
    """`simparity list | head -1`: the closed pipe ends the command quietly with exit 0."""
    process = subprocess.Popen([sys.executable, "-m", "simparity.comparisons.cli", "list"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    process.stdout.close()  # the reader is gone before the first line is written
    _, err = process.communicate(timeout=120)
    assert process.returncode == EXIT_OK and "Traceback" not in err, err


def test_show_reports_a_point_mass_body_and_the_contact_settings():
    """`simparity show` prints what the loader computed: a point-mass body's mass, COM and tensor (physical
    sign), normalised planes and every body-plane material."""
    code, text = _run(["show", "point-mass-tumble"])
    assert code == EXIT_OK
    # By hand: masses 1, 0.5, 0.5, 0.5 at (0.2,0,0), (-0.2,0,0), (0,0.15,0), (0,0,0.25): M = 2.5,
    # COM = (0.1, 0.075, 0.125) / 2.5 = (0.04, 0.03, 0.05); I_xy = -sum m (x - 0.04)(y - 0.03) = 0.003.
    assert "mass 2.5 kg" in text and "COM = sum m_i q_i / M = [0.04, 0.03, 0.05]" in text
    assert "[[0.034, 0.003, 0.005], [0.003, 0.081, 0.00375], [0.005, 0.00375, 0.065]]" in text
    assert "-sum m x y" in text and "plane floor: E(p) = N . p + d, N = [0, 0, 1]" in text
    assert "tetra on floor: restitution 0.3, friction static 0.5, kinetic 0.5" in text


@pytest.mark.slow
def test_every_run_ends_with_its_wall_time_and_peak_memory(tmp_path, arm_run):
    """Issue #11: the last line of `simparity run` is what the run cost; a refused run prints no cost."""
    code, text, _ = arm_run
    last = text.strip().splitlines()[-1]
    assert code == EXIT_OK
    assert re.fullmatch(r"wall time \d+\.\d s; peak memory [\d,]+ MiB( \(largest worker process [\d,]+ MiB\))?", last)
    code, text = _run(["run", "no-such-scene", "--out", str(tmp_path / "p")])
    assert code == EXIT_USAGE and "wall time" not in text


def test_bench_is_a_command_with_help():
    with pytest.raises(SystemExit) as done:
        main(["bench", "--help"])
    assert done.value.code == 0


@pytest.mark.slow
def test_check_explain_says_what_holds_an_engine(capsys, projectile_run):
    """--explain ENGINE: one line per scene and bound that holds the engine's rows, from the bound's file and index,
    with the rows it holds, to what and why; an engine the run does not have is a one-line error."""
    code, _, run, _ = projectile_run
    assert code == EXIT_OK
    assert main(["check", str(run), "--explain", "core"]) == EXIT_OK
    lines = capsys.readouterr().out.splitlines()
    assert lines and all(line.startswith("lecture-projectile: default.toml: bound[") for line in lines)
    assert any("position_error_final" in line and "x dt^1" in line and "g T dt / 2" in line for line in lines)
    assert main(["check", str(run), "--explain", "nosuch"]) == EXIT_USAGE
    assert "--explain nosuch: no rows of that engine" in capsys.readouterr().err


def _stored(path, rows, profile="quick"):
    """A stored run of ``rows`` (ResultRow) with ``profile`` in its run.json, written as 'simparity run' writes."""
    from simparity.comparisons.pipeline.run_info import describe_run
    from simparity.reports.store import RunWriter

    RunWriter(path, describe_run([], "test", [], profile)).append(rows)
    return path


def _user_rows(factor=1.0, status="ok"):
    from simparity.core.model.results import ResultRow

    return [ResultRow("my-scene", "mine", f"scheme{k}", dt, "position_error_max", 1e-6 * dt * factor, "m",
                      "analytic:exact", status, "" if status == OK else "raised") for k in range(3) for dt in (0.01, 0.02)]


def test_check_bless_round_trips_and_refuses_a_failed_run(tmp_path, capsys):
    """A user's scene the shipped tolerances do not name: the check fails as too unbounded (exit 1, one line) unless
    --allow-unbounded; blessed, it passes; a degraded copy fails against the blessed file; a failed run refuses."""
    run = _stored(tmp_path / "run", _user_rows())
    assert main(["check", str(run)]) == 1
    out = capsys.readouterr().out
    assert "unbounded: 3 of 3 series" in out and "check FAILED" in out
    assert main(["check", str(run), "--allow-unbounded"]) == EXIT_OK
    blessed = tmp_path / "blessed.toml"
    assert main(["check", str(run), "--bless", str(blessed)]) == EXIT_OK
    assert "blessed 6 bounds" in capsys.readouterr().out
    assert main(["check", str(run), "--tolerances", str(blessed)]) == EXIT_OK
    worse = _stored(tmp_path / "worse", _user_rows(factor=2.0))
    assert main(["check", str(worse), "--tolerances", str(blessed)]) == 1
    assert capsys.readouterr().out.count("violation: ") == 6
    failed = _stored(tmp_path / "failed", _user_rows(status="failed"))
    assert main(["check", str(failed), "--bless", str(tmp_path / "no.toml")]) == EXIT_USAGE
    assert "nothing was blessed" in capsys.readouterr().err and not (tmp_path / "no.toml").exists()


def test_a_baseline_of_another_profile_is_refused_and_a_subset_prints_nothing(tmp_path, capsys):
    """A baseline that ran more engines and scenes than the run: nothing is missing, nothing printed but the verdict
    (which says what was not compared); a full-profile baseline for a quick run is refused in one line."""
    rows = _user_rows()
    full = _stored(tmp_path / "full", rows, profile="full")
    quick_run = _stored(tmp_path / "quick", rows, profile="quick")
    more = rows + [dataclasses.replace(r, engine="other") for r in rows] + [
        dataclasses.replace(r, scene="other-scene") for r in rows]
    bigger = _stored(tmp_path / "bigger", more, profile="quick")
    assert main(["check", str(quick_run), "--allow-unbounded", "--baseline", str(full)]) == EXIT_USAGE
    assert "a full-profile run, this one is quick" in capsys.readouterr().err
    assert main(["check", str(quick_run), "--allow-unbounded", "--baseline", str(bigger)]) == EXIT_OK
    out = capsys.readouterr().out
    assert [line.split(":")[0] for line in out.splitlines()] == ["check passed"]
    assert "0 moved, 0 missing, 0 new (not compared: 12 baseline rows of scenes x engines this run did not run)" in out


def test_history_without_a_match_exits_1_naming_the_recorded_scenes(tmp_path, capsys, monkeypatch):
    from simparity.comparisons.gate.history import record_run
    from simparity.core.model.run_info import RunInfo

    history = tmp_path / "history.sqlite"
    run = _stored(tmp_path / "run", _user_rows())
    record_run(history, run, RunInfo(created_utc="2026-11-27T00:00:00+00:00"), read_run(run)[0])
    assert main(["history", "no-such-scene", "--history", str(history)]) == 1
    assert "no recorded values match scene no-such-scene" in capsys.readouterr().out
    assert main(["history", "my-scene", "--history", str(history)]) == EXIT_OK


@pytest.mark.parametrize("name", ["nosuchfile.toml", "some/dir/x.toml"])
def test_run_of_a_missing_scene_file_is_one_line_naming_it(tmp_path, capsys, monkeypatch, name):
    """Issue #25: a path that does not exist says so, naming it as resolved, not the 40 built-in scenes."""
    monkeypatch.chdir(tmp_path)
    assert main(["run", name, "--out", str(tmp_path / "out")]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"simparity: error: {name}: the file {tmp_path / name} does not exist "
                                                   "(allowed: ")
    assert "lecture-projectile" not in err and not (tmp_path / "out").exists()


def test_run_of_an_unknown_scene_name_suggests_the_closest(capsys):
    assert main(["run", "lecture-projectil"]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "closest: lecture-projectile, lecture-bouncing-particle (allowed: " in err
    assert "wind" not in err   # not the whole list


@pytest.mark.slow  # ~2 s of CPU: a subprocess
def test_export_of_a_urdf_nested_5000_deep_is_one_line_in_a_process_of_its_own(tmp_path):
    """Issue #25, as a user runs it: no RecursionError traceback, exit 2, one line naming the file and the limit."""
    from simparity.core.model.files import MAX_XML_DEPTH

    from tests.core.test_urdf import nested_urdf

    (tmp_path / "deep.urdf").write_text(nested_urdf(5_000))
    (tmp_path / "scene.toml").write_text(
        '[scene]\nname = "d"\nkind = "kinematics"\nreference = "core"\n[chain]\nurdf = "deep.urdf"\n')
    done = subprocess.run([sys.executable, "-m", "simparity.comparisons.cli", "export", str(tmp_path / "scene.toml"),
                           "--engine", "pinocchio"], check=False, capture_output=True, text=True, timeout=120)
    assert done.returncode == EXIT_USAGE and done.stdout == "" and done.stderr.count("\n") == 1
    assert (f"deep.urdf: <a> at depth {MAX_XML_DEPTH + 1}: elements nested more than {MAX_XML_DEPTH} levels deep "
            "(allowed: ") in done.stderr
