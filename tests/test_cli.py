"""The simparity command: list, run, export, report, and clean errors for user mistakes."""

import io
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from simparity.comparisons.cli import EXIT_OK, EXIT_USAGE, main
from simparity.comparisons.engines import DEFAULT_ENGINES
from simparity.comparisons.library import builtin_paths
from simparity.core.results import COLUMNS, NOT_AVAILABLE, OK, STATUSES
from simparity.reports.store import read_run
from tests.test_scene_loader import BROKEN


def _run(argv):
    out = io.StringIO()
    code = main(argv, out=out)
    return code, out.getvalue()


def test_list_names_every_builtin_scene():
    """'simparity list' prints one line per built-in scene, starting with its name."""
    code, text = _run(["list"])
    lines = text.strip().splitlines()
    assert code == EXIT_OK
    assert [line.split()[0] for line in lines] == sorted(builtin_paths())


def test_run_without_scenes_runs_the_whole_builtin_suite(tmp_path, monkeypatch):
    """No scene argument means every built-in scene, each once, on the default engines."""
    seen = []
    monkeypatch.setattr("simparity.comparisons.cli.run_scene", lambda scene, engines, *a, **k: seen.append(
        (scene.name, tuple(e.name for e in engines))) or [])
    code, _ = _run(["run", "--out", str(tmp_path)])
    assert code == EXIT_OK
    assert [name for name, _ in seen] == sorted(builtin_paths())
    assert all(engines == DEFAULT_ENGINES for _, engines in seen)


def test_lecture_scenes_end_to_end(tmp_path):
    """'simparity run' on the two lecture scenes writes results.csv and report.md with every engine's rows."""
    code, text = _run(["run", "lecture-projectile", "lecture-planar-arm", "--out", str(tmp_path), "--repeats", "1"])
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
    assert "## lecture-projectile (dynamics)" in report and "## lecture-planar-arm (kinematics)" in report
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
        (["run", "no-such-scene"], "neither a built-in scene nor a file"),
        (["run", "lecture-projectile", "--engines", "core,havok"], "unknown engine(s): havok"),
        (["run", "lecture-projectile", "--repeats", "0"], "--repeats 0"),
        (["run", "lecture-projectile", "--engines", ","], "no engine named"),
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


def test_report_rerenders_a_stored_run(tmp_path):
    """'simparity report DIR' rebuilds report.md from results.csv alone."""
    assert _run(["run", "lecture-planar-arm", "--engines", "core,analytic", "--out", str(tmp_path), "--repeats", "1"])[0] == 0
    (tmp_path / "report.md").unlink()
    code, _ = _run(["report", str(tmp_path)])
    assert code == EXIT_OK and "lecture-planar-arm" in (tmp_path / "report.md").read_text()


def test_console_script_help():
    """The installed entry point answers --help for every command."""
    for argv in ([], ["run"], ["list"], ["export"], ["report"]):
        done = subprocess.run([sys.executable, "-m", "simparity.comparisons.cli", *argv, "--help"],
                              capture_output=True, text=True, timeout=60)
        assert done.returncode == 0 and "usage: simparity" in done.stdout


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


def test_repeated_engine_names_run_once(tmp_path):
    """--engines core,core runs core once."""
    code, _ = _run(["run", "lecture-planar-arm", "--engines", "core,core", "--out", str(tmp_path), "--repeats", "1"])
    table, _ = read_run(tmp_path)
    assert code == EXIT_OK and len(table[table["engine"] == "core"]) == len(table)
    assert table.duplicated(["engine", "metric"]).sum() == 0


def test_export_output_is_only_the_model():
    """Piped, 'export --engine pybullet' is one XML document (a provenance comment, then the robot) and says
    nothing on stderr: PyBullet's banner stays out."""
    done = subprocess.run([sys.executable, "-m", "simparity.comparisons.cli", "export", "lecture-planar-arm", "--engine",
                           "pybullet"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0
    assert ET.fromstring(done.stdout).tag == "robot" and "build time" not in done.stdout
    assert "build time" not in done.stderr
